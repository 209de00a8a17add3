"""The result of a planning run (:class:`PlanningResult`): a record of what the run
produced, checked when built.

A result folder holds three files (schema: ``docs/results.md``)::

    result.json           everything, the authoritative copy (format "adept_traj.result", v1)
    front.csv             the final front: z1..z6, feasible, x0..x{n_var-1}
    best_trajectory.csv   the certified best trajectory at ≥ 1 kHz: t, q_*, qd_*, qdd_*,
                          qddd_*, tau_*, min_distance

:meth:`PlanningResult.save` writes them (creating the folder), :meth:`PlanningResult.load`
reads them back: every field round-trips exactly (floats are written with Python's
shortest round-trip representation), arrays come back as read-only numpy arrays. Nothing is
ever pickled. The codecs live beside this module: :mod:`~adept_traj.results.json_codec`
(``result.json``) and :mod:`~adept_traj.results.csv_codec` (the two CSV files and their
agreement with ``result.json``); the parts of a result (:class:`~adept_traj.results.Front`,
:class:`~adept_traj.results.BestSolution`, …) are in :mod:`~adept_traj.results.parts`.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.certification.certificate import Certificate, DenseTrajectory
from adept_traj.collision import SelfPairs
from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.problem import (
    OBJECTIVE_NAMES,
    KinematicBound,
    ProblemSettings,
    TrajectoryProblem,
)
from adept_traj.results import parts
from adept_traj.results.csv_codec import (
    check_front_csv,
    check_trajectory_csv,
    write_front_csv,
    write_trajectory_csv,
)
from adept_traj.results.json_codec import (
    FORMAT,
    READ_VERSIONS,
    VERSION,
    read_json,
    write_json,
)
from adept_traj.results.json_values import jsonable
from adept_traj.results.unchecked import unchecked
from adept_traj.robot import Robot
from adept_traj.robot.limits import JointLimits
from adept_traj.scene.scene import Scene
from adept_traj.validation import (
    DeepEqual,
    as_finite_array,
    as_integer,
    check_type,
    deep_equal,
    readonly_copy,
)

__all__ = [
    "FORMAT",
    "FRONT_FILE",
    "NO_FEASIBLE_WARNING",
    "READ_VERSIONS",
    "RESULT_FILE",
    "TRAJECTORY_FILE",
    "VERSION",
    "PlanningResult",
]

#: File names inside a result folder.
RESULT_FILE = "result.json"
FRONT_FILE = "front.csv"
TRAJECTORY_FILE = "best_trajectory.csv"
#: Warning set when no solution of the front is feasible.
NO_FEASIBLE_WARNING = "no feasible solution found: the front holds the least-infeasible solutions"


# ============================================================================ the result
@dataclass(frozen=True, eq=False)
class PlanningResult(DeepEqual):
    """Everything a planning run produces (see ``docs/results.md`` for the file schema).

    Build one with :meth:`from_problem` (fills the problem-derived fields) or directly.

    Attributes
    ----------
    start, goal: (nq,) rest configurations [rad | m].
    robot: :class:`~adept_traj.results.RobotInfo`.
    scene: the scene as :meth:`Scene.to_dict` (a :class:`Scene` is accepted and converted).
    problem_settings: the problem's :class:`ProblemSettings`.
    limits: the robot's :class:`JointLimits` (SI).
    lower_bound: the kinematic lower bound of the travel time (:class:`KinematicBound`).
    algorithm: name of the optimiser as run (``"nsga2"``, ``"mode"``, …).
    algorithm_settings: its settings, stored as a JSON-compatible copy (numpy values become
        Python values, tuples lists, non-finite floats ``None``, other objects ``str``).
    seed: random seed, or ``None``.
    front: the final non-dominated set (:class:`~adept_traj.results.Front`, n ≥ 1); when
        nothing is feasible, the least-infeasible solutions.
    best: the chosen solution (:class:`~adept_traj.results.BestSolution`, an index into
        ``front``).
    certificate: the dense :class:`~adept_traj.analysis.Certificate` of the best
        solution (its ``x`` must equal ``front.x[best.index]``).
    timing: :class:`~adept_traj.results.Timing`.
    metrics: :class:`~adept_traj.results.Metrics` (default: none computed).
    history: per-generation :class:`~adept_traj.results.GenerationRecord` tuple, or ``None``.
    warning: a warning for the reader; defaults to :data:`NO_FEASIBLE_WARNING` when no
        solution of the front is feasible.
    versions: software versions (default: :func:`~adept_traj.results.software_versions` now).
    self_pairs: the link pairs the self-collision check covered and those it left out,
        with why (:class:`~adept_traj.collision.SelfPairs`); ``None``: self-collision off
        (or a file written before the field).
    unchecked: what the certificate did not check (limits the robot lacks, self-collision
        off: :func:`~adept_traj.results.unchecked.unchecked`; ``None``: nothing unchecked,
        or not recorded (a result saved before the field) —
        :func:`~adept_traj.results.unchecked.unchecked_of` derives it).
    """

    start: np.ndarray
    goal: np.ndarray
    robot: parts.RobotInfo
    scene: dict[str, Any]
    problem_settings: ProblemSettings
    limits: JointLimits
    lower_bound: KinematicBound
    algorithm: str
    algorithm_settings: dict[str, Any]
    seed: int | None
    front: parts.Front
    best: parts.BestSolution
    certificate: Certificate
    timing: parts.Timing
    metrics: parts.Metrics = field(default_factory=parts.Metrics)
    history: tuple[parts.GenerationRecord, ...] | None = None
    warning: str | None = None
    versions: dict[str, str] = field(default_factory=parts.software_versions)
    self_pairs: SelfPairs | None = None
    unchecked: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        if self.unchecked is not None:  # () is stored as None: nothing to say either way
            statements = tuple(str(u) for u in self.unchecked)
            object.__setattr__(self, "unchecked", statements or None)
        if self.self_pairs is not None:
            check_type(self.self_pairs, SelfPairs, "self_pairs")
        check_type(self.robot, parts.RobotInfo, "robot")
        check_type(self.problem_settings, ProblemSettings, "problem_settings")
        check_type(self.limits, JointLimits, "limits")
        check_type(self.lower_bound, KinematicBound, "lower_bound")
        check_type(self.front, parts.Front, "front")
        check_type(self.best, parts.BestSolution, "best")
        check_type(self.certificate, Certificate, "certificate")
        check_type(self.timing, parts.Timing, "timing")
        check_type(self.metrics, parts.Metrics, "metrics")
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
        object.__setattr__(self, "scene", jsonable(scene))
        if not isinstance(self.algorithm, str) or not self.algorithm:
            raise InvalidInputError(f"algorithm must be a non-empty name; got {self.algorithm!r}")
        if not isinstance(self.algorithm_settings, Mapping):
            raise InvalidInputError("algorithm_settings must be a mapping")
        object.__setattr__(self, "algorithm_settings", jsonable(self.algorithm_settings))
        if self.seed is not None:
            object.__setattr__(self, "seed", as_integer(self.seed, "seed"))
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
        if not deep_equal(self.certificate.x, fr.x[self.best.index]):
            raise InvalidInputError("certificate.x must equal front.x[best.index]")
        if self.certificate.dense.nq != nq or self.lower_bound.times.shape != (nq,):
            raise InputShapeError(f"certificate and lower_bound must have {nq} joints")
        ref = self.metrics.hv_reference_point
        if ref is not None and ref.shape != (len(OBJECTIVE_NAMES),):
            raise InputShapeError(f"metrics.hv_reference_point must have shape (6,); {ref.shape}")
        if self.history is not None:
            history = tuple(self.history)
            for i, rec in enumerate(history):
                check_type(rec, parts.GenerationRecord, f"history[{i}]")
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
        front: parts.Front,
        best: parts.BestSolution,
        certificate: Certificate,
        timing: parts.Timing,
        metrics: parts.Metrics | None = None,
        history: Iterable[parts.GenerationRecord] | None = None,
        warning: str | None = None,
    ) -> PlanningResult:
        """A result whose start, goal, robot, scene, settings, limits and lower bound are
        taken from ``problem``."""
        return cls(
            start=problem.start,
            goal=problem.goal,
            robot=parts.RobotInfo.of(problem.robot),
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
            metrics=metrics if metrics is not None else parts.Metrics(),
            history=None if history is None else tuple(history),
            warning=warning,
            self_pairs=problem.self_pairs,
            unchecked=unchecked(problem.robot.limits, problem.settings),
        )

    def problem(self, robot: Robot | None = None) -> TrajectoryProblem:
        """Rebuild the whole :class:`TrajectoryProblem` of the run, e.g. to certify the best
        solution again (``certify(result.problem(), result.best_x)``).

        This reloads the robot files (they must still exist; or give the ``robot``, e.g.
        loaded from files that moved: ``adept-traj verify --robot``), parses the stored
        scene and builds the problem's collision checker and distance tables; close it when
        done (``problem.close()``). To view, plot or export the motion, use the lighter
        :class:`~adept_traj.results.Replay` (``Replay.of(result)``: robot, scene and spline
        only), as the modules of :mod:`adept_traj.results` do.
        """
        if robot is not None:
            check_type(robot, Robot, "robot")
        return TrajectoryProblem(
            self.robot.load() if robot is None else robot,
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
    def feasible_front(self) -> parts.Front:
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

    @property
    def gap_best(self) -> float | None:
        """Best travel time over the best T the parametrisation reached in the run,
        ``z1 / metrics.t_best`` (≥ 1); ``None`` when T_best was not computed."""
        t_best = self.metrics.t_best
        return float(self.best_objectives[0]) / t_best if t_best else None

    # ------------------------------------------------------------------ files
    def save(self, folder: str | os.PathLike[str]) -> Path:
        """Write ``result.json``, ``front.csv`` and ``best_trajectory.csv`` into ``folder``
        (created if needed; existing files are replaced). Returns the folder's path."""
        path = Path(folder)
        path.mkdir(parents=True, exist_ok=True)
        write_json(self, path / RESULT_FILE)
        write_front_csv(self, path / FRONT_FILE)
        write_trajectory_csv(self, path / TRAJECTORY_FILE)
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
        result = read_json(path / RESULT_FILE, cls)
        check_front_csv(result, path / FRONT_FILE)
        check_trajectory_csv(result, path / TRAJECTORY_FILE)
        return result
