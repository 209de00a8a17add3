r"""The dense certificate of a trajectory: "feasible" means *verified*.

:func:`certify` re-checks one decision vector of a :class:`~adept_traj.problem.TrajectoryProblem`
on a uniform grid of at least ``rate_hz`` samples per second over :math:`[0, T]`, both ends
included (:math:`n = \lceil T \cdot \text{rate} \rceil + 1` samples), independently of the
optimiser's coarse Gauss–Legendre samples:

- positions, velocities, accelerations and jerks from the spline at every sample, **and** the
  exact per-segment extrema of :meth:`~adept_traj.problem.BSplineTrajectory.bounds`
  (the reported worst value is the larger of the two, so nothing between samples is missed);
- joint torques/forces :math:`u = ` :meth:`~adept_traj.robot.Robot.inverse_dynamics` at every
  sample (the torque is not a polynomial: dense samples only);
- the exact signed distance of **every** robot solid to **every** obstacle at every sample,
  moving obstacles at their pose at that instant (``CollisionChecker.distances(...,
  exact=True)``: coal for each pair, the closed form for sphere obstacles; no broad-phase
  bound stands in for a distance).

Each limit kind is summarised per joint by a :class:`LimitCheck`:

==============  ========================================================================  =========
kind            value per joint                                                           feasible
==============  ========================================================================  =========
position        :math:`\max_t \max(q - q^{\max},\ q^{\min} - q) / (q^{\max} - q^{\min})`  ≤ 0
velocity        :math:`\max_t |\dot q| / VC`                                              ≤ 1
acceleration    :math:`\max_t |\ddot q| / WC`                                             ≤ 1
jerk            :math:`\max_t |\dddot q| / JC`                                            ≤ 1
torque          :math:`\max_k |u(t_k)| / UC`                                              ≤ 1
==============  ========================================================================  =========

(the position value is the problem's constraint :math:`g^q`: ≤ 0 inside the limits, the
fraction of the joint range beyond the nearer limit otherwise; an infinite limit gives the
ratio 0). The certificate is feasible when every value is within its bound plus
``tolerance`` (default 1e-9) **and** the smallest distance over all samples and pairs is at
least the problem's safety margin (no tolerance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError, InvalidInputError
from adept_traj.problem.trajectory_problem import TrajectoryProblem
from adept_traj.validation import as_finite_array, as_vector, readonly_copy

__all__ = [
    "DEFAULT_RATE_HZ",
    "DEFAULT_TOLERANCE",
    "LIMIT_KINDS",
    "Certificate",
    "DenseTrajectory",
    "LimitCheck",
    "certify",
    "dense_samples",
]

#: Default sampling rate of the dense check [Hz].
DEFAULT_RATE_HZ = 1000.0
#: Default tolerance on the limit values (dimensionless ratios).
DEFAULT_TOLERANCE = 1e-9
#: The limit kinds, in the order of the problem's constraints.
LIMIT_KINDS = ("position", "velocity", "acceleration", "jerk", "torque")
#: The paper's name of each limit (Table 2).
_LIMIT_SYMBOL = {
    "position": "QC",
    "velocity": "VC",
    "acceleration": "WC",
    "jerk": "JC",
    "torque": "UC",
}


@dataclass(frozen=True, eq=False)
class DenseTrajectory:
    """A trajectory sampled on a uniform grid (both ends included).

    Attributes
    ----------
    t: (n,) sample times [s], ``t[0] = 0``, ``t[-1] = T``.
    q: (n, nq) positions [rad | m].
    qd: (n, nq) velocities [rad/s | m/s].
    qdd: (n, nq) accelerations [rad/s² | m/s²].
    qddd: (n, nq) jerks [rad/s³ | m/s³].
    tau: (n, nq) joint torques/forces [N·m | N] (inverse dynamics with friction).
    min_distance: (n,) smallest signed distance over every (solid, obstacle) pair [m]
        (negative: penetration depth; ``inf`` when the scene has no obstacle).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    qddd: np.ndarray
    tau: np.ndarray
    min_distance: np.ndarray

    def __post_init__(self) -> None:
        t = readonly_copy(as_finite_array(self.t, "t"))
        if t.ndim != 1 or t.size < 2:
            raise InvalidInputError(f"t must have shape (n,) with n ≥ 2; got {t.shape}")
        object.__setattr__(self, "t", t)
        nq = None
        for name in ("q", "qd", "qdd", "qddd", "tau"):
            arr = readonly_copy(as_finite_array(getattr(self, name), name))
            if arr.ndim != 2 or arr.shape[0] != t.size or (nq is not None and arr.shape[1] != nq):
                raise InvalidInputError(
                    f"{name} must have shape ({t.size}, nq) like the others; got {arr.shape}"
                )
            nq = arr.shape[1]
            object.__setattr__(self, name, arr)
        d = np.array(self.min_distance, dtype=np.float64)
        if d.shape != t.shape or np.isnan(d).any() or (d == -np.inf).any():
            raise InvalidInputError(
                f"min_distance must have shape {t.shape} with no NaN or -inf; got {d.shape}"
            )
        object.__setattr__(self, "min_distance", readonly_copy(d))

    @property
    def n_samples(self) -> int:
        """Number of samples n."""
        return int(self.t.size)

    @property
    def nq(self) -> int:
        """Number of joints."""
        return int(self.q.shape[1])

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return all(
            _arrays_equal(getattr(self, k), getattr(other, k))
            for k in ("t", "q", "qd", "qdd", "qddd", "tau", "min_distance")
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True, eq=False)
class LimitCheck:
    """The worst use of one kind of limit over the trajectory, per joint.

    Attributes
    ----------
    kind: one of :data:`LIMIT_KINDS`.
    dense: (nq,) worst value over the dense samples (see the module table; position:
        fraction of the joint range beyond the nearer limit, ≤ 0 inside; the others: ratio
        to the limit, ≤ 1 within).
    exact: (nq,) the same from the exact spline extrema, or ``None`` (torque: samples only).
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
        tol = float(self.tolerance)
        if not (math.isfinite(tol) and tol >= 0.0):
            raise InvalidInputError(f"tolerance must be finite and ≥ 0; got {self.tolerance!r}")
        object.__setattr__(self, "tolerance", tol)

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

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return (
            self.kind == other.kind
            and self.tolerance == other.tolerance
            and _arrays_equal(self.dense, other.dense)
            and _arrays_equal(self.exact, other.exact)
            and _arrays_equal(self.t_worst, other.t_worst)
        )

    __hash__ = None  # type: ignore[assignment]


@dataclass(frozen=True, eq=False)
class Certificate:
    """The dense verification of one trajectory (see the module docstring).

    Attributes
    ----------
    x: (n_var,) the decision vector checked ``[T, free control points]``.
    rate_hz: requested sampling rate [Hz]; the grid spacing is ``T/(n − 1) ≤ 1/rate_hz``.
    margin: safety margin [m] the distances are checked against.
    position, velocity, acceleration, jerk, torque: the :class:`LimitCheck` of each kind.
    min_distance: smallest signed distance over all samples and pairs [m] (``inf``: no
        obstacle).
    t_min_distance: time [s] where it occurs (``None``: no obstacle).
    closest_pair: ``(solid, obstacle)`` names at that instant (``None``: no obstacle).
    violations: human-readable description of every violated limit, e.g.
        ``"torque joint3: 1.042 × UC at t = 0.512 s"`` (empty when feasible).
    dense: the sampled :class:`DenseTrajectory`.
    """

    x: np.ndarray
    rate_hz: float
    margin: float
    position: LimitCheck
    velocity: LimitCheck
    acceleration: LimitCheck
    jerk: LimitCheck
    torque: LimitCheck
    min_distance: float
    t_min_distance: float | None
    closest_pair: tuple[str, str] | None
    violations: tuple[str, ...]
    dense: DenseTrajectory

    def __post_init__(self) -> None:
        x = readonly_copy(as_finite_array(self.x, "x"))
        if x.ndim != 1 or x.size < 1 or not x[0] > 0:
            raise InvalidInputError(f"x must have shape (n_var,) with T = x[0] > 0; got {x!r}")
        object.__setattr__(self, "x", x)
        object.__setattr__(self, "rate_hz", _positive(self.rate_hz, "rate_hz"))
        margin = float(self.margin)
        if not (math.isfinite(margin) and margin >= 0.0):
            raise InvalidInputError(f"margin must be finite and ≥ 0 [m]; got {self.margin!r}")
        object.__setattr__(self, "margin", margin)
        for kind in LIMIT_KINDS:
            check = getattr(self, kind)
            if not isinstance(check, LimitCheck) or check.kind != kind:
                raise InvalidInputError(f"{kind} must be a LimitCheck of kind {kind!r}")
            if check.dense.size != self.dense.nq:
                raise InvalidInputError(
                    f"{kind} has {check.dense.size} joints, the dense trajectory {self.dense.nq}"
                )
        d = float(self.min_distance)
        if math.isnan(d) or d == -math.inf:
            raise InvalidInputError(f"min_distance must be a number or +inf; got {d!r}")
        object.__setattr__(self, "min_distance", d)
        if self.t_min_distance is not None:
            object.__setattr__(self, "t_min_distance", float(self.t_min_distance))
        if self.closest_pair is not None:
            pair = tuple(str(n) for n in self.closest_pair)
            if len(pair) != 2:
                raise InvalidInputError(f"closest_pair must be (solid, obstacle); got {pair!r}")
            object.__setattr__(self, "closest_pair", pair)
        object.__setattr__(self, "violations", tuple(str(v) for v in self.violations))

    # ------------------------------------------------------------------ summaries
    @property
    def T(self) -> float:
        """Travel time [s]."""
        return float(self.x[0])

    @property
    def n_samples(self) -> int:
        """Number of dense samples."""
        return self.dense.n_samples

    @property
    def checks(self) -> tuple[LimitCheck, ...]:
        """The five :class:`LimitCheck` in the order of :data:`LIMIT_KINDS`."""
        return tuple(getattr(self, kind) for kind in LIMIT_KINDS)

    @property
    def limits_ok(self) -> bool:
        """Every limit of every joint within its bound (+ tolerance)."""
        return all(check.ok for check in self.checks)

    @property
    def distance_ok(self) -> bool:
        """The smallest distance is at least the margin."""
        return self.min_distance >= self.margin

    @property
    def feasible(self) -> bool:
        """Verified feasible: :attr:`limits_ok` and :attr:`distance_ok`."""
        return self.limits_ok and self.distance_ok

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        return (
            _arrays_equal(self.x, other.x)
            and (self.rate_hz, self.margin, self.min_distance, self.t_min_distance)
            == (other.rate_hz, other.margin, other.min_distance, other.t_min_distance)
            and self.closest_pair == other.closest_pair
            and self.violations == other.violations
            and self.checks == other.checks
            and self.dense == other.dense
        )

    __hash__ = None  # type: ignore[assignment]


def dense_samples(T: float, rate_hz: float) -> int:
    """Number of uniform samples over [0, T] [s] with spacing at most 1/``rate_hz`` [Hz],
    both ends included: ``ceil(T·rate) + 1`` (at least 2). The 1e-9 keeps
    T·rate = 2100.0000000000005 at 2100."""
    return max(2, math.ceil(T * rate_hz - 1e-9) + 1)


def certify(
    problem: TrajectoryProblem,
    x: Any,
    rate_hz: float = DEFAULT_RATE_HZ,
    *,
    tolerance: float = DEFAULT_TOLERANCE,
) -> Certificate:
    """Verify the trajectory ``x`` of ``problem`` on a dense uniform grid.

    Parameters
    ----------
    problem:
        The problem (robot, scene, start/goal, margin).
    x:
        (n_var,) decision vector ``[T, free control points]``.
    rate_hz:
        Minimum sampling rate [Hz] (> 0): ``n = ceil(T·rate_hz) + 1`` samples over [0, T].
    tolerance:
        Slack on the limit values (dimensionless, ≥ 0); the distance has none.

    Returns
    -------
    Certificate
        Worst value of every limit per joint (dense and exact), the smallest distance with
        its time and pair, the violations and the :class:`DenseTrajectory`.

    Raises
    ------
    InputShapeError, InvalidInputError
        ``x`` not of shape (n_var,), not finite, ``T ≤ 0``; ``rate_hz`` not > 0.
    ConfigurationError
        A robot limit that is not > 0 (the velocity, acceleration, jerk and effort limits may
        be infinite; the position limits must be finite with lower < upper).
    """
    xa = as_vector(x, "x", problem.n_var)
    T = float(xa[0])
    if not T > 0.0:
        raise InvalidInputError(f"x[0] (travel time T [s]) must be > 0; got {T!r}")
    rate = _positive(rate_hz, "rate_hz")
    tol = float(tolerance)
    if not (math.isfinite(tol) and tol >= 0.0):
        raise InvalidInputError(f"tolerance must be finite and ≥ 0; got {tolerance!r}")
    robot, lim = problem.robot, problem.robot.limits
    span = _limits(lim)

    n = dense_samples(T, rate)
    s = np.linspace(0.0, 1.0, n)
    smp = problem.trajectory.sample(xa, s)
    t, q, qd, qdd, qddd = smp.t, smp.q, smp.qd, smp.qdd, smp.qddd
    tau = robot.inverse_dynamics(q, qd, qdd)
    bounds = problem.trajectory.bounds(xa)

    checker = problem.checker
    if checker.n_obstacles and checker.n_solids:
        pairs = checker.distances(q[None], t[None], exact=True).distance[0]  # (n, ns, no)
        per_sample = pairs.min(axis=(1, 2))
        k, solid, obstacle = np.unravel_index(int(np.argmin(pairs)), pairs.shape)
        min_d = float(pairs[k, solid, obstacle])
        t_min_d: float | None = float(t[k])
        pair: tuple[str, str] | None = (
            checker.solid_names[solid],
            checker.obstacle_names[obstacle],
        )
    else:
        per_sample = np.full(n, np.inf)
        min_d, t_min_d, pair = math.inf, None, None

    excess = np.maximum(q - lim.upper, lim.lower - q) / span  # (n, nq)
    exact_excess = np.maximum(bounds.q_max - lim.upper, lim.lower - bounds.q_min) / span
    checks = {
        "position": _check("position", excess, exact_excess, t, tol),
        "velocity": _ratio_check("velocity", qd, bounds.qd_abs_max, lim.velocity, t, tol),
        "acceleration": _ratio_check(
            "acceleration", qdd, bounds.qdd_abs_max, lim.acceleration, t, tol
        ),
        "jerk": _ratio_check("jerk", qddd, bounds.qddd_abs_max, lim.jerk, t, tol),
        "torque": _ratio_check("torque", tau, None, lim.effort, t, tol),
    }
    violations = [
        message
        for kind in LIMIT_KINDS
        for message in _limit_messages(checks[kind], lim.names, lim.lower, lim.upper)
    ]
    margin = float(problem.settings.margin)
    if min_d < margin and pair is not None:
        violations.append(
            f"distance: {min_d:.4g} m < margin {margin:.4g} m at t = {t_min_d:.3f} s "
            f"({pair[0]} – {pair[1]})"
        )
    dense = DenseTrajectory(t=t, q=q, qd=qd, qdd=qdd, qddd=qddd, tau=tau, min_distance=per_sample)
    return Certificate(
        x=xa,
        rate_hz=rate,
        margin=margin,
        min_distance=min_d,
        t_min_distance=t_min_d,
        closest_pair=pair,
        violations=tuple(violations),
        dense=dense,
        **checks,
    )


# ---------------------------------------------------------------------------- helpers


def _arrays_equal(a: np.ndarray | None, b: np.ndarray | None) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return a.shape == b.shape and bool(np.array_equal(a, b))


def _positive(value: Any, name: str) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise InvalidInputError(f"{name} must be a number > 0; got {value!r}") from None
    if not (math.isfinite(out) and out > 0.0):
        raise InvalidInputError(f"{name} must be finite and > 0; got {value!r}")
    return out


def _limits(lim: Any) -> np.ndarray:
    """Check the robot's limits; return the position ranges (nq,)."""
    span = np.asarray(lim.upper - lim.lower, dtype=float)
    if not (np.all(np.isfinite(lim.lower)) and np.all(np.isfinite(lim.upper)) and np.all(span > 0)):
        raise ConfigurationError(
            f"position limits must be finite with lower < upper; got lower={lim.lower.tolist()}, "
            f"upper={lim.upper.tolist()}"
        )
    for name in ("velocity", "acceleration", "jerk", "effort"):
        value = np.asarray(getattr(lim, name), dtype=float)
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
