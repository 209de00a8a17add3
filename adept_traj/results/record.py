"""The result of a planning run (:class:`PlanningResult`) and its folder on disk.

A result folder holds three files (schema: ``docs/results.md``)::

    result.json           everything, the authoritative copy (format "adept_traj.result", v1)
    front.csv             the final front: z1..z6, feasible, x0..x{n_var-1}
    best_trajectory.csv   the certified best trajectory at ≥ 1 kHz: t, q_*, qd_*, qdd_*,
                          qddd_*, tau_*, min_distance

:meth:`PlanningResult.save` writes them (creating the folder), :meth:`PlanningResult.load`
reads them back: every field round-trips exactly (floats are written with Python's
shortest round-trip representation), arrays come back as read-only numpy arrays. Nothing is
ever pickled. JSON has no NaN or infinity: NaN is refused when a result is built (metrics
excepted: a NaN metric becomes ``None``) and an infinite value is written as ``null``
(``-inf`` in ``limits.q_lower``, ``+inf`` everywhere else it may occur: infinite joint
limits, the distance of a scene without obstacles). Any missing or malformed file, field or
value raises :class:`ResultFormatError` naming the file and the field.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import os
import platform
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.analysis.certificate import LIMIT_KINDS, Certificate, DenseTrajectory, LimitCheck
from adept_traj.errors import AdeptTrajError, InputShapeError, InvalidInputError, ResultFormatError
from adept_traj.files import write_text_atomic
from adept_traj.problem import (
    OBJECTIVE_NAMES,
    Evaluation,
    KinematicBound,
    ProblemSettings,
    TrajectoryProblem,
)
from adept_traj.robot.limits import JointLimits
from adept_traj.robot.robot import Robot
from adept_traj.scene.scene import Scene
from adept_traj.validation import as_finite_array, readonly_copy

__all__ = [
    "FORMAT",
    "FRONT_FILE",
    "NO_FEASIBLE_WARNING",
    "RESULT_FILE",
    "SHIPPED_ROBOT",
    "TRAJECTORY_FILE",
    "VERSION",
    "BestSolution",
    "Front",
    "GenerationRecord",
    "Metrics",
    "PlanningResult",
    "ResultFormatError",
    "RobotInfo",
    "Timing",
    "software_versions",
]

#: Value of the ``"format"`` key of ``result.json``.
FORMAT = "adept_traj.result"
#: Schema version written (and the only one read).
VERSION = 1
#: File names inside a result folder.
RESULT_FILE = "result.json"
FRONT_FILE = "front.csv"
TRAJECTORY_FILE = "best_trajectory.csv"
#: Marker stored as ``robot.urdf`` for the shipped AdeptOne XL (URDF + parameter file).
SHIPPED_ROBOT = "adept_one_xl"
#: Warning set when no solution of the front is feasible.
NO_FEASIBLE_WARNING = "no feasible solution found: the front holds the least-infeasible solutions"
_JSON_METRICS = {"ssm": "SSM", "rni": "RNI", "oo": "OO", "ae": "AE", "hv": "HV"}


# ============================================================================ parts
@dataclass(frozen=True)
class RobotInfo:
    """How to rebuild the robot of a run.

    Attributes
    ----------
    name: the robot's name.
    joint_names: names of the joints, in the order of q.
    urdf: ``"adept_one_xl"`` for the shipped AdeptOne XL (:meth:`Robot.adept_one_xl`),
        else the URDF path as given when the robot was loaded.
    params: parameter-file path, or ``None`` (no file, the shipped robot, or parameters
        given as an object, which cannot be recorded).
    tool_frame: the tool frame's name.
    """

    name: str
    joint_names: tuple[str, ...]
    urdf: str
    params: str | None = None
    tool_frame: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "joint_names", tuple(str(n) for n in self.joint_names))
        if not self.joint_names:
            raise InvalidInputError("joint_names must not be empty")

    @classmethod
    def of(cls, robot: Robot) -> RobotInfo:
        """The description of ``robot``."""
        urdf = str(robot.urdf_path) if robot.urdf_path is not None else robot.name
        params = str(robot.params_path) if robot.params_path is not None else None
        if _is_shipped(robot):
            urdf, params = SHIPPED_ROBOT, None
        return cls(
            name=robot.name,
            joint_names=robot.joint_names,
            urdf=urdf,
            params=params,
            tool_frame=robot.tool_frame,
        )

    def load(self) -> Robot:
        """Rebuild the robot (raises :class:`~adept_traj.errors.RobotModelError` when its
        files are gone)."""
        if self.urdf == SHIPPED_ROBOT:
            return Robot.adept_one_xl()
        return Robot.from_urdf(self.urdf, self.params, tool_frame=self.tool_frame)


@dataclass(frozen=True, eq=False)
class Front:
    """A set of solutions: the final non-dominated set of a run.

    Attributes
    ----------
    x: (n, n_var) decision vectors ``[T, free control points]``.
    objectives: (n, 6) z1…z6, **z4 positive** (as reported, not pymoo's negated value).
    constraints: (n, n_con) normalised constraints g (≤ 0 satisfied), the problem's order.
    feasible: (n,) bool, as decided by the engine (the certificate for "verified").
    """

    x: np.ndarray
    objectives: np.ndarray
    constraints: np.ndarray
    feasible: np.ndarray

    def __post_init__(self) -> None:
        x = _matrix(self.x, "front.x")
        n = x.shape[0]
        obj = _matrix(self.objectives, "front.objectives", (n, len(OBJECTIVE_NAMES)))
        con = _matrix(self.constraints, "front.constraints", (n, None))
        feas = np.array(self.feasible)
        if feas.shape != (n,) or feas.dtype != bool:
            raise InputShapeError(
                f"front.feasible must be a bool array of shape ({n},); got {feas.dtype} "
                f"{feas.shape}"
            )
        feas = feas.copy()
        feas.flags.writeable = False
        for name, value in (("x", x), ("objectives", obj), ("constraints", con)):
            object.__setattr__(self, name, value)
        object.__setattr__(self, "feasible", feas)

    @classmethod
    def from_evaluation(cls, x: Any, evaluation: Evaluation, feasible: Any | None = None) -> Front:
        """The front of decision vectors ``x`` (n, n_var) and their :class:`Evaluation`
        (objectives with z4 positive, constraints); ``feasible`` defaults to
        ``evaluation.feasible``."""
        return cls(
            x=np.atleast_2d(np.asarray(x, dtype=float)),
            objectives=np.atleast_2d(evaluation.objectives),
            constraints=np.atleast_2d(evaluation.constraints),
            feasible=np.atleast_1d(evaluation.feasible if feasible is None else feasible),
        )

    def __len__(self) -> int:
        return int(self.x.shape[0])

    def subset(self, mask: Any) -> Front:
        """The solutions selected by a bool mask or index array."""
        return Front(
            self.x[mask], self.objectives[mask], self.constraints[mask], self.feasible[mask]
        )

    def __eq__(self, other: object) -> bool:
        return _equal(self, other) if type(other) is type(self) else NotImplemented

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True)
class BestSolution:
    """The solution picked from the front.

    Attributes
    ----------
    index: its row in the front.
    f_c: the selection score of the engine's decision rule (``None`` if not used).
    f_avg: the average fitness ``F_avg`` of the decision rule (``None`` if not used).
    """

    index: int
    f_c: float | None = None
    f_avg: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "index", _index(self.index, "best.index"))
        object.__setattr__(self, "f_c", _optional_float(self.f_c, "best.f_c"))
        object.__setattr__(self, "f_avg", _optional_float(self.f_avg, "best.f_avg"))


@dataclass(frozen=True, eq=False)
class Metrics:
    """Quality metrics of the front (``None``: not computed; NaN is stored as ``None``).

    Attributes
    ----------
    ssm, rni, oo, ae: the paper's spacing (SSM), ratio of non-dominated individuals (RNI),
        optimiser overhead (OO) and algorithm effort (AE), as the engine defines them.
    hv: hypervolume of the normalised front w.r.t. ``hv_reference_point``.
    hv_reference_point: (6,) the reference point, or ``None``.
    """

    ssm: float | None = None
    rni: float | None = None
    oo: float | None = None
    ae: float | None = None
    hv: float | None = None
    hv_reference_point: np.ndarray | None = None

    def __post_init__(self) -> None:
        for name in _JSON_METRICS:
            object.__setattr__(self, name, _metric(getattr(self, name), f"metrics.{name}"))
        if self.hv_reference_point is not None:
            ref = readonly_copy(as_finite_array(self.hv_reference_point, "hv_reference_point"))
            if ref.ndim != 1:
                raise InputShapeError(f"hv_reference_point must be 1-D; got {ref.shape}")
            object.__setattr__(self, "hv_reference_point", ref)

    def __eq__(self, other: object) -> bool:
        return _equal(self, other) if type(other) is type(self) else NotImplemented

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True)
class Timing:
    """Cost of a run.

    Attributes
    ----------
    total_s: wall time of the whole run [s].
    evaluation_s: wall time spent evaluating objectives and constraints [s].
    n_evaluations: trajectories evaluated.
    n_generations: generations run.
    """

    total_s: float
    evaluation_s: float
    n_evaluations: int
    n_generations: int

    def __post_init__(self) -> None:
        for name in ("total_s", "evaluation_s"):
            value = _optional_float(getattr(self, name), f"timing.{name}")
            if value is None or value < 0:
                raise InvalidInputError(f"timing.{name} must be a number ≥ 0 [s]")
            object.__setattr__(self, name, value)
        for name in ("n_evaluations", "n_generations"):
            object.__setattr__(self, name, _index(getattr(self, name), f"timing.{name}"))


@dataclass(frozen=True)
class GenerationRecord:
    """Progress after one generation.

    Attributes
    ----------
    generation: 1-based generation number.
    n_evaluations: evaluations so far.
    n_feasible: feasible individuals in the population.
    hypervolume: hypervolume of the feasible front, or ``None`` (not computed / none).
    """

    generation: int
    n_evaluations: int
    n_feasible: int
    hypervolume: float | None = None

    def __post_init__(self) -> None:
        for name in ("generation", "n_evaluations", "n_feasible"):
            object.__setattr__(self, name, _index(getattr(self, name), f"history.{name}"))
        object.__setattr__(self, "hypervolume", _metric(self.hypervolume, "history.hypervolume"))


def software_versions() -> dict[str, str]:
    """Versions of adept_traj, numpy, pinocchio, coal, pymoo and Python."""
    import coal
    import pinocchio
    import pymoo

    from adept_traj import __version__

    return {
        "adept_traj": str(__version__),
        "numpy": np.__version__,
        "pinocchio": str(pinocchio.__version__),
        "coal": str(getattr(coal, "__version__", "unknown")),
        "pymoo": str(getattr(pymoo, "__version__", "unknown")),
        "python": platform.python_version(),
    }


# ============================================================================ the result
@dataclass(frozen=True, eq=False)
class PlanningResult:
    """Everything a planning run produces (see ``docs/results.md`` for the file schema).

    Build one with :meth:`from_problem` (fills the problem-derived fields) or directly.

    Attributes
    ----------
    start, goal: (nq,) rest configurations [rad | m].
    robot: :class:`RobotInfo`.
    scene: the scene as :meth:`Scene.to_dict` (a :class:`Scene` is accepted and converted).
    problem_settings: the problem's :class:`ProblemSettings`.
    limits: the robot's :class:`JointLimits` (SI).
    lower_bound: the kinematic lower bound of the travel time (:class:`KinematicBound`).
    algorithm: name of the optimiser as run (``"nsga2"``, ``"mode"``, …).
    algorithm_settings: its settings, stored as a JSON-compatible copy (numpy values become
        Python values, tuples lists, non-finite floats ``None``, other objects ``str``).
    seed: random seed, or ``None``.
    front: the final non-dominated set (:class:`Front`, n ≥ 1); when nothing is feasible,
        the least-infeasible solutions.
    best: the chosen solution (:class:`BestSolution`, an index into ``front``).
    certificate: the dense :class:`~adept_traj.verification.Certificate` of the best
        solution (its ``x`` must equal ``front.x[best.index]``).
    timing: :class:`Timing`.
    metrics: :class:`Metrics` (default: none computed).
    history: per-generation :class:`GenerationRecord` tuple, or ``None``.
    warning: a warning for the reader; defaults to :data:`NO_FEASIBLE_WARNING` when no
        solution of the front is feasible.
    versions: software versions (default: :func:`software_versions` now).
    """

    start: np.ndarray
    goal: np.ndarray
    robot: RobotInfo
    scene: dict[str, Any]
    problem_settings: ProblemSettings
    limits: JointLimits
    lower_bound: KinematicBound
    algorithm: str
    algorithm_settings: dict[str, Any]
    seed: int | None
    front: Front
    best: BestSolution
    certificate: Certificate
    timing: Timing
    metrics: Metrics = field(default_factory=Metrics)
    history: tuple[GenerationRecord, ...] | None = None
    warning: str | None = None
    versions: dict[str, str] = field(default_factory=software_versions)

    def __post_init__(self) -> None:
        _check_type(self.robot, RobotInfo, "robot")
        _check_type(self.problem_settings, ProblemSettings, "problem_settings")
        _check_type(self.limits, JointLimits, "limits")
        _check_type(self.lower_bound, KinematicBound, "lower_bound")
        _check_type(self.front, Front, "front")
        _check_type(self.best, BestSolution, "best")
        _check_type(self.certificate, Certificate, "certificate")
        _check_type(self.timing, Timing, "timing")
        _check_type(self.metrics, Metrics, "metrics")
        nq = len(self.robot.joint_names)
        if tuple(self.limits.names) != self.robot.joint_names:
            raise InvalidInputError(
                f"limits.names {list(self.limits.names)} differ from robot.joint_names "
                f"{list(self.robot.joint_names)}"
            )
        for name in ("start", "goal"):
            arr = readonly_copy(as_finite_array(getattr(self, name), name))
            if arr.shape != (nq,):
                raise InputShapeError(f"{name} must have shape ({nq},); got {arr.shape}")
            object.__setattr__(self, name, arr)
        scene = self.scene.to_dict() if isinstance(self.scene, Scene) else self.scene
        if not isinstance(scene, Mapping):
            raise InvalidInputError(f"scene must be a Scene or a mapping; got {type(scene)}")
        object.__setattr__(self, "scene", _jsonable(scene))
        if not isinstance(self.algorithm, str) or not self.algorithm:
            raise InvalidInputError(f"algorithm must be a non-empty name; got {self.algorithm!r}")
        if not isinstance(self.algorithm_settings, Mapping):
            raise InvalidInputError("algorithm_settings must be a mapping")
        object.__setattr__(self, "algorithm_settings", _jsonable(self.algorithm_settings))
        if self.seed is not None:
            object.__setattr__(self, "seed", _integer(self.seed, "seed"))
        n_knots = int(self.problem_settings.n_knots)
        n_var, n_con = 1 + nq * (n_knots - 4), 5 * nq + 1
        fr = self.front
        if len(fr) == 0:
            raise InvalidInputError("front must hold at least one solution")
        if fr.x.shape[1] != n_var or fr.constraints.shape[1] != n_con:
            raise InputShapeError(
                f"front.x must have {n_var} columns and front.constraints {n_con} "
                f"(nq = {nq}, n_knots = {n_knots}); got {fr.x.shape[1]} and "
                f"{fr.constraints.shape[1]}"
            )
        if self.best.index >= len(fr):
            raise InvalidInputError(f"best.index {self.best.index} ≥ front size {len(fr)}")
        if not _equal(self.certificate.x, fr.x[self.best.index]):
            raise InvalidInputError("certificate.x must equal front.x[best.index]")
        if self.certificate.dense.nq != nq or self.lower_bound.times.shape != (nq,):
            raise InputShapeError(f"certificate and lower_bound must have {nq} joints")
        ref = self.metrics.hv_reference_point
        if ref is not None and ref.shape != (len(OBJECTIVE_NAMES),):
            raise InputShapeError(f"metrics.hv_reference_point must have shape (6,); {ref.shape}")
        if self.history is not None:
            history = tuple(self.history)
            for i, rec in enumerate(history):
                _check_type(rec, GenerationRecord, f"history[{i}]")
            object.__setattr__(self, "history", history)
        warning = self.warning
        if warning is None and not fr.feasible.any():
            warning = NO_FEASIBLE_WARNING
        if warning is not None:
            object.__setattr__(self, "warning", str(warning))
        versions = {str(k): str(v) for k, v in dict(self.versions).items()}
        object.__setattr__(self, "versions", versions)

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_problem(
        cls,
        problem: TrajectoryProblem,
        *,
        algorithm: str,
        algorithm_settings: Mapping[str, Any],
        seed: int | None,
        front: Front,
        best: BestSolution,
        certificate: Certificate,
        timing: Timing,
        metrics: Metrics | None = None,
        history: Iterable[GenerationRecord] | None = None,
        warning: str | None = None,
    ) -> PlanningResult:
        """A result whose start, goal, robot, scene, settings, limits and lower bound are
        taken from ``problem``."""
        return cls(
            start=problem.start,
            goal=problem.goal,
            robot=RobotInfo.of(problem.robot),
            scene=problem.scene.to_dict(),
            problem_settings=problem.settings,
            limits=problem.robot.limits,
            lower_bound=problem.lower_bound,
            algorithm=algorithm,
            algorithm_settings=dict(algorithm_settings),
            seed=seed,
            front=front,
            best=best,
            certificate=certificate,
            timing=timing,
            metrics=metrics if metrics is not None else Metrics(),
            history=None if history is None else tuple(history),
            warning=warning,
        )

    def problem(self) -> TrajectoryProblem:
        """Rebuild the :class:`TrajectoryProblem` of the run (robot files must exist)."""
        return TrajectoryProblem(
            self.robot.load(),
            Scene.from_dict(self.scene, source="result scene"),
            self.start,
            self.goal,
            self.problem_settings,
        )

    # ------------------------------------------------------------------ convenience
    @property
    def nq(self) -> int:
        """Number of joints."""
        return len(self.robot.joint_names)

    @property
    def feasible(self) -> bool:
        """The best solution is verified feasible (its dense :attr:`certificate`)."""
        return self.certificate.feasible

    @property
    def best_x(self) -> np.ndarray:
        """(n_var,) decision vector of the best solution."""
        return self.front.x[self.best.index]

    @property
    def best_objectives(self) -> np.ndarray:
        """(6,) z1…z6 of the best solution (z4 positive)."""
        return self.front.objectives[self.best.index]

    @property
    def front_objectives(self) -> np.ndarray:
        """(n, 6) z1…z6 of the front (z4 positive)."""
        return self.front.objectives

    @property
    def feasible_front(self) -> Front:
        """The feasible solutions of the front (possibly empty)."""
        return self.front.subset(self.front.feasible)

    @property
    def best_trajectory(self) -> DenseTrajectory:
        """The certified best trajectory at ≥ ``certificate.rate_hz``."""
        return self.certificate.dense

    @property
    def gap(self) -> float | None:
        """Best travel time over the kinematic lower bound, ``z1 / T_min`` (≥ 1); ``None``
        when ``T_min`` is 0."""
        t_min = float(self.lower_bound.T_min)
        return float(self.best_objectives[0]) / t_min if t_min > 0 else None

    def __eq__(self, other: object) -> bool:
        return _equal(self, other) if type(other) is type(self) else NotImplemented

    __hash__ = None  # type: ignore[assignment]

    # ------------------------------------------------------------------ files
    def save(self, folder: str | os.PathLike[str]) -> Path:
        """Write ``result.json``, ``front.csv`` and ``best_trajectory.csv`` into ``folder``
        (created if needed; existing files are replaced). Returns the folder's path."""
        path = Path(folder)
        path.mkdir(parents=True, exist_ok=True)
        write_text_atomic(path / RESULT_FILE, _dumps(_encode(self)) + "\n")
        write_text_atomic(path / FRONT_FILE, _front_csv(self))
        write_text_atomic(path / TRAJECTORY_FILE, _trajectory_csv(self))
        return path

    @classmethod
    def load(cls, folder: str | os.PathLike[str]) -> PlanningResult:
        """Read a result folder written by :meth:`save`.

        Raises
        ------
        ResultFormatError
            A file is missing or unreadable, ``result.json`` is not JSON, has another
            format or version, lacks a field or holds a bad value, or a CSV file disagrees
            with it. The message names the file and the field.
        """
        path = Path(folder)
        json_path = path / RESULT_FILE
        result = _decode(_parse_json(json_path), _Reader(json_path))
        _check_front_csv(result, path / FRONT_FILE)
        _check_trajectory_csv(result, path / TRAJECTORY_FILE)
        return result


# ============================================================================ encoding
def _encode(r: PlanningResult) -> dict[str, Any]:
    lim, lb, c = r.limits, r.lower_bound, r.certificate
    best = {
        "index": r.best.index,
        "objectives": _floats(r.best_objectives),
        "f_c": r.best.f_c,
        "F_avg": r.best.f_avg,
    }
    metrics: dict[str, Any] = {key: getattr(r.metrics, name) for name, key in _JSON_METRICS.items()}
    ref = r.metrics.hv_reference_point
    metrics["HV_reference_point"] = None if ref is None else _floats(ref)
    history = None
    if r.history is not None:
        history = [dataclasses.asdict(rec) for rec in r.history]
    return {
        "format": FORMAT,
        "version": VERSION,
        "warning": r.warning,
        "robot": {
            "name": r.robot.name,
            "joint_names": list(r.robot.joint_names),
            "urdf": r.robot.urdf,
            "params": r.robot.params,
            "tool_frame": r.robot.tool_frame,
        },
        "start": _floats(r.start),
        "goal": _floats(r.goal),
        "seed": r.seed,
        "algorithm": {"name": r.algorithm, "settings": r.algorithm_settings},
        "problem_settings": _jsonable(dataclasses.asdict(r.problem_settings)),
        "scene": r.scene,
        "limits": {
            "joint_names": list(lim.names),
            "units": list(lim.units),
            "q_lower": _floats(lim.lower),
            "q_upper": _floats(lim.upper),
            "qd": _floats(lim.velocity),
            "qdd": _floats(lim.acceleration),
            "qddd": _floats(lim.jerk),
            "tau": _floats(lim.effort),
        },
        "lower_bound": {
            "T_min": _float(lb.T_min),
            "per_joint": _floats(lb.times),
            "limiting_joint": int(lb.limiting_joint),
            "delta": _floats(lb.delta),
            "cases": list(lb.cases),
        },
        "gap": r.gap,
        "best": best,
        "certificate": _encode_certificate(c),
        "metrics": metrics,
        "timing": dataclasses.asdict(r.timing),
        "versions": dict(r.versions),
        "front": [
            {
                "objectives": _floats(r.front.objectives[i]),
                "x": _floats(r.front.x[i]),
                "constraints": _floats(r.front.constraints[i]),
                "feasible": bool(r.front.feasible[i]),
            }
            for i in range(len(r.front))
        ],
        "best_trajectory": {name: _floats(getattr(c.dense, name)) for name in _DENSE_FIELDS},
        "history": history,
    }


_DENSE_FIELDS = ("t", "q", "qd", "qdd", "qddd", "tau", "min_distance")


def _encode_certificate(c: Certificate) -> dict[str, Any]:
    out: dict[str, Any] = {
        "feasible": c.feasible,
        "rate_hz": c.rate_hz,
        "n_samples": c.n_samples,
        "margin": c.margin,
        "min_distance": _float(c.min_distance),
        "t_min_distance": c.t_min_distance,
        "closest_pair": None if c.closest_pair is None else list(c.closest_pair),
        "violations": list(c.violations),
        "x": _floats(c.x),
    }
    for check in c.checks:
        out[check.kind] = {
            "limit": check.symbol,
            "worst": _floats(check.worst),
            "within": [bool(b) for b in check.within],
            "dense": _floats(check.dense),
            "exact": None if check.exact is None else _floats(check.exact),
            "t_worst": _floats(check.t_worst),
            "tolerance": check.tolerance,
        }
    return out


def _float(value: float) -> float | None:
    """A finite float as is; ±inf as ``None``; NaN refused."""
    v = float(value)
    if math.isnan(v):
        raise InvalidInputError("NaN cannot be saved")
    return v if math.isfinite(v) else None


def _floats(arr: Any) -> Any:
    """Nested lists of floats (±inf → ``None``) from an array."""
    a = np.asarray(arr, dtype=float)
    if np.isnan(a).any():
        raise InvalidInputError("NaN cannot be saved")
    out = a.tolist()
    if np.isinf(a).any():
        return _replace_inf(out)
    return out


def _replace_inf(value: Any) -> Any:
    if isinstance(value, list):
        return [_replace_inf(v) for v in value]
    return None if math.isinf(value) else value


def _jsonable(value: Any) -> Any:
    """A JSON-compatible deep copy: mappings → dict (str keys), sequences and arrays →
    list, numpy scalars → Python, non-finite floats → None, other objects → str."""
    if isinstance(value, Mapping):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return _jsonable(value.item())
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    return str(value)


def _dumps(value: Any, level: int = 0) -> str:
    """Pretty JSON: objects one key a line, lists of scalars on one line (a matrix: one row
    a line). Refuses NaN and infinity."""
    pad, end = "  " * (level + 1), "  " * level
    if isinstance(value, dict):
        if not value:
            return "{}"
        items = [f"{pad}{_scalar(str(k))}: {_dumps(v, level + 1)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + end + "}"
    if isinstance(value, list):
        if all(not isinstance(v, (dict, list)) for v in value):
            return "[" + ", ".join(_scalar(v) for v in value) + "]"
        return "[\n" + ",\n".join(pad + _dumps(v, level + 1) for v in value) + "\n" + end + "]"
    return _scalar(value)


def _scalar(value: Any) -> str:
    return json.dumps(value, allow_nan=False, ensure_ascii=False)


def _csv_number(value: float) -> str:
    return repr(float(value))


def _front_header(n_var: int) -> list[str]:
    return [*OBJECTIVE_NAMES, "feasible", *(f"x{i}" for i in range(n_var))]


def _trajectory_header(names: Sequence[str]) -> list[str]:
    cols = ["t"]
    for prefix in ("q", "qd", "qdd", "qddd", "tau"):
        cols += [f"{prefix}_{n}" for n in names]
    return [*cols, "min_distance"]


def _front_table(r: PlanningResult) -> np.ndarray:
    fr = r.front
    return np.column_stack([fr.objectives, fr.feasible.astype(float), fr.x])


def _trajectory_table(r: PlanningResult) -> np.ndarray:
    d = r.certificate.dense
    return np.column_stack([d.t, d.q, d.qd, d.qdd, d.qddd, d.tau, d.min_distance])


def _csv_text(header: list[str], rows: np.ndarray, int_columns: Sequence[int] = ()) -> str:
    lines = [",".join(header)]
    for row in rows.tolist():
        cells = [_csv_number(v) for v in row]
        for j in int_columns:
            cells[j] = str(int(row[j]))
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"


def _front_csv(r: PlanningResult) -> str:
    return _csv_text(_front_header(r.front.x.shape[1]), _front_table(r), [len(OBJECTIVE_NAMES)])


def _trajectory_csv(r: PlanningResult) -> str:
    return _csv_text(_trajectory_header(r.robot.joint_names), _trajectory_table(r))


# ============================================================================ decoding
def _read(path: Path) -> str:
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ResultFormatError(path, None, "missing file") from None
    except UnicodeDecodeError as exc:
        raise ResultFormatError(path, None, f"not UTF-8 text ({exc.reason})") from None
    except OSError as exc:
        raise ResultFormatError(path, None, f"cannot read: {exc.strerror or exc}") from None


def _parse_json(path: Path) -> Any:
    """The parsed content of a JSON file (NaN and Infinity refused)."""

    def reject(constant: str) -> Any:
        raise ResultFormatError(path, None, f"holds {constant}, which JSON does not allow")

    try:
        return json.loads(_read(path), parse_constant=reject)
    except json.JSONDecodeError as exc:
        raise ResultFormatError(
            path, None, f"not valid JSON: {exc.msg} (line {exc.lineno}, column {exc.colno})"
        ) from None


class _Reader:
    """Typed access to the parsed JSON, raising ResultFormatError naming file and field."""

    def __init__(self, file: Path) -> None:
        self.file = file

    def error(self, where: str | None, message: str) -> ResultFormatError:
        return ResultFormatError(self.file, where, message)

    def obj(self, value: Any, where: str) -> dict[str, Any]:
        if not isinstance(value, dict):
            raise self.error(where, f"expected an object; got {_kind(value)}")
        return value

    def get(self, parent: Any, key: str, where: str, *, optional: bool = False) -> Any:
        """``parent[key]``; ``where`` is the parent's path ('' at the top)."""
        path = f"{where}.{key}" if where else key
        table = self.obj(parent, where or "(top level)")
        if key not in table:
            if optional:
                return None
            raise self.error(path, "missing")
        return table[key]

    def string(self, value: Any, where: str, *, nullable: bool = False) -> Any:
        if value is None and nullable:
            return None
        if not isinstance(value, str):
            raise self.error(where, f"expected a string; got {_kind(value)}")
        return value

    def strings(self, value: Any, where: str) -> tuple[str, ...]:
        if not isinstance(value, list):
            raise self.error(where, f"expected a list of strings; got {_kind(value)}")
        return tuple(self.string(v, f"{where}[{i}]") for i, v in enumerate(value))

    def integer(self, value: Any, where: str, *, nullable: bool = False) -> Any:
        if value is None and nullable:
            return None
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(where, f"expected an integer; got {_kind(value)}")
        return value

    def boolean(self, value: Any, where: str) -> bool:
        if not isinstance(value, bool):
            raise self.error(where, f"expected true or false; got {_kind(value)}")
        return value

    def number(self, value: Any, where: str, *, null: float | None = None) -> Any:
        """A float; ``null`` maps JSON null to that value (``None`` keeps ``None``)."""
        if value is None:
            if null is None:
                raise self.error(where, "expected a number; got null")
            return null
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.error(where, f"expected a number; got {_kind(value)}")
        return float(value)

    def optional_number(self, value: Any, where: str) -> float | None:
        return None if value is None else self.number(value, where)

    def array(
        self,
        value: Any,
        where: str,
        shape: tuple[int | None, ...],
        *,
        null: float | None = None,
    ) -> np.ndarray:
        """A float array of ``len(shape)`` dimensions (1 or 2; None: any length)."""
        if len(shape) == 1:
            rows = [self._row(value, where, shape[0], null)]
            arr = np.array(rows[0], dtype=float)
        else:
            if not isinstance(value, list):
                raise self.error(where, f"expected a list of rows; got {_kind(value)}")
            if shape[0] is not None and len(value) != shape[0]:
                raise self.error(where, f"expected {shape[0]} rows; got {len(value)}")
            width = shape[1]
            rows = []
            for i, row in enumerate(value):
                rows.append(self._row(row, f"{where}[{i}]", width, null))
                width = len(rows[-1])
            arr = np.array(rows, dtype=float).reshape(len(rows), width or 0)
        arr.flags.writeable = False
        return arr

    def _row(self, value: Any, where: str, size: int | None, null: float | None) -> list[float]:
        if not isinstance(value, list):
            raise self.error(where, f"expected a list of numbers; got {_kind(value)}")
        if size is not None and len(value) != size:
            raise self.error(where, f"expected {size} numbers; got {len(value)}")
        return [self.number(v, f"{where}[{i}]", null=null) for i, v in enumerate(value)]

    def build(self, where: str | None, make: Callable[..., Any], *args: Any, **kw: Any) -> Any:
        """Call a constructor, turning its input errors into ResultFormatError."""
        try:
            return make(*args, **kw)
        except (AdeptTrajError, ValueError, TypeError) as exc:
            raise self.error(where, str(exc)) from None


def _kind(value: Any) -> str:
    if value is None:
        return "null"
    names = {bool: "a boolean", str: "a string", list: "a list", dict: "an object"}
    for t, name in names.items():
        if isinstance(value, t):
            return f"{name} ({str(value)[:40]!r})" if t is str else name
    return f"the number {value!r}" if isinstance(value, (int, float)) else type(value).__name__


def _decode(data: Any, rd: _Reader) -> PlanningResult:
    top = rd.obj(data, "(top level)")
    fmt = rd.get(top, "format", "")
    if fmt != FORMAT:
        raise rd.error("format", f"expected {FORMAT!r}; got {fmt!r}")
    version = rd.get(top, "version", "")
    if isinstance(version, bool) or version != VERSION:
        raise rd.error("version", f"unsupported version {version!r} (this adept_traj reads 1)")

    robot_d = rd.get(top, "robot", "")
    robot = rd.build(
        "robot",
        RobotInfo,
        name=rd.string(rd.get(robot_d, "name", "robot"), "robot.name"),
        joint_names=rd.strings(rd.get(robot_d, "joint_names", "robot"), "robot.joint_names"),
        urdf=rd.string(rd.get(robot_d, "urdf", "robot"), "robot.urdf"),
        params=rd.string(
            rd.get(robot_d, "params", "robot", optional=True), "robot.params", nullable=True
        ),
        tool_frame=rd.string(
            rd.get(robot_d, "tool_frame", "robot", optional=True),
            "robot.tool_frame",
            nullable=True,
        ),
    )
    nq = len(robot.joint_names)
    start = rd.array(rd.get(top, "start", ""), "start", (nq,))
    goal = rd.array(rd.get(top, "goal", ""), "goal", (nq,))
    seed = rd.integer(rd.get(top, "seed", ""), "seed", nullable=True)
    alg = rd.get(top, "algorithm", "")
    algorithm = rd.string(rd.get(alg, "name", "algorithm"), "algorithm.name")
    settings = rd.obj(rd.get(alg, "settings", "algorithm"), "algorithm.settings")

    ps = rd.obj(rd.get(top, "problem_settings", ""), "problem_settings")
    known = {f.name for f in dataclasses.fields(ProblemSettings)}
    for key in ps:
        if key not in known:
            raise rd.error(f"problem_settings.{key}", f"unknown setting (known: {sorted(known)})")
    kwargs = {k: tuple(v) if isinstance(v, list) else v for k, v in ps.items()}
    problem_settings = rd.build("problem_settings", ProblemSettings, **kwargs)

    scene = rd.obj(rd.get(top, "scene", ""), "scene")
    rd.build("scene", Scene.from_dict, scene, source=f"{rd.file} (scene)")

    ld = rd.get(top, "limits", "")

    def lim(key: str, null: float = math.inf) -> np.ndarray:
        return rd.array(rd.get(ld, key, "limits"), f"limits.{key}", (nq,), null=null)

    limits = rd.build(
        "limits",
        JointLimits,
        names=rd.strings(rd.get(ld, "joint_names", "limits"), "limits.joint_names"),
        units=rd.strings(rd.get(ld, "units", "limits"), "limits.units"),
        lower=lim("q_lower", -math.inf),
        upper=lim("q_upper"),
        velocity=lim("qd"),
        acceleration=lim("qdd"),
        jerk=lim("qddd"),
        effort=lim("tau"),
    )

    lbd = rd.get(top, "lower_bound", "")
    lower_bound = KinematicBound(
        times=rd.array(rd.get(lbd, "per_joint", "lower_bound"), "lower_bound.per_joint", (nq,)),
        delta=rd.array(rd.get(lbd, "delta", "lower_bound"), "lower_bound.delta", (nq,)),
        cases=rd.strings(rd.get(lbd, "cases", "lower_bound"), "lower_bound.cases"),
        T_min=rd.number(rd.get(lbd, "T_min", "lower_bound"), "lower_bound.T_min"),
        limiting_joint=rd.integer(
            rd.get(lbd, "limiting_joint", "lower_bound"), "lower_bound.limiting_joint"
        ),
    )

    front = _decode_front(rd.get(top, "front", ""), rd)
    bd = rd.get(top, "best", "")
    best = rd.build(
        "best",
        BestSolution,
        index=rd.integer(rd.get(bd, "index", "best"), "best.index"),
        f_c=rd.optional_number(rd.get(bd, "f_c", "best"), "best.f_c"),
        f_avg=rd.optional_number(rd.get(bd, "F_avg", "best"), "best.F_avg"),
    )
    if best.index >= len(front):
        raise rd.error("best.index", f"{best.index} is not a row of the front ({len(front)} rows)")
    dense = _decode_dense(rd.get(top, "best_trajectory", ""), nq, rd)
    certificate = _decode_certificate(rd.get(top, "certificate", ""), dense, rd)
    if not _equal(certificate.x, front.x[best.index]):
        raise rd.error("certificate.x", f"differs from front[{best.index}].x (the best solution)")

    md = rd.get(top, "metrics", "")
    ref = rd.get(md, "HV_reference_point", "metrics")
    metrics = rd.build(
        "metrics",
        Metrics,
        **{
            name: rd.optional_number(rd.get(md, key, "metrics"), f"metrics.{key}")
            for name, key in _JSON_METRICS.items()
        },
        hv_reference_point=None
        if ref is None
        else rd.array(ref, "metrics.HV_reference_point", (len(OBJECTIVE_NAMES),)),
    )
    td = rd.get(top, "timing", "")
    timing = rd.build(
        "timing",
        Timing,
        total_s=rd.number(rd.get(td, "total_s", "timing"), "timing.total_s"),
        evaluation_s=rd.number(rd.get(td, "evaluation_s", "timing"), "timing.evaluation_s"),
        n_evaluations=rd.integer(rd.get(td, "n_evaluations", "timing"), "timing.n_evaluations"),
        n_generations=rd.integer(rd.get(td, "n_generations", "timing"), "timing.n_generations"),
    )
    history = _decode_history(rd.get(top, "history", "", optional=True), rd)
    vd = rd.obj(rd.get(top, "versions", ""), "versions")
    versions = {k: rd.string(v, f"versions.{k}") for k, v in vd.items()}
    warning = rd.string(rd.get(top, "warning", "", optional=True), "warning", nullable=True)

    result = rd.build(
        None,
        PlanningResult,
        start=start,
        goal=goal,
        robot=robot,
        scene=scene,
        problem_settings=problem_settings,
        limits=limits,
        lower_bound=lower_bound,
        algorithm=algorithm,
        algorithm_settings=settings,
        seed=seed,
        front=front,
        best=best,
        certificate=certificate,
        timing=timing,
        metrics=metrics,
        history=history,
        warning=warning,
        versions=versions,
    )
    stored = rd.boolean(
        rd.get(top["certificate"], "feasible", "certificate"), "certificate.feasible"
    )
    if stored != certificate.feasible:
        raise rd.error(
            "certificate.feasible", f"is {stored} but the stored checks say {certificate.feasible}"
        )
    return result


def _decode_front(value: Any, rd: _Reader) -> Front:
    if not isinstance(value, list) or not value:
        raise rd.error("front", f"expected a non-empty list of solutions; got {_kind(value)}")
    xs, objs, cons, feas = [], [], [], []
    n_var = n_con = None
    for i, item in enumerate(value):
        where = f"front[{i}]"
        xs.append(rd.array(rd.get(item, "x", where), f"{where}.x", (n_var,)))
        objs.append(
            rd.array(
                rd.get(item, "objectives", where), f"{where}.objectives", (len(OBJECTIVE_NAMES),)
            )
        )
        cons.append(rd.array(rd.get(item, "constraints", where), f"{where}.constraints", (n_con,)))
        feas.append(rd.boolean(rd.get(item, "feasible", where), f"{where}.feasible"))
        n_var, n_con = xs[-1].size, cons[-1].size
    return rd.build(
        "front",
        Front,
        x=np.array(xs),
        objectives=np.array(objs),
        constraints=np.array(cons),
        feasible=np.array(feas, dtype=bool),
    )


def _decode_dense(value: Any, nq: int, rd: _Reader) -> DenseTrajectory:
    where = "best_trajectory"
    t = rd.array(rd.get(value, "t", where), f"{where}.t", (None,))
    n = t.size
    arrays: dict[str, np.ndarray] = {"t": t}
    for name in ("q", "qd", "qdd", "qddd", "tau"):
        arrays[name] = rd.array(rd.get(value, name, where), f"{where}.{name}", (n, nq))
    arrays["min_distance"] = rd.array(
        rd.get(value, "min_distance", where), f"{where}.min_distance", (n,), null=math.inf
    )
    return rd.build(where, DenseTrajectory, **arrays)


def _decode_certificate(value: Any, dense: DenseTrajectory, rd: _Reader) -> Certificate:
    w = "certificate"
    nq = dense.nq
    checks = {}
    for kind in LIMIT_KINDS:
        cd = rd.get(value, kind, w)
        kw = f"{w}.{kind}"
        exact = rd.get(cd, "exact", kw)
        checks[kind] = rd.build(
            kw,
            LimitCheck,
            kind=kind,
            dense=rd.array(rd.get(cd, "dense", kw), f"{kw}.dense", (nq,)),
            exact=None if exact is None else rd.array(exact, f"{kw}.exact", (nq,)),
            t_worst=rd.array(rd.get(cd, "t_worst", kw), f"{kw}.t_worst", (nq,)),
            tolerance=rd.number(rd.get(cd, "tolerance", kw), f"{kw}.tolerance"),
        )
    pair = rd.get(value, "closest_pair", w)
    violations = rd.get(value, "violations", w)
    return rd.build(
        w,
        Certificate,
        x=rd.array(rd.get(value, "x", w), f"{w}.x", (None,)),
        rate_hz=rd.number(rd.get(value, "rate_hz", w), f"{w}.rate_hz"),
        margin=rd.number(rd.get(value, "margin", w), f"{w}.margin"),
        min_distance=rd.number(
            rd.get(value, "min_distance", w), f"{w}.min_distance", null=math.inf
        ),
        t_min_distance=rd.optional_number(
            rd.get(value, "t_min_distance", w), f"{w}.t_min_distance"
        ),
        closest_pair=None if pair is None else rd.strings(pair, f"{w}.closest_pair"),
        violations=rd.strings(violations, f"{w}.violations"),
        dense=dense,
        **checks,
    )


def _decode_history(value: Any, rd: _Reader) -> tuple[GenerationRecord, ...] | None:
    if value is None:
        return None
    if not isinstance(value, list):
        raise rd.error("history", f"expected a list or null; got {_kind(value)}")
    out = []
    for i, item in enumerate(value):
        w = f"history[{i}]"
        out.append(
            rd.build(
                w,
                GenerationRecord,
                generation=rd.integer(rd.get(item, "generation", w), f"{w}.generation"),
                n_evaluations=rd.integer(rd.get(item, "n_evaluations", w), f"{w}.n_evaluations"),
                n_feasible=rd.integer(rd.get(item, "n_feasible", w), f"{w}.n_feasible"),
                hypervolume=rd.optional_number(rd.get(item, "hypervolume", w), f"{w}.hypervolume"),
            )
        )
    return tuple(out)


def _check_csv(path: Path, header: list[str], expected: np.ndarray) -> None:
    """Check that the CSV file at ``path`` has ``header`` and the values of ``expected``."""
    rows = list(csv.reader(io.StringIO(_read(path))))
    if not rows or rows[0] != header:
        got = rows[0] if rows else "nothing"
        raise ResultFormatError(path, "header", f"expected {','.join(header)}; got {got}")
    body = [row for row in rows[1:] if row]
    if len(body) != expected.shape[0]:
        raise ResultFormatError(
            path, None, f"expected {expected.shape[0]} data rows as in result.json; got {len(body)}"
        )
    for i, row in enumerate(body):
        if len(row) != len(header):
            raise ResultFormatError(path, f"row {i + 1}", f"expected {len(header)} columns")
        for j, cell in enumerate(row):
            try:
                value = float(cell)
            except ValueError:
                value = math.nan
            if math.isnan(value) or value != expected[i, j]:
                raise ResultFormatError(
                    path,
                    f"row {i + 1}, column {header[j]}",
                    f"{cell!r} is not the number in result.json ({expected[i, j]!r})",
                )


def _check_front_csv(r: PlanningResult, path: Path) -> None:
    _check_csv(path, _front_header(r.front.x.shape[1]), _front_table(r))


def _check_trajectory_csv(r: PlanningResult, path: Path) -> None:
    _check_csv(path, _trajectory_header(r.robot.joint_names), _trajectory_table(r))


# ============================================================================ helpers


def _matrix(value: Any, name: str, shape: tuple[int, int | None] | None = None) -> np.ndarray:
    arr = readonly_copy(as_finite_array(value, name))
    if arr.ndim != 2 or (
        shape is not None
        and (arr.shape[0] != shape[0] or (shape[1] is not None and arr.shape[1] != shape[1]))
    ):
        want = "(n, m)" if shape is None else str(shape).replace("None", "m")
        raise InputShapeError(f"{name} must have shape {want}; got {arr.shape}")
    return arr


def _integer(value: Any, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InvalidInputError(f"{name} must be an integer; got {value!r}")
    return int(value)


def _index(value: Any, name: str) -> int:
    out = _integer(value, name)
    if out < 0:
        raise InvalidInputError(f"{name} must be ≥ 0; got {out}")
    return out


def _optional_float(value: Any, name: str) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool):
        raise InvalidInputError(f"{name} must be a number; got {value!r}")
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number; got {value!r}") from None
    if not math.isfinite(out):
        raise InvalidInputError(f"{name} must be finite; got {value!r}")
    return out


def _metric(value: Any, name: str) -> float | None:
    """A metric: a finite float, or ``None`` (not computed; NaN counts as not computed)."""
    if value is not None and not isinstance(value, bool):
        try:
            if math.isnan(float(value)):
                return None
        except (TypeError, ValueError):
            pass  # reported below
    return _optional_float(value, name)


def _check_type(value: Any, kind: type, name: str) -> None:
    if not isinstance(value, kind):
        raise InvalidInputError(f"{name} must be a {kind.__name__}; got {type(value).__name__}")


def _is_shipped(robot: Robot) -> bool:
    """True for the AdeptOne XL loaded from the shipped URDF and parameter file."""
    from adept_traj.robot.robot import shipped_file

    try:
        urdf, params = shipped_file("adept_one_xl.urdf"), shipped_file("adept_one_xl.toml")
    except AdeptTrajError:
        return False
    if robot.urdf_path is None or robot.params_path is None:
        return False
    return (
        Path(robot.urdf_path).resolve() == urdf.resolve()
        and Path(robot.params_path).resolve() == params.resolve()
    )


def _equal(a: Any, b: Any) -> bool:
    """Deep equality: arrays element-wise (same shape), dataclasses field by field,
    mappings and sequences item by item."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (
            isinstance(a, np.ndarray)
            and isinstance(b, np.ndarray)
            and a.shape == b.shape
            and bool(np.array_equal(a, b))
        )
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        return type(a) is type(b) and all(
            _equal(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a)
        )
    if isinstance(a, Mapping):
        return (
            isinstance(b, Mapping) and a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
        )
    if isinstance(a, (list, tuple)):
        return (
            isinstance(b, (list, tuple))
            and len(a) == len(b)
            and all(_equal(x, y) for x, y in zip(a, b))
        )
    return bool(a == b)
