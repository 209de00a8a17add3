"""The parts of a :class:`~adept_traj.results.PlanningResult`: the robot's description, the
final front, the chosen solution, the quality metrics, the cost of the run and its
per-generation progress.

Every part is a frozen dataclass that checks and normalises its fields when built (arrays
become read-only float64 copies; NaN is refused, except in a metric, where it means "not
computed" and becomes ``None``); bad input raises
:class:`~adept_traj.errors.InvalidInputError` naming the field.
"""

from __future__ import annotations

import dataclasses
import math
import platform
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.certification.member_certificate import MemberCertificate
from adept_traj.errors import AdeptTrajError, InputShapeError, InvalidInputError
from adept_traj.problem import OBJECTIVE_NAMES, Evaluation
from adept_traj.robot import RobotSource
from adept_traj.robot.robot import Robot, shipped_file
from adept_traj.validation import (
    DeepEqual,
    as_finite_array,
    as_integer,
    as_scalar,
    readonly_copy,
)

__all__ = [
    "SHIPPED_ROBOT",
    "BestSolution",
    "Front",
    "GenerationRecord",
    "Metrics",
    "RobotInfo",
    "Timing",
    "software_versions",
]

#: Marker stored as ``robot.urdf`` for the shipped AdeptOne XL (URDF + parameter file).
SHIPPED_ROBOT = "adept_one_xl"
#: Field names of :class:`Metrics` that hold a number (or ``None``).
METRIC_NAMES = ("ssm", "rni", "oo", "ae", "hv")
#: Sources of :attr:`Metrics.t_best`: the fastest member's polish, the time-optimal mode.
T_BEST_SOURCES = ("polish", "time-optimal")


def _optional_scalar(value: Any, name: str, unit: str = "", minimum: float = -math.inf) -> Any:
    """``None`` as is, else a finite float ≥ ``minimum`` (:func:`as_scalar`)."""
    return None if value is None else as_scalar(value, name, unit, minimum=minimum)


def _metric(value: Any, name: str) -> float | None:
    """A metric: a finite float, or ``None`` (not computed; a float NaN counts as such)."""
    if isinstance(value, (float, np.floating)) and math.isnan(value):
        return None
    return _optional_scalar(value, name)


# ============================================================================ robot
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
    package_dirs: the folders where the URDF's ``package://`` meshes were found (absolute),
        searched first when the robot is rebuilt (no ``ROS_PACKAGE_PATH`` needed).
    locked_joints: joints fixed at a value [rad | m] (name → value).
    srdf: the SRDF given (its ``disable_collisions`` pairs), or ``None``.
    """

    name: str
    joint_names: tuple[str, ...]
    urdf: str
    params: str | None = None
    tool_frame: str | None = None
    package_dirs: tuple[str, ...] = ()
    locked_joints: Mapping[str, float] = field(default_factory=dict)
    srdf: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "joint_names", tuple(str(n) for n in self.joint_names))
        object.__setattr__(self, "package_dirs", tuple(str(p) for p in self.package_dirs))
        locked = {str(k): float(v) for k, v in dict(self.locked_joints).items()}
        object.__setattr__(self, "locked_joints", locked)
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
            package_dirs=tuple(str(p.resolve()) for p in robot.package_dirs),
            locked_joints=robot.locked_joints,
            srdf=None if robot.srdf_path is None else str(Path(robot.srdf_path).resolve()),
        )

    def as_json(self) -> dict[str, Any]:
        """The ``robot`` object of ``result.json``; ``package_dirs``, ``locked_joints`` and
        ``srdf`` only when not empty (files written before them have neither, and must re-encode
        to themselves)."""
        out = dataclasses.asdict(self) | {
            "joint_names": list(self.joint_names),
            "package_dirs": list(self.package_dirs),
        }
        optional = ("package_dirs", "locked_joints", "srdf")
        return {k: v for k, v in out.items() if v or k not in optional}

    def source(self) -> RobotSource:
        """Where the robot is loaded from (the shipped AdeptOne XL: ``RobotSource()``)."""
        if self.urdf == SHIPPED_ROBOT:
            return RobotSource()
        files = ("params", "tool_frame", "package_dirs", "srdf", "locked_joints")
        return RobotSource(self.urdf, **{name: getattr(self, name) for name in files})

    def load(self) -> Robot:
        """Rebuild the robot (raises :class:`~adept_traj.errors.RobotModelError` when its
        files are gone)."""
        return self.source().load()


def _is_shipped(robot: Robot) -> bool:
    """True for the AdeptOne XL loaded from the shipped URDF and parameter file."""
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


# ============================================================================ front
@dataclass(frozen=True, eq=False)
class Front(DeepEqual):
    """A set of solutions: the final non-dominated set of a run.

    Attributes
    ----------
    x: (n, n_var) decision vectors ``[T, free control points]``.
    objectives: (n, 6) z1…z6, **z4 positive** (as reported, not pymoo's negated value).
    constraints: (n, n_con) normalised constraints g (≤ 0 satisfied), the problem's order.
    feasible: (n,) bool, as decided by the engine (the certificate for "verified").
    n_certified: members whose certificate passed with the continuous guarantee, when
        :func:`~adept_traj.plan` certified every member: ``feasible`` is then the
        certificate's verdict and ``n_certified == feasible.sum()``. ``None``: ``feasible``
        is the optimiser's verdict at its samples (results saved before).
    """

    x: np.ndarray
    objectives: np.ndarray
    constraints: np.ndarray
    feasible: np.ndarray
    n_certified: int | None = None
    certificates: tuple[MemberCertificate | None, ...] | None = None

    def __post_init__(self) -> None:
        n = None
        for name, width in (
            ("x", None),
            ("objectives", len(OBJECTIVE_NAMES)),
            ("constraints", None),
        ):
            arr = readonly_copy(as_finite_array(getattr(self, name), f"front.{name}"))
            n = arr.shape[0] if n is None and arr.ndim == 2 else n
            if arr.ndim != 2 or arr.shape[0] != n or width not in (None, arr.shape[1]):
                want = f"({n}, {width or 'm'})" if n is not None else "(n, m)"
                raise InputShapeError(f"front.{name} must have shape {want}; got {arr.shape}")
            object.__setattr__(self, name, arr)
        feas = np.array(self.feasible)
        if feas.shape != (n,) or feas.dtype != bool:
            raise InputShapeError(
                f"front.feasible must be a bool array of shape ({n},); got {feas.dtype} "
                f"{feas.shape}"
            )
        feas.flags.writeable = False
        object.__setattr__(self, "feasible", feas)
        if self.n_certified is not None:
            count = as_integer(self.n_certified, "front.n_certified", minimum=0)
            if count != int(feas.sum()):
                raise InvalidInputError(
                    f"front.n_certified must be the number of feasible (certified) members, "
                    f"{int(feas.sum())}; got {count}"
                )
            object.__setattr__(self, "n_certified", count)
        if self.certificates is not None:
            object.__setattr__(self, "certificates", self._checked_certificates(feas))

    def _checked_certificates(self, feasible: np.ndarray) -> tuple[MemberCertificate | None, ...]:
        """The member certificates as a tuple, one per member, each agreeing with
        ``feasible`` (n,)."""
        if self.n_certified is None:
            raise InvalidInputError("front.certificates needs front.n_certified")
        certificates = tuple(self.certificates)
        if len(certificates) != len(feasible):
            raise InputShapeError(
                f"front.certificates must have one entry per member, {len(feasible)}; "
                f"got {len(certificates)}"
            )
        for i, (c, ok) in enumerate(zip(certificates, feasible)):
            if c is not None and not isinstance(c, MemberCertificate):
                raise InvalidInputError(
                    f"front.certificates[{i}] must be a MemberCertificate or None; "
                    f"got {type(c).__name__}"
                )
            if bool(ok) != (c is not None and c.feasible):
                raise InvalidInputError(
                    f"front.feasible[{i}] is {bool(ok)} but its certificate says "
                    f"{'not certified' if c is None else c.feasible}"
                )
        return certificates

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
        feasible = self.feasible[mask]
        certified = None if self.n_certified is None else int(np.sum(feasible))
        certificates = None
        if self.certificates is not None:
            certificates = tuple(self.certificates[i] for i in np.arange(len(self))[mask])
        return Front(
            self.x[mask],
            self.objectives[mask],
            self.constraints[mask],
            feasible,
            certified,
            certificates,
        )


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
        object.__setattr__(self, "index", as_integer(self.index, "best.index", minimum=0))
        object.__setattr__(self, "f_c", _optional_scalar(self.f_c, "best.f_c"))
        object.__setattr__(self, "f_avg", _optional_scalar(self.f_avg, "best.f_avg"))


# ============================================================================ run
@dataclass(frozen=True, eq=False)
class Metrics(DeepEqual):
    """Quality metrics of the front (``None``: not computed; NaN is stored as ``None``).

    Attributes
    ----------
    ssm, rni, oo, ae: the paper's spacing (SSM), ratio of non-dominated individuals (RNI),
        optimiser overhead (OO) and algorithm effort (AE), as the engine defines them.
    hv, hv_reference_point: hypervolume of the normalised front w.r.t. the (6,) reference point.
    t_best, t_best_source: T_best [s], the z1 of the front's fastest certified member when
        the local solver made it, and that solver (:data:`T_BEST_SOURCES`); ``None``: not
        computed (no polish, or no polished move is the fastest certified member).
    """

    ssm: float | None = None
    rni: float | None = None
    oo: float | None = None
    ae: float | None = None
    hv: float | None = None
    hv_reference_point: np.ndarray | None = None
    t_best: float | None = None
    t_best_source: str | None = None

    def __post_init__(self) -> None:
        for name in METRIC_NAMES:
            object.__setattr__(self, name, _metric(getattr(self, name), f"metrics.{name}"))
        t_best, src = _optional_scalar(self.t_best, "metrics.t_best", "s"), self.t_best_source
        object.__setattr__(self, "t_best", t_best)
        if (t_best is None) != (src is None) or src not in (None, *T_BEST_SOURCES):
            raise InvalidInputError(f"metrics.t_best_source {src!r}: {T_BEST_SOURCES} with t_best")
        if self.hv_reference_point is not None:
            ref = readonly_copy(as_finite_array(self.hv_reference_point, "hv_reference_point"))
            if ref.ndim != 1:
                raise InputShapeError(f"hv_reference_point must be 1-D; got {ref.shape}")
            object.__setattr__(self, "hv_reference_point", ref)


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
            value = as_scalar(getattr(self, name), f"timing.{name}", "[s]", minimum=0.0)
            object.__setattr__(self, name, value)
        for name in ("n_evaluations", "n_generations"):
            value = as_integer(getattr(self, name), f"timing.{name}", minimum=0)
            object.__setattr__(self, name, value)


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
            value = as_integer(getattr(self, name), f"history.{name}", minimum=0)
            object.__setattr__(self, name, value)
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
