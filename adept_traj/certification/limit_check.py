r"""The worst use of each kind of joint limit over a trajectory, per joint.

A :class:`LimitCheck` summarises one of the :data:`LIMIT_KINDS` (position, velocity,
acceleration, jerk, torque; the paper's QC, VC, WC, JC, UC of Table 2) as a dimensionless
value per joint, from dense samples and, where they exist, the exact spline extrema (see
:mod:`adept_traj.certification.certificate` for the table of values and bounds). The private
helpers build the checks and their messages for
:func:`~adept_traj.certification.certificate.certify`.

**The torque between the samples.** The torque :math:`u(t)` is not a polynomial (RNEA of
the spline), so it has no exact extrema. :func:`_refined_torque_check` refines adaptively:
every sample interval :math:`[t_k, t_{k+1}]` where some joint's sampled ratio
:math:`\max(|u_i(t_k)|, |u_i(t_{k+1})|) / UC_i` reaches :data:`TORQUE_REFINE_FRACTION`
(0.9) is re-sampled at :data:`TORQUE_REFINE_FACTOR` (8) times the density with
:meth:`~adept_traj.robot.Robot.inverse_dynamics`; the new sub-intervals that still reach
the fraction are refined again, until the largest ratio grows by less than
:data:`TORQUE_REFINE_TOLERANCE` (1e-4 of UC) from one level to the next, or after
:data:`TORQUE_MAX_LEVELS` (3) levels (512× the grid rate). This is a refinement, not a
bound: the guarantee is labelled ``"sampled at N Hz, refined to M Hz near the limit"``
(M the finest rate reached) or ``"sampled at N Hz, below 0.9 × UC"`` when no interval
reached the fraction.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError, InvalidInputError
from adept_traj.robot.limits import LIMIT_KINDS, LIMITS
from adept_traj.validation import (
    DeepEqual,
    as_finite_array,
    as_scalar,
    as_vector,
    readonly_copy,
)

__all__ = [
    "DEFAULT_TOLERANCE",
    "TORQUE_MAX_LEVELS",
    "TORQUE_REFINE_FACTOR",
    "TORQUE_REFINE_FRACTION",
    "TORQUE_REFINE_TOLERANCE",
    "LimitCheck",
    "limit_checks",
    "position_spans",
]

#: Default tolerance on the limit values (dimensionless ratios).
DEFAULT_TOLERANCE = 1e-9
#: The paper's name of each limit kind (Table 2), from the one vocabulary in robot.limits.
_LIMIT_SYMBOL = {kind.name: kind.symbol for kind in LIMITS}
#: Sample intervals whose torque ratio reaches this fraction of UC are refined.
TORQUE_REFINE_FRACTION = 0.9
#: Density factor of one refinement level (sub-intervals per interval).
TORQUE_REFINE_FACTOR = 8
#: Refinement stops when the largest torque ratio grows by less than this (fraction of UC).
TORQUE_REFINE_TOLERANCE = 1e-4
#: Most refinement levels (the finest rate is ``8**3 = 512`` × the grid rate).
TORQUE_MAX_LEVELS = 3


@dataclass(frozen=True, eq=False)
class LimitCheck(DeepEqual):
    """The worst use of one kind of limit over the trajectory, per joint.

    Attributes
    ----------
    kind: one of :data:`LIMIT_KINDS`.
    dense: (nq,) worst value over the dense samples (see the module table; position:
        fraction of the joint range beyond the nearer limit, ≤ 0 inside; the others: ratio
        to the limit, ≤ 1 within).
    exact: (nq,) the same from the exact spline extrema, or ``None`` (torque: samples only,
        with the refined samples near the limit when the certificate refined them).
    t_worst: (nq,) time [s] of the worst dense sample.
    tolerance: slack allowed beyond :attr:`bound` (dimensionless).
    """

    kind: str
    dense: np.ndarray
    exact: np.ndarray | None
    t_worst: np.ndarray
    tolerance: float = DEFAULT_TOLERANCE

    def __post_init__(self) -> None:
        if self.kind not in LIMIT_KINDS:
            raise InvalidInputError(f"kind must be one of {LIMIT_KINDS}; got {self.kind!r}")
        dense = readonly_copy(as_finite_array(self.dense, f"{self.kind}.dense"))
        if dense.ndim != 1:
            raise InvalidInputError(f"{self.kind}.dense must have shape (nq,); got {dense.shape}")
        object.__setattr__(self, "dense", dense)
        if self.exact is not None:
            exact = readonly_copy(as_vector(self.exact, f"{self.kind}.exact", dense.size))
            object.__setattr__(self, "exact", exact)
        t_worst = readonly_copy(as_vector(self.t_worst, f"{self.kind}.t_worst", dense.size))
        object.__setattr__(self, "t_worst", t_worst)
        object.__setattr__(self, "tolerance", as_scalar(self.tolerance, "tolerance", minimum=0.0))

    @property
    def bound(self) -> float:
        """The largest feasible value: 0 for position, 1 for the ratios."""
        return 0.0 if self.kind == "position" else 1.0

    @property
    def symbol(self) -> str:
        """The paper's name of the limit: QC, VC, WC, JC or UC."""
        return _LIMIT_SYMBOL[self.kind]

    @property
    def worst(self) -> np.ndarray:
        """(nq,) the larger of :attr:`dense` and :attr:`exact` (dense alone for torque)."""
        return self.dense if self.exact is None else np.maximum(self.dense, self.exact)

    @property
    def within(self) -> np.ndarray:
        """(nq,) bool: ``worst ≤ bound + tolerance``."""
        return self.worst <= self.bound + self.tolerance

    @property
    def ok(self) -> bool:
        """Every joint within the limit."""
        return bool(self.within.all())

    __hash__ = None  # type: ignore[assignment]


def position_spans(lim: Any) -> np.ndarray:
    """The position ranges of checked joint limits.

    Parameters
    ----------
    lim:
        The robot's :class:`~adept_traj.robot.JointLimits`.

    Returns
    -------
    numpy.ndarray
        (nq,) ``upper - lower`` [rad | m].

    Raises
    ------
    ConfigurationError
        A position limit is not finite or not lower < upper, or another limit is not > 0
        (``inf`` allowed).
    """
    span = np.asarray(lim.upper - lim.lower, dtype=float)
    if not (np.all(np.isfinite(lim.lower)) and np.all(np.isfinite(lim.upper)) and np.all(span > 0)):
        raise ConfigurationError(
            f"position limits must be finite with lower < upper; got lower={lim.lower.tolist()}, "
            f"upper={lim.upper.tolist()}"
        )
    for name in LIMIT_KINDS[1:]:
        value = np.asarray(lim.bound(name), dtype=float)
        if not np.all(value > 0):  # NaN, 0 and negative values; inf is allowed
            raise ConfigurationError(
                f"{name} limits must be > 0 (inf allowed); got {value.tolist()}"
            )
    return span


def _check(
    kind: str, values: np.ndarray, exact: np.ndarray | None, t: np.ndarray, tol: float
) -> LimitCheck:
    """LimitCheck from per-sample values (n, nq) (already normalised)."""
    worst = np.argmax(values, axis=0)
    dense = values[worst, np.arange(values.shape[1])]
    return LimitCheck(kind=kind, dense=dense, exact=exact, t_worst=t[worst], tolerance=tol)


def _ratio_check(
    kind: str,
    values: np.ndarray,
    exact_abs_max: np.ndarray | None,
    limit: np.ndarray,
    t: np.ndarray,
    tol: float,
) -> LimitCheck:
    """LimitCheck of max |value| / limit (an infinite limit gives 0)."""
    ratio = np.abs(values) / limit
    exact = None if exact_abs_max is None else exact_abs_max / limit
    return _check(kind, ratio, exact, t, tol)


def _limit_messages(
    check: LimitCheck,
    names: tuple[str, ...],
    lower: np.ndarray,
    upper: np.ndarray,
) -> list[str]:
    """One message per joint whose limit of this kind is violated."""
    out = []
    for i in np.flatnonzero(~check.within):
        worst, dense = float(check.worst[i]), float(check.dense[i])
        at = f"at t = {check.t_worst[i]:.3f} s"
        if check.exact is not None and dense <= check.bound + check.tolerance:
            at = f"between samples (exact spline bound; dense worst {dense:.4g} {at})"
        if check.kind == "position":
            out.append(
                f"position {names[i]}: {worst:.4g} of the range beyond its limits "
                f"[{lower[i]:.6g}, {upper[i]:.6g}] {at}"
            )
        else:
            out.append(f"{check.kind} {names[i]}: {worst:.4g} × {check.symbol} {at}")
    return out


def _refined_torque_check(
    problem: Any, x: np.ndarray, t: np.ndarray, tau: np.ndarray, tol: float
) -> tuple[LimitCheck, str]:
    """The torque :class:`LimitCheck` over the uniform samples ``t`` (n,) [s] with torques
    ``tau`` (n, nq) [N·m | N], refined near the limit (module docstring), and its
    guarantee label."""
    limit = np.asarray(problem.robot.limits.torque, dtype=float)
    T, grid_hz = float(x[0]), (t.size - 1) / float(t[-1] - t[0])
    ratio = np.abs(tau) / limit  # (n, nq)
    best_t = [t]
    best_r = [ratio]
    worst = ratio.max()
    near = np.maximum(ratio[:-1], ratio[1:]).max(axis=1) >= TORQUE_REFINE_FRACTION
    left, h = t[:-1][near], float(t[1] - t[0])  # interval starts (m,) [s] and width [s]
    levels = 0
    while left.size and levels < TORQUE_MAX_LEVELS:
        levels += 1
        h /= TORQUE_REFINE_FACTOR
        steps = np.arange(TORQUE_REFINE_FACTOR + 1) * h  # both ends, to test sub-intervals
        tt = np.minimum(left[:, None] + steps[None, :], T)  # (m, 9)
        smp = problem.trajectory.sample(x, tt.ravel() / T, orders=(0, 1, 2))
        r = (np.abs(problem.robot.inverse_dynamics(smp.q, smp.qd, smp.qdd)) / limit).reshape(
            (*tt.shape, limit.size)
        )  # (m, 9, nq)
        best_t.append(tt.ravel())
        best_r.append(r.reshape(-1, limit.size))
        grown, worst = r.max() - worst, max(worst, r.max())
        if grown < TORQUE_REFINE_TOLERANCE:
            break
        sub = np.maximum(r[:, :-1], r[:, 1:]).max(axis=2) >= TORQUE_REFINE_FRACTION  # (m, 8)
        left = tt[:, :-1][sub]
    check = _check("torque", np.concatenate(best_r), None, np.concatenate(best_t), tol)
    if levels:
        label = (
            f"sampled at {grid_hz:g} Hz, refined to "
            f"{grid_hz * TORQUE_REFINE_FACTOR**levels:g} Hz near the limit"
        )
    else:
        label = f"sampled at {grid_hz:g} Hz, below {TORQUE_REFINE_FRACTION:g} × UC"
    return check, label


def limit_checks(
    problem: Any,
    x: np.ndarray,
    smp: Any,
    tau: np.ndarray,
    bounds: Any,
    tol: float,
    continuous: bool,
) -> tuple[dict[str, LimitCheck], str, list[str]]:
    """The five limit checks of the certificate of one move.

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    x:
        (n_var,) the move.
    smp:
        Its dense spline samples: ``t`` (n,) [s], ``q, qd, qdd, qddd`` (n, nq).
    tau:
        (n, nq) [N·m | N] the torques at the samples.
    bounds:
        The spline's exact extrema of ``x``
        (:meth:`~adept_traj.problem.BSplineTrajectory.bounds`).
    tol:
        Tolerance of every ratio.
    continuous:
        Refine the torque near its limit (:func:`_refined_torque_check`).

    Returns
    -------
    tuple
        The :class:`LimitCheck` by kind (position … torque), the torque's guarantee label
        and the messages of the violated limits.
    """
    lim = problem.robot.limits
    span = position_spans(lim)
    t, q, n = smp.t, smp.q, len(smp.t)
    excess = np.maximum(q - lim.upper, lim.lower - q) / span  # (n, nq)
    exact_excess = np.maximum(bounds.q_max - lim.upper, lim.lower - bounds.q_min) / span
    checks = {
        "position": _check("position", excess, exact_excess, t, tol),
        "velocity": _ratio_check("velocity", smp.qd, bounds.qd_abs_max, lim.velocity, t, tol),
        "acceleration": _ratio_check(
            "acceleration", smp.qdd, bounds.qdd_abs_max, lim.acceleration, t, tol
        ),
        "jerk": _ratio_check("jerk", smp.qddd, bounds.qddd_abs_max, lim.jerk, t, tol),
    }
    if continuous:
        checks["torque"], torque_guarantee = _refined_torque_check(problem, x, t, tau, tol)
    else:
        checks["torque"] = _ratio_check("torque", tau, None, lim.torque, t, tol)
        torque_guarantee = f"sampled at {(n - 1) / float(x[0]):g} Hz"
    violations = [
        message
        for kind in LIMIT_KINDS
        for message in _limit_messages(checks[kind], lim.names, lim.lower, lim.upper)
    ]
    return checks, torque_guarantee, violations
