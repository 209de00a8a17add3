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
  bound stands in for a distance); with self-collision on, the distance between the
  robot's own solids too (:mod:`~adept_traj.certification.self_distance`, part of the verdict).

Each limit kind is summarised per joint by a :class:`LimitCheck`:

==============  ========================================================================  =========
kind            value per joint                                                           feasible
==============  ========================================================================  =========
position        :math:`\max_t \max(q - q^{\max},\ q^{\min} - q) / (q^{\max} - q^{\min})`  ≤ 0
velocity        :math:`\max_t |\dot q| / VC`                                              ≤ 1
acceleration    :math:`\max_t |\ddot q| / WC`                                             ≤ 1
jerk            :math:`\max_t |\dddot q| / JC`                                            ≤ 1
torque          :math:`\max_k |u(t_k)| / UC` (refined near the limit, see below)          ≤ 1
==============  ========================================================================  =========

(the position value is the problem's constraint :math:`g^q`: ≤ 0 inside the limits, the
fraction of the joint range beyond the nearer limit otherwise; an infinite limit gives the
ratio 0). The certificate is feasible when every value is within its bound plus
``tolerance`` (default 1e-9) **and** the smallest distance over all samples and pairs is at
least the problem's safety margin (no tolerance).

**Between the samples** (``continuous=True``, the default),
:mod:`~adept_traj.certification.continuous` bounds the distance on every sample interval
from the robot's and the obstacles' point speeds and bisects the intervals where the bound
misses the margin; the refined samples join the distance check.
:attr:`Certificate.guarantee` then says ``"continuous"`` (the distance is
at least the margin at every instant: :attr:`Certificate.distance_bound` ≥ margin) or
``"sampled at N Hz"`` (the finest rate reached); :attr:`Certificate.certified` is
:attr:`~Certificate.feasible` with the continuous guarantee. The torque has no exact
extrema: with ``continuous=True`` the sample intervals near the torque limit (≥ 0.9 UC) are
re-sampled 8× denser with RNEA until the largest ratio stops growing (by < 1e-4 UC, at
most 512× the grid rate; :mod:`~adept_traj.certification.limit_check`), and
:attr:`Certificate.torque_guarantee` says so honestly: ``"sampled at N Hz, refined to M Hz
near the limit"`` or ``"sampled at N Hz, below 0.9 × UC"`` (``continuous=False``:
``"sampled at N Hz"``). It is a refinement, not a proven bound.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.certification.continuous import (
    CONTINUOUS,
    DEFAULT_MAX_DEPTH,
    SampledMove,
    continuous_distance,
)
from adept_traj.certification.dense_trajectory import (
    DenseStates,
    DenseTrajectory,
    dense_samples,
    dense_states,
)
from adept_traj.certification.limit_check import (
    DEFAULT_TOLERANCE,
    LimitCheck,
    limit_checks,
    position_spans,
)
from adept_traj.certification.self_distance import (
    SelfDistance,
    normalise_distance_fields,
    self_distance,
)
from adept_traj.errors import InvalidInputError
from adept_traj.memory import check_memory
from adept_traj.problem.trajectory_problem import TrajectoryProblem
from adept_traj.robot.limits import LIMIT_KINDS
from adept_traj.validation import (
    DeepEqual,
    as_finite_array,
    as_integer,
    as_scalar,
    as_vector,
    check_type,
    readonly_copy,
)

__all__ = [
    "DEFAULT_RATE_HZ",
    "Certificate",
    "certificate_bytes",
    "certify",
    "certify_states",
    "check_certificate_memory",
]

#: Default sampling rate of the dense check [Hz].
DEFAULT_RATE_HZ = 1000.0


@dataclass(frozen=True, eq=False)
class Certificate(DeepEqual):
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
    guarantee: ``"continuous"`` or ``"sampled at N Hz"`` for the distance (``None``: not
        recorded, e.g. a result saved before the continuous check).
    distance_bound: lower bound [m] of the distance at every instant of [0, T] (``None``:
        not computed; ``inf``: no obstacle).
    torque_guarantee: how the torque was checked, e.g. ``"sampled at 1000 Hz, refined to
        8000 Hz near the limit"`` (``None``: not recorded, e.g. a result saved before).
    self_distance: the robot's distance to itself (:class:`SelfDistance`; ``None``:
        self-collision off), part of the verdict.
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
    guarantee: str | None = None
    distance_bound: float | None = None
    torque_guarantee: str | None = None
    self_distance: SelfDistance | None = None

    def __post_init__(self) -> None:
        if self.self_distance is not None:
            check_type(self.self_distance, SelfDistance, "self_distance")
        x = readonly_copy(as_finite_array(self.x, "x"))
        if x.ndim != 1 or x.size < 1 or not x[0] > 0:
            raise InvalidInputError(f"x must have shape (n_var,) with T = x[0] > 0; got {x!r}")
        object.__setattr__(self, "x", x)
        rate = as_scalar(self.rate_hz, "rate_hz", "[Hz]", minimum=0.0, strict=True)
        object.__setattr__(self, "rate_hz", rate)
        object.__setattr__(self, "margin", as_scalar(self.margin, "margin", "[m]", minimum=0.0))
        for kind in LIMIT_KINDS:
            check = getattr(self, kind)
            if not isinstance(check, LimitCheck) or check.kind != kind:
                raise InvalidInputError(f"{kind} must be a LimitCheck of kind {kind!r}")
            if check.dense.size != self.dense.nq:
                raise InvalidInputError(
                    f"{kind} has {check.dense.size} joints, the dense trajectory {self.dense.nq}"
                )
        normalise_distance_fields(
            self, "min_distance", "t_min_distance", "closest_pair", "distance_bound"
        )
        object.__setattr__(self, "violations", tuple(str(v) for v in self.violations))
        for name in ("guarantee", "torque_guarantee"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, str(getattr(self, name)))

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
        """The smallest distance, and self-distance, is at least the margin."""
        own = self.self_distance
        return self.min_distance >= self.margin and (own is None or own.ok(self.margin))

    @property
    def feasible(self) -> bool:
        """Verified feasible: :attr:`limits_ok` and :attr:`distance_ok`."""
        return self.limits_ok and self.distance_ok

    @property
    def certified(self) -> bool:
        """:attr:`feasible` with the ``"continuous"`` distance (and self-distance) guarantee."""
        own_ok = self.self_distance is None or self.self_distance.guarantee == CONTINUOUS
        return self.feasible and self.guarantee == CONTINUOUS and own_ok

    __hash__ = None  # type: ignore[assignment]


def certificate_bytes(problem: TrajectoryProblem, T: float, rate_hz: float) -> int:
    r"""Estimated peak memory [B] of :func:`certify` over a travel time ``T`` [s] at
    ``rate_hz`` [Hz]: with :math:`n = \lceil T \cdot \text{rate} \rceil + 1` samples,
    :math:`n_q` joints, :math:`n_s` robot solids and :math:`n_o` obstacles,

    .. math::
        M = n \,(700\,n_q + 12\,n_s n_o)\ \text{B} + 1\ \text{MiB}.

    The first term is the states, torques, poses and their temporaries (2 610 B per sample
    measured for the AdeptOne XL, :math:`n_q = 4`, 7 solids), the second the exact
    distance of every pair at every sample (10 B per pair and sample measured); the
    coefficients are :mod:`tracemalloc` peaks at 2–16 kHz with 4 and 24 obstacles, rounded
    up (``benchmarks/bench_memory.py``).
    """
    n = dense_samples(T, rate_hz)
    nq, checker = problem.trajectory.nq, problem.checker
    return n * (700 * nq + 12 * checker.n_solids * checker.n_obstacles) + 2**20


def check_certificate_memory(
    problem: TrajectoryProblem, rate_hz: float, T: float | None = None, *, option: str = "rate_hz"
) -> int:
    """:func:`certificate_bytes` if it fits the memory budget, else
    :class:`~adept_traj.errors.ResourceLimitError` naming ``option`` (e.g. ``"--rate"``),
    the rate, the estimate and the limit. ``T`` [s] defaults to the longest travel time
    the problem allows (its upper bound of ``x[0]``): the check before a run."""
    rate = as_scalar(rate_hz, option, "[Hz]", minimum=0.0, strict=True)
    T = float(problem.xu[0]) if T is None else as_scalar(T, "T", "[s]", minimum=0.0)
    need = certificate_bytes(problem, T, rate)
    check_memory(need, option, f"{rate:g} Hz (T = {T:.4g} s)")
    return need


def certify(
    problem: TrajectoryProblem,
    x: Any,
    rate_hz: float = DEFAULT_RATE_HZ,
    *,
    tolerance: float = DEFAULT_TOLERANCE,
    continuous: bool = True,
    max_depth: int = DEFAULT_MAX_DEPTH,
    exact: bool = True,
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
    continuous:
        Bound the distance between the samples and refine where needed, and refine the
        torque near its limit (module docstring); ``False``: the uniform samples only
        (both guarantees ``"sampled at N Hz"``).
    max_depth:
        Most bisections of a sample interval (integer ≥ 0).
    exact:
        ``True``: every pair's exact distance at every sample. ``False`` (fast, for
        certifying a whole front): a pair whose broad-phase lower bound exceeds the
        checker's ``influence`` [m] (≥ the margin) keeps that bound instead of a coal call.
        The verdict is the same (every distance ≤ ``influence`` is exact) and the
        continuous bound stays sound (it only needs lower bounds at the samples); the
        distances reported above ``influence`` are then lower bounds.

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
        A robot limit that is not > 0 (the velocity, acceleration, jerk and torque limits may
        be infinite; the position limits must be finite with lower < upper).
    ResourceLimitError
        The samples would need more memory than the budget
        (:func:`check_certificate_memory`); checked before anything is allocated.
    """
    xa = as_vector(x, "x", problem.n_var)
    T = float(xa[0])
    if not T > 0.0:
        raise InvalidInputError(f"x[0] (travel time T [s]) must be > 0; got {T!r}")
    rate = as_scalar(rate_hz, "rate_hz", "[Hz]", minimum=0.0, strict=True)
    tol = as_scalar(tolerance, "tolerance", minimum=0.0)
    check_type(continuous, bool, "continuous")
    depth = as_integer(max_depth, "max_depth", minimum=0)
    check_type(exact, bool, "exact")
    position_spans(problem.robot.limits)
    check_certificate_memory(problem, rate, T)
    states = dense_states(problem, xa[None], rate, exact)[0]
    return certify_states(problem, xa, rate, tol, continuous, depth, exact, states)


def certify_states(
    problem: TrajectoryProblem,
    xa: np.ndarray,
    rate: float,
    tol: float,
    continuous: bool,
    depth: int,
    exact: bool,
    states: DenseStates,
) -> Certificate:
    """:func:`certify` of a checked move from its dense states already computed (one
    :func:`~adept_traj.certification.dense_trajectory.dense_states` call for many moves).

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    xa:
        (n_var,) the checked move ``[T [s], control points [rad | m]]``.
    rate, tol, continuous, depth, exact:
        As :func:`certify` (``rate_hz`` [Hz], ``tolerance``, ``continuous``,
        ``max_depth``, ``exact``), checked by the caller.
    states:
        The :data:`~adept_traj.certification.dense_trajectory.DenseStates` of ``xa`` at ``rate``.

    Returns
    -------
    Certificate
        As :func:`certify`.
    """
    smp, tau, pairs = states
    n = len(smp.t)
    t, q, qd, qdd, qddd = smp.t, smp.q, smp.qd, smp.qdd, smp.qddd
    bounds = problem.trajectory.bounds(xa)
    move = SampledMove(xa, t, q, qd, bounds.qdd_abs_max)  # the exact largest |q̈|

    checker = problem.checker
    if pairs is not None:  # (n, ns, no)
        per_sample = pairs.min(axis=(1, 2))
        if continuous:
            found = continuous_distance(problem, move, pairs, depth, exact)
            guarantee, bound = found.guarantee, found.lower_bound
            min_d, t_min_d, (solid, obstacle) = found.min_distance, found.t_min_distance, found.pair
        else:
            guarantee, bound = f"sampled at {move.rate_hz:g} Hz", None
            k, solid, obstacle = np.unravel_index(int(np.argmin(pairs)), pairs.shape)
            min_d, t_min_d = float(pairs[k, solid, obstacle]), float(t[k])
        pair: tuple[str, str] | None = (
            checker.solid_names[solid],
            checker.obstacle_names[obstacle],
        )
    else:
        per_sample = np.full(n, np.inf)
        min_d, t_min_d, pair = math.inf, None, None
        guarantee, bound = CONTINUOUS, math.inf

    checks, torque_guarantee, violations = limit_checks(
        problem, xa, smp, tau, bounds, tol, continuous
    )
    margin = float(problem.settings.margin)
    if min_d < margin and pair is not None:
        violations.append(
            f"distance: {min_d:.4g} m < margin {margin:.4g} m at t = {t_min_d:.3f} s "
            f"({pair[0]} – {pair[1]})"
        )
    own = problem.self_check and self_distance(problem, move, continuous, depth)
    violations.extend(own.violations(margin) if own else ())
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
        guarantee=guarantee,
        distance_bound=bound,
        torque_guarantee=torque_guarantee,
        self_distance=own,
        **checks,
    )
