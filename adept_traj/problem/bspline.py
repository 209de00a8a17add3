r"""Uniform cubic B-spline joint trajectories (batch-first, exact bounds and integrals).

A trajectory of ``nq`` joints over the travel time ``T`` [s] is a uniform cubic B-spline in
the normalised time :math:`s = t/T \in [0, 1]` with ``n_knots`` knots (the paper's
:math:`m = 20`), hence :math:`S = m - 1` uniform segments and :math:`n_c = m + 2` control
points per joint (``n_control = 22``; 4 joints × 22 = 88 coefficients, the paper's 88
variables). On segment :math:`j` with local parameter :math:`u \in [0, 1]`:

.. math::

    q(u) = \begin{bmatrix} u^3 & u^2 & u & 1 \end{bmatrix} M
           \begin{bmatrix} P_j \\ P_{j+1} \\ P_{j+2} \\ P_{j+3} \end{bmatrix},
    \qquad
    M = \frac{1}{6}\begin{bmatrix} -1 & 3 & -3 & 1 \\ 3 & -6 & 3 & 0 \\
                                     -3 & 0 & 3 & 0 \\ 1 & 4 & 1 & 0 \end{bmatrix},

    s = \frac{j + u}{S}, \qquad t = T s, \qquad
    \frac{\mathrm{d}}{\mathrm{d}t} = \frac{S}{T} \frac{\mathrm{d}}{\mathrm{d}u}.

Rest-to-rest conditions. The first three control points of every joint equal ``start`` and
the last three equal ``goal``; this gives exactly :math:`q = q_\text{start}, \dot q = \ddot q
= 0` at :math:`t = 0` and :math:`q = q_\text{goal}, \dot q = \ddot q = 0` at :math:`t = T`
(the jerk is *not* zero there). Of the paper's 88 coefficients, 4 × 6 = 24 are thus fixed and
4 × 16 = 64 are free; the travel time ``T`` is added as a decision variable (the paper's
objective :math:`z_1`), so the decision vector has ``n_var = 1 + nq · n_free`` = 65 entries:

.. math::

    x = [\,T,\; P_{3,0}, \dots, P_{n_c-4,0},\; P_{3,1}, \dots, P_{n_c-4,1},\; \dots\,]

i.e. ``T`` first, then the free control points joint-major (joint 0's ``n_free`` points,
then joint 1's, …). Control points have the units of their joint ([rad] or [m]).

Every method accepts ``x`` of shape ``(n_var,)`` or ``(..., n_var)`` and keeps the leading
(population) axes. Bounds of :math:`q, \dot q, \ddot q, \dddot q` over :math:`[0, T]` and
the integrals :math:`\int \ddot q^2 \mathrm{d}t`, :math:`\int \dddot q^2 \mathrm{d}t` are
computed exactly from the per-segment polynomials, not from samples.

:func:`kinematic_lower_bound` gives the exact minimum rest-to-rest time under velocity,
acceleration and jerk limits (the time-optimal "double S" profile), a bound no trajectory of
this class can beat.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from adept_traj.errors import (
    ConfigurationError,
    InputShapeError,
    InvalidInputError,
    JointLimitError,
)
from adept_traj.validation import (
    as_batch,
    as_finite_array,
    as_vector,
    describe_bad_values,
    readonly_copy,
)

__all__ = [
    "BSplineTrajectory",
    "KinematicBound",
    "TrajectoryBounds",
    "TrajectoryIntegrals",
    "TrajectorySamples",
    "kinematic_lower_bound",
]

#: Uniform cubic B-spline basis matrix (rows: coefficients of u³, u², u, 1).
_M = (
    np.array(
        [
            [-1.0, 3.0, -3.0, 1.0],
            [3.0, -6.0, 3.0, 0.0],
            [-3.0, 0.0, 3.0, 0.0],
            [1.0, 4.0, 1.0, 0.0],
        ]
    )
    / 6.0
)
_M.flags.writeable = False

#: Number of control points fixed at each end of every joint (rest-to-rest conditions).
_N_FIXED_END = 3

_ALL_ORDERS = (0, 1, 2, 3)


# --------------------------------------------------------------------------------------------
# Result containers
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class TrajectorySamples:
    """Joint trajectories sampled at shared normalised times.

    Attributes:
        t: sample times [s], shape ``(..., n_s)`` (``t = T·s``, one row per individual).
        q: positions [rad] or [m], shape ``(..., n_s, nq)``.
        qd: velocities [rad/s] or [m/s], shape ``(..., n_s, nq)``.
        qdd: accelerations [rad/s²] or [m/s²], shape ``(..., n_s, nq)``.
        qddd: jerks [rad/s³] or [m/s³], shape ``(..., n_s, nq)``.

    A derivative that was not requested (``orders`` of :meth:`BSplineTrajectory.sample`) is
    ``None``.
    """

    t: np.ndarray
    q: np.ndarray | None
    qd: np.ndarray | None
    qdd: np.ndarray | None
    qddd: np.ndarray | None


@dataclass(frozen=True, eq=False)
class TrajectoryBounds:
    r"""Exact per-joint extrema over :math:`t \in [0, T]`, each of shape ``(..., nq)``.

    Attributes:
        q_min, q_max: position extrema [rad] or [m].
        qd_min, qd_max: velocity extrema [rad/s] or [m/s].
        qdd_min, qdd_max: acceleration extrema [rad/s²] or [m/s²].
        qddd_min, qddd_max: jerk extrema [rad/s³] or [m/s³] (the jerk is piecewise
            constant; its value on every segment counts, including the first and last).
    """

    q_min: np.ndarray
    q_max: np.ndarray
    qd_min: np.ndarray
    qd_max: np.ndarray
    qdd_min: np.ndarray
    qdd_max: np.ndarray
    qddd_min: np.ndarray
    qddd_max: np.ndarray

    @property
    def q_abs_max(self) -> np.ndarray:
        r""":math:`\max_t |q_i(t)|` [rad] or [m], shape ``(..., nq)``."""
        return np.maximum(np.abs(self.q_min), np.abs(self.q_max))

    @property
    def qd_abs_max(self) -> np.ndarray:
        r""":math:`\max_t |\dot q_i(t)|` [rad/s] or [m/s], shape ``(..., nq)``."""
        return np.maximum(np.abs(self.qd_min), np.abs(self.qd_max))

    @property
    def qdd_abs_max(self) -> np.ndarray:
        r""":math:`\max_t |\ddot q_i(t)|` [rad/s²] or [m/s²], shape ``(..., nq)``."""
        return np.maximum(np.abs(self.qdd_min), np.abs(self.qdd_max))

    @property
    def qddd_abs_max(self) -> np.ndarray:
        r""":math:`\max_t |\dddot q_i(t)|` [rad/s³] or [m/s³], shape ``(..., nq)``."""
        return np.maximum(np.abs(self.qddd_min), np.abs(self.qddd_max))


@dataclass(frozen=True, eq=False)
class TrajectoryIntegrals:
    r"""Exact per-joint integrals of squared acceleration and jerk over :math:`[0, T]`.

    Attributes:
        acc_sq: :math:`\int_0^T \ddot q_i^2 \, \mathrm{d}t` [rad²/s³] or [m²/s³],
            shape ``(..., nq)``.
        jerk_sq: :math:`\int_0^T \dddot q_i^2 \, \mathrm{d}t` [rad²/s⁵] or [m²/s⁵],
            shape ``(..., nq)``.
    """

    acc_sq: np.ndarray
    jerk_sq: np.ndarray

    @property
    def z6(self) -> np.ndarray:
        r"""Paper objective :math:`z_6 = \sum_i \int_0^T \ddot q_i^2 dt`, shape ``(...)``."""
        return self.acc_sq.sum(axis=-1)

    @property
    def z5(self) -> np.ndarray:
        r"""Paper objective :math:`z_5 = \sum_i \int_0^T \dddot q_i^2 dt`, shape ``(...)``."""
        return self.jerk_sq.sum(axis=-1)


@dataclass(frozen=True, eq=False)
class KinematicBound:
    r"""Minimum rest-to-rest travel times under velocity, acceleration and jerk limits.

    Attributes:
        times: per-joint minimum time [s], shape ``(nq,)``.
        delta: per-joint distance :math:`|q_\text{goal} - q_\text{start}|` [rad] or [m],
            shape ``(nq,)``.
        cases: per-joint profile type, one of ``"rest"`` (Δ = 0), ``"instant"`` (all limits
            infinite), ``"jerk"`` (neither a nor v reached), ``"acc"`` (a reached, v not),
            ``"vel"`` (v reached, a not), ``"acc+vel"`` (both reached).
        T_min: :math:`\max_i` ``times[i]`` [s]: no trajectory respecting the limits can be
            faster.
        limiting_joint: index of the joint that attains ``T_min`` (0 if all times are 0).
    """

    times: np.ndarray
    delta: np.ndarray
    cases: tuple[str, ...]
    T_min: float
    limiting_joint: int


# --------------------------------------------------------------------------------------------
# Private helpers
# --------------------------------------------------------------------------------------------


def _monomial_derivative_rows(u: np.ndarray, order: int) -> np.ndarray:
    r"""Rows :math:`\frac{d^r}{du^r}[u^3, u^2, u, 1]`, shape ``(n, 4)``."""
    one = np.ones_like(u)
    zero = np.zeros_like(u)
    if order == 0:
        cols = (u**3, u**2, u, one)
    elif order == 1:
        cols = (3.0 * u**2, 2.0 * u, one, zero)
    elif order == 2:
        cols = (6.0 * u, 2.0 * one, zero, zero)
    else:
        cols = (6.0 * one, zero, zero, zero)
    return np.stack(cols, axis=-1)


def _check_orders(orders: Sequence[int]) -> tuple[int, ...]:
    """Validate derivative orders (subset of 0..3) and return them sorted and unique."""
    try:
        out = tuple(sorted({int(o) for o in orders}))
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"orders must be a sequence of integers in 0..3; got {orders!r}"
        ) from None
    if not out or any(o not in _ALL_ORDERS for o in out):
        raise InvalidInputError(
            f"orders must be a non-empty subset of (0, 1, 2, 3); got {orders!r}"
        )
    return out


def _check_positive_times(T: np.ndarray, name: str) -> None:
    """Raise if any travel time is not strictly positive."""
    bad = ~(T > 0.0)
    if bad.any():
        where = describe_bad_values(T, bad) if T.ndim else repr(float(T))
        raise InvalidInputError(f"{name} (travel time T [s]) must be > 0; bad entries: {where}")


def _clip_candidates(u: np.ndarray) -> np.ndarray:
    """Map candidate parameters to [0, 1]; NaN/inf (no root) become 0 (an endpoint)."""
    u = np.where(np.isfinite(u), u, 0.0)
    return np.clip(u, 0.0, 1.0)


def _quadratic_roots(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Real roots of :math:`a u^2 + b u + c` by the cancellation-free formula.

    Complex pairs, and roots of a degenerate polynomial, come out as NaN or inf (the
    caller replaces them by an endpoint). A linear polynomial (``a = 0``) yields its
    root in the second output.
    """
    with np.errstate(divide="ignore", invalid="ignore"):
        disc = b * b - 4.0 * a * c
        sq = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
        qq = -0.5 * (b + np.where(b >= 0.0, sq, -sq))
        r1 = qq / a
        r2 = c / qq
    return r1, r2


def _double_s_time(h: float, v: float, a: float, j: float) -> tuple[float, str]:
    """Minimum rest-to-rest time [s] for distance ``h`` ≥ 0 under limits v, a, j (> 0, may be inf).

    Biagiotti & Melchiorri, *Trajectory Planning for Automatic Machines and Robots* (2008),
    Sec. 3.4, with zero boundary velocities and accelerations and symmetric limits.
    """
    if h == 0.0:
        return 0.0, "rest"
    if math.isinf(j):
        # Jerk unlimited: trapezoidal (or triangular) velocity profile.
        if math.isinf(a):
            return (0.0, "instant") if math.isinf(v) else (h / v, "vel")
        if math.isinf(v) or v * v / a >= h:
            return 2.0 * math.sqrt(h / a), "acc"
        return h / v + v / a, "acc+vel"
    # Jerk limited. 1) Is v reached? Time Ta to accelerate from 0 to v:
    if not math.isinf(v):
        a_reached = (not math.isinf(a)) and v * j >= a * a
        t_acc = a / j + v / a if a_reached else 2.0 * math.sqrt(v / j)
        if h >= v * t_acc:  # distance covered by accelerating to v and back to 0
            return h / v + t_acc, ("acc+vel" if a_reached else "vel")
    # 2) v not reached: is a reached?
    if not math.isinf(a) and h >= 2.0 * a**3 / j**2:
        return a / j + math.sqrt((a / j) ** 2 + 4.0 * h / a), "acc"
    return 4.0 * (h / (2.0 * j)) ** (1.0 / 3.0), "jerk"


def _as_limit(value: Any, name: str, nq: int) -> np.ndarray:
    """Return a positive limit (inf allowed) broadcast to shape ``(nq,)``."""
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be numeric; got {value!r} ({exc})") from None
    if arr.ndim > 1 or (arr.ndim == 1 and arr.shape[0] != nq):
        raise InputShapeError(f"{name} must be a scalar or have shape ({nq},); got {arr.shape}")
    arr = np.broadcast_to(arr, (nq,)).copy()
    bad = ~(arr > 0.0)  # NaN, zero and negative values
    if bad.any():
        raise InvalidInputError(
            f"{name} must be > 0 (inf allowed); bad entries: {describe_bad_values(arr, bad)}"
        )
    return arr


# --------------------------------------------------------------------------------------------
# The trajectory class
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class BSplineTrajectory:
    r"""Rest-to-rest uniform cubic B-spline trajectories from ``start`` to ``goal``.

    Args:
        start: start configuration [rad] or [m] per joint, shape ``(nq,)``.
        goal: goal configuration [rad] or [m] per joint, shape ``(nq,)``.
        n_knots: number of knots :math:`m \ge 4` (paper: 20); segments ``S = m − 1``,
            control points per joint ``n_control = m + 2``, free per joint
            ``n_free = m − 4``.

    The object is immutable (``start`` and ``goal`` are stored as read-only copies). See the
    module docstring for the decision-vector layout
    ``x = [T, free control points joint-major]``, shape ``(n_var,) = (1 + nq·n_free,)``.

    Raises:
        InvalidInputError: ``start`` or ``goal`` not finite.
        InputShapeError: ``start`` not 1-D and non-empty, or ``goal`` of another shape.
        ConfigurationError: ``n_knots`` not an integer ≥ 4.
    """

    start: np.ndarray
    goal: np.ndarray
    n_knots: int = 20
    _fixed_head: np.ndarray = field(init=False, repr=False)
    _fixed_tail: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        start = as_finite_array(self.start, "start")
        if start.ndim != 1 or start.shape[0] == 0:
            raise InputShapeError(f"start must have shape (nq,) with nq >= 1; got {start.shape}")
        goal = as_vector(self.goal, "goal", start.shape[0])
        n_knots = self.n_knots
        if isinstance(n_knots, bool) or not isinstance(n_knots, (int, np.integer)):
            raise ConfigurationError(f"n_knots must be an integer >= 4; got {n_knots!r}")
        if n_knots < 4:
            raise ConfigurationError(f"n_knots must be >= 4; got {n_knots}")
        object.__setattr__(self, "start", readonly_copy(start))
        object.__setattr__(self, "goal", readonly_copy(goal))
        object.__setattr__(self, "n_knots", int(n_knots))
        object.__setattr__(
            self, "_fixed_head", readonly_copy(np.broadcast_to(start, (_N_FIXED_END, start.size)))
        )
        object.__setattr__(
            self, "_fixed_tail", readonly_copy(np.broadcast_to(goal, (_N_FIXED_END, goal.size)))
        )

    # ---- sizes -------------------------------------------------------------------------

    @property
    def nq(self) -> int:
        """Number of joints."""
        return int(self.start.shape[0])

    @property
    def n_segments(self) -> int:
        """Number of uniform segments ``S = n_knots − 1``."""
        return self.n_knots - 1

    @property
    def n_control(self) -> int:
        """Control points per joint ``n_knots + 2`` (22 for the paper)."""
        return self.n_knots + 2

    @property
    def n_free(self) -> int:
        """Free control points per joint ``n_control − 6`` (16 for the paper)."""
        return self.n_control - 2 * _N_FIXED_END

    @property
    def free_abscissae(self) -> np.ndarray:
        """(n_free,) Greville abscissae in [0, 1] of the free control points (where each
        control point acts along the normalised time; used to shape whole control polygons).

        .. math:: \\xi_c = \\operatorname{clip}\\big((c - 1) / S,\\ 0,\\ 1\\big)
        """
        xi = np.clip((np.arange(self.n_control) - 1.0) / self.n_segments, 0.0, 1.0)
        return xi[_N_FIXED_END:-_N_FIXED_END]

    @property
    def n_var(self) -> int:
        """Length of the decision vector ``1 + nq·n_free`` (65 for the paper)."""
        return 1 + self.nq * self.n_free

    # ---- decision vector <-> control points ----------------------------------------------

    def _check_x(self, x: Any) -> np.ndarray:
        arr = as_batch(x, "x", self.n_var, "(decision vector [T, free control points])")
        _check_positive_times(arr[..., 0], "x[..., 0]")
        return arr

    def _decode_clean(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lead = x.shape[:-1]
        T = x[..., 0].copy()
        free = np.swapaxes(x[..., 1:].reshape(*lead, self.nq, self.n_free), -1, -2)
        P = np.empty((*lead, self.n_control, self.nq))  # C-contiguous: fast matmul
        P[..., :_N_FIXED_END, :] = self._fixed_head
        P[..., _N_FIXED_END : self.n_control - _N_FIXED_END, :] = free
        P[..., self.n_control - _N_FIXED_END :, :] = self._fixed_tail
        return T, P

    def decode(self, x: Any) -> tuple[np.ndarray, np.ndarray]:
        """Split decision vectors into travel times and full control-point arrays.

        Args:
            x: decision vectors, shape ``(..., n_var)``; ``x[..., 0]`` is ``T`` [s] (> 0).

        Returns:
            ``(T, P)``: ``T`` [s] of shape ``(...)`` and control points ``P`` [rad] or [m] of
            shape ``(..., n_control, nq)`` (``P[..., :3, :] = start``,
            ``P[..., -3:, :] = goal``). New arrays; ``x`` is not modified.

        Raises:
            InputShapeError: wrong last axis. InvalidInputError: NaN/inf or ``T ≤ 0``.
        """
        return self._decode_clean(self._check_x(x))

    def encode(self, T: Any, free: Any) -> np.ndarray:
        """Build decision vectors from travel times and free control points (inverse of decode).

        Args:
            T: travel times [s] (> 0), shape ``(...)`` (broadcast against ``free``).
            free: free control points [rad] or [m], shape ``(..., n_free, nq)`` — the same
                layout as ``P[..., 3:-3, :]`` returned by :meth:`decode`: after
                ``T, P = traj.decode(x)``, ``traj.encode(T, P[..., 3:-3, :])`` equals ``x``.

        Returns:
            Decision vectors, shape ``(..., n_var)``.
        """
        T_arr = as_finite_array(T, "T")
        _check_positive_times(T_arr, "T")
        free_arr = as_finite_array(free, "free")
        if free_arr.ndim < 2 or free_arr.shape[-2:] != (self.n_free, self.nq):
            raise InputShapeError(
                f"free must have shape (..., {self.n_free}, {self.nq}) [rad or m]; "
                f"got {free_arr.shape}"
            )
        try:
            lead = np.broadcast_shapes(T_arr.shape, free_arr.shape[:-2])
        except ValueError:
            raise InputShapeError(
                f"T of shape {T_arr.shape} does not broadcast against free of shape "
                f"{free_arr.shape} (leading axes {free_arr.shape[:-2]})"
            ) from None
        free_b = np.broadcast_to(free_arr, (*lead, self.n_free, self.nq))
        flat = np.swapaxes(free_b, -1, -2).reshape(*lead, self.nq * self.n_free)
        return np.concatenate([np.broadcast_to(T_arr, lead)[..., None], flat], axis=-1)

    def straight_line(self, T: Any) -> np.ndarray:
        r"""Decision vectors of the straight joint-space move from ``start`` to ``goal``.

        Every joint uses the same ramp :math:`\lambda_k` of control points,
        :math:`P_k = q_\text{start} + \lambda_k (q_\text{goal} - q_\text{start})` with
        :math:`\lambda_k = 10\xi_k^3 - 15\xi_k^4 + 6\xi_k^5` (the minimum-jerk "smoothstep"),
        :math:`\xi_k = \operatorname{clip}((k - 2)/(n_c - 5), 0, 1)`, so

        .. math::

            q(t) = q_\text{start} + (q_\text{goal} - q_\text{start})\,\sigma(t/T),

        with one scalar, monotone (the ramp is monotone and B-splines diminish variation),
        rest-to-rest :math:`\sigma` close to the minimum-jerk profile, so that peak
        accelerations are moderate (a good seed for an optimiser).

        Args:
            T: travel time(s) [s] (> 0), scalar or shape ``(...)``.

        Returns:
            Decision vectors, shape ``(..., n_var)``.
        """
        lam = self._straight_ramp()[_N_FIXED_END:-_N_FIXED_END]
        free = self.start + lam[:, None] * (self.goal - self.start)
        T_arr = as_finite_array(T, "T")
        return self.encode(T_arr, np.broadcast_to(free, (*T_arr.shape, *free.shape)))

    def _straight_ramp(self) -> np.ndarray:
        k = np.arange(self.n_control, dtype=np.float64)
        xi = np.clip((k - 2.0) / (self.n_control - 5.0), 0.0, 1.0)
        return xi**3 * (10.0 + xi * (-15.0 + 6.0 * xi))

    # ---- sampling --------------------------------------------------------------------------

    def _check_s(self, s: Any) -> np.ndarray:
        s_arr = as_finite_array(s, "s")
        if s_arr.ndim != 1:
            raise InputShapeError(f"s (normalised times) must have shape (n_s,); got {s_arr.shape}")
        bad = (s_arr < 0.0) | (s_arr > 1.0)
        if bad.any():
            raise InvalidInputError(
                f"s (normalised times) must lie in [0, 1]; bad entries: "
                f"{describe_bad_values(s_arr, bad)}"
            )
        return s_arr

    def basis_matrix(self, s: Any, order: int = 0) -> np.ndarray:
        r"""B-spline basis (or its derivative in normalised time) at normalised times ``s``.

        .. math::

            \frac{d^r q}{ds^r}(s_k) = \sum_c B^{(r)}_{kc} P_c, \qquad
            \frac{d^r q}{dt^r} = T^{-r}\,\frac{d^r q}{ds^r}.

        Args:
            s: normalised times in [0, 1], shape ``(n_s,)`` (``s = 1`` uses the last segment).
            order: derivative order ``r`` in 0..3.

        Returns:
            ``B`` of shape ``(n_s, n_control)`` (dimensionless, scaled by :math:`S^r`).
        """
        (order,) = _check_orders([order])
        return self._basis(self._check_s(s), order)

    def _basis(self, s: np.ndarray, order: int) -> np.ndarray:
        S = self.n_segments
        seg = np.minimum(np.floor(s * S).astype(np.intp), S - 1)
        u = s * S - seg
        rows = _monomial_derivative_rows(u, order) @ _M * float(S) ** order  # (n_s, 4)
        B = np.zeros((s.shape[0], self.n_control))
        cols = seg[:, None] + np.arange(4)
        np.put_along_axis(B, cols, rows, axis=1)
        return B

    def sample(self, x: Any, s: Any, orders: Sequence[int] = _ALL_ORDERS) -> TrajectorySamples:
        r"""Evaluate positions and derivatives at normalised times shared by the population.

        One matrix product per derivative order:

        .. math::

            q^{(r)}(T s_k) = T^{-r} \sum_c B^{(r)}_{kc} P_c .

        Args:
            x: decision vectors, shape ``(..., n_var)``.
            s: normalised times in [0, 1], shape ``(n_s,)``.
            orders: derivative orders to compute (subset of ``(0, 1, 2, 3)``); the others
                are ``None`` in the result.

        Returns:
            :class:`TrajectorySamples` with ``t`` [s] ``(..., n_s)`` and
            ``q, qd, qdd, qddd`` [rad, rad/s, rad/s², rad/s³ or m…] ``(..., n_s, nq)``.
        """
        wanted = _check_orders(orders)
        T, P = self._decode_clean(self._check_x(x))
        s_arr = self._check_s(s)
        out: list[np.ndarray | None] = [None, None, None, None]
        for r in wanted:
            P_r = P if r == 0 else P * (T[..., None, None] ** (-r))  # small: scale before
            out[r] = self._basis(s_arr, r) @ P_r
        t = T[..., None] * s_arr
        return TrajectorySamples(t=t, q=out[0], qd=out[1], qdd=out[2], qddd=out[3])

    # ---- exact per-segment analysis ----------------------------------------------------

    def _segment_coefficients(self, P: np.ndarray) -> np.ndarray:
        """Monomial coefficients in ``u`` per segment, shape ``(..., S, 4, nq)`` (u³, u², u, 1)."""
        idx = np.arange(self.n_segments)[:, None] + np.arange(4)
        windows = P[..., idx, :]  # (..., S, 4, nq)
        return np.einsum("ab,...sbj->...saj", _M, windows)

    def bounds(self, x: Any) -> TrajectoryBounds:
        r"""Exact per-joint minima and maxima of :math:`q, \dot q, \ddot q, \dddot q` over [0, T].

        On each segment, with :math:`q(u) = c_3 u^3 + c_2 u^2 + c_1 u + c_0`:

        .. math::

            q:&\ u \in \{0, 1\} \cup \{u \in (0,1): 3c_3u^2 + 2c_2u + c_1 = 0\} \\
            \dot q:&\ u \in \{0, 1, -c_2/(3c_3)\} \cap [0,1] \\
            \ddot q:&\ u \in \{0, 1\}, \qquad \dddot q = 6 c_3 (S/T)^3 .

        Args:
            x: decision vectors, shape ``(..., n_var)``.

        Returns:
            :class:`TrajectoryBounds`, every field of shape ``(..., nq)`` in SI units.
        """
        T, P = self._decode_clean(self._check_x(x))
        c = self._segment_coefficients(P)
        c3, c2, c1, c0 = c[..., 0, :], c[..., 1, :], c[..., 2, :], c[..., 3, :]  # (..., S, nq)
        rate = self.n_segments / T[..., None, None]  # (..., 1, 1) d/dt = rate·d/du

        r1, r2 = _quadratic_roots(3.0 * c3, 2.0 * c2, c1)
        with np.errstate(divide="ignore", invalid="ignore"):
            vertex = -c2 / (3.0 * c3)
        zeros = np.zeros_like(c3)
        ones = np.ones_like(c3)
        u_q = np.stack([zeros, ones, _clip_candidates(r1), _clip_candidates(r2)], axis=-3)
        u_qd = np.stack([zeros, ones, _clip_candidates(vertex)], axis=-3)
        u_qdd = np.stack([zeros, ones], axis=-3)
        cc3, cc2, cc1, cc0 = (ci[..., None, :, :] for ci in (c3, c2, c1, c0))

        q_val = ((cc3 * u_q + cc2) * u_q + cc1) * u_q + cc0  # (..., k, S, nq)
        qd_val = ((3.0 * cc3 * u_qd + 2.0 * cc2) * u_qd + cc1) * rate[..., None, :, :]
        qdd_val = (6.0 * cc3 * u_qdd + 2.0 * cc2) * rate[..., None, :, :] ** 2
        qddd_val = 6.0 * c3 * rate**3  # (..., S, nq)

        def ext(v: np.ndarray, axes: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
            return v.min(axis=axes), v.max(axis=axes)

        q_min, q_max = ext(q_val, (-3, -2))
        qd_min, qd_max = ext(qd_val, (-3, -2))
        qdd_min, qdd_max = ext(qdd_val, (-3, -2))
        qddd_min, qddd_max = ext(qddd_val, (-2,))
        return TrajectoryBounds(
            q_min=q_min,
            q_max=q_max,
            qd_min=qd_min,
            qd_max=qd_max,
            qdd_min=qdd_min,
            qdd_max=qdd_max,
            qddd_min=qddd_min,
            qddd_max=qddd_max,
        )

    def integrals(self, x: Any) -> TrajectoryIntegrals:
        r"""Exact per-joint integrals of squared acceleration and squared jerk over [0, T].

        With :math:`q''(u) = A u + B` on a segment (:math:`A = 6c_3`, :math:`B = 2c_2`) and
        :math:`\mathrm{d}t = (T/S)\,\mathrm{d}u`:

        .. math::

            \int_0^T \ddot q^2 \mathrm{d}t = \Bigl(\frac{S}{T}\Bigr)^3
                \sum_{\text{seg}} \Bigl(\frac{A^2}{3} + AB + B^2\Bigr), \qquad
            \int_0^T \dddot q^2 \mathrm{d}t = \Bigl(\frac{S}{T}\Bigr)^5
                \sum_{\text{seg}} A^2 .

        Args:
            x: decision vectors, shape ``(..., n_var)``.

        Returns:
            :class:`TrajectoryIntegrals` with ``acc_sq`` and ``jerk_sq`` of shape ``(..., nq)``;
            ``.z6`` and ``.z5`` give the paper's sums over joints, shape ``(...)``.
        """
        T, P = self._decode_clean(self._check_x(x))
        c = self._segment_coefficients(P)
        A = 6.0 * c[..., 0, :]
        B = 2.0 * c[..., 1, :]
        rate = self.n_segments / T[..., None]
        acc = (A * A / 3.0 + A * B + B * B).sum(axis=-2) * rate**3
        jerk = (A * A).sum(axis=-2) * rate**5
        return TrajectoryIntegrals(acc_sq=acc, jerk_sq=jerk)

    def quadrature(self, n_per_segment: int) -> tuple[np.ndarray, np.ndarray]:
        r"""Composite Gauss–Legendre rule on the spline segments, in normalised time.

        .. math::

            \int_0^T f(t)\,\mathrm{d}t \approx T \sum_k w_k\, f(T s_k),

        exact when ``f`` is a polynomial of degree ≤ ``2·n_per_segment − 1`` on every segment.

        Args:
            n_per_segment: Gauss–Legendre nodes per segment (≥ 1).

        Returns:
            ``(s, w)``: increasing normalised nodes in (0, 1) and weights (sum 1), both of shape
            ``(n_segments·n_per_segment,)``.
        """
        if (
            isinstance(n_per_segment, bool)
            or not isinstance(n_per_segment, (int, np.integer))
            or n_per_segment < 1
        ):
            raise InvalidInputError(f"n_per_segment must be an integer >= 1; got {n_per_segment!r}")
        S = self.n_segments
        xg, wg = np.polynomial.legendre.leggauss(int(n_per_segment))
        s = (np.arange(S)[:, None] + 0.5 * (xg + 1.0)) / S
        w = np.broadcast_to(wg / (2.0 * S), s.shape)
        return s.ravel(), w.ravel().copy()

    # ---- box bounds for optimisers -----------------------------------------------------

    def decision_bounds(
        self, q_lower: Any, q_upper: Any, T_min: float, T_max: float
    ) -> tuple[np.ndarray, np.ndarray]:
        r"""Box bounds of the decision vector for a population-based optimiser.

        Free control points are confined to the joint limits; by the convex-hull property
        of B-splines (and because the fixed points ``start``/``goal`` are inside the limits)
        every trajectory in the box then satisfies
        :math:`q_\text{lower} \le q(t) \le q_\text{upper}` for all t.

        Args:
            q_lower: lower joint limits [rad] or [m], shape ``(nq,)``.
            q_upper: upper joint limits [rad] or [m], shape ``(nq,)``, ``> q_lower``.
            T_min: smallest travel time [s], ``> 0`` (e.g. :func:`kinematic_lower_bound`).
            T_max: largest travel time [s], ``> T_min``.

        Returns:
            ``(xl, xu)``, each of shape ``(n_var,)``.

        Raises:
            InvalidInputError: bad times or limits. JointLimitError (an InvalidInputError):
            ``start`` or ``goal`` outside the limits (the message names joint, value, range).
        """
        lo = as_vector(q_lower, "q_lower", self.nq, "[rad or m]")
        hi = as_vector(q_upper, "q_upper", self.nq, "[rad or m]")
        t_lo = float(as_finite_array(T_min, "T_min"))
        t_hi = float(as_finite_array(T_max, "T_max"))
        if not t_lo > 0.0:
            raise InvalidInputError(f"T_min must be > 0 s; got {t_lo!r}")
        if not t_lo < t_hi:
            raise InvalidInputError(f"T_min must be < T_max; got T_min={t_lo!r}, T_max={t_hi!r}")
        for i in range(self.nq):
            if not lo[i] < hi[i]:
                raise InvalidInputError(
                    f"joint {i}: q_lower must be < q_upper; "
                    f"got {float(lo[i])!r} >= {float(hi[i])!r}"
                )
        for name, q in (("start", self.start), ("goal", self.goal)):
            for i in range(self.nq):
                if not lo[i] <= q[i] <= hi[i]:
                    raise JointLimitError(
                        f"{name}[{i}] = {float(q[i])!r} (joint {i}) lies outside the joint range "
                        f"[{float(lo[i])!r}, {float(hi[i])!r}]"
                    )
        xl = np.concatenate([[t_lo], np.repeat(lo, self.n_free)])
        xu = np.concatenate([[t_hi], np.repeat(hi, self.n_free)])
        return xl, xu


# --------------------------------------------------------------------------------------------
# Kinematic lower bound
# --------------------------------------------------------------------------------------------


def kinematic_lower_bound(
    start: Any, goal: Any, v_max: Any, a_max: Any, j_max: Any
) -> KinematicBound:
    r"""Exact minimum time of a rest-to-rest move under per-joint v, a, j limits.

    For each joint, :math:`h = |q_\text{goal} - q_\text{start}|` and limits
    :math:`|\dot q| \le v`, :math:`|\ddot q| \le a`, :math:`|\dddot q| \le j`, the
    time-optimal profile is the jerk-limited "double S" (bang-bang jerk; Biagiotti &
    Melchiorri 2008, Sec. 3.4). With :math:`T_a` the time to accelerate from 0 to v,

    .. math::

        T_a = \begin{cases} a/j + v/a & v j \ge a^2 \\ 2\sqrt{v/j} & v j < a^2
              \end{cases}, \qquad
        T = \begin{cases}
            h/v + T_a & h \ge v T_a \quad\text{(v reached)} \\
            a/j + \sqrt{(a/j)^2 + 4h/a} & h < v T_a,\ h \ge 2a^3/j^2
                \quad\text{(a reached)} \\
            4\,(h/(2j))^{1/3} & \text{otherwise.}
        \end{cases}

    Infinite limits are allowed (``j = inf`` gives the trapezoidal-velocity times;
    all three infinite give 0). ``h = 0`` gives 0.

    Args:
        start: start configuration [rad] or [m], shape ``(nq,)``.
        goal: goal configuration [rad] or [m], shape ``(nq,)``.
        v_max: velocity limits [rad/s] or [m/s], scalar or ``(nq,)``, > 0 (inf allowed).
        a_max: acceleration limits [rad/s²] or [m/s²], scalar or ``(nq,)``, > 0.
        j_max: jerk limits [rad/s³] or [m/s³], scalar or ``(nq,)``, > 0.

    Returns:
        :class:`KinematicBound` (per-joint times [s], ``T_min`` [s], ``limiting_joint``).

    Example:
        >>> kinematic_lower_bound([0.0], [0.929], np.inf, 9.5, 50.0).T_min  # doctest: +ELLIPSIS
        0.843...
    """
    q0 = as_finite_array(start, "start")
    if q0.ndim != 1 or q0.shape[0] == 0:
        raise InputShapeError(f"start must have shape (nq,) with nq >= 1; got {q0.shape}")
    nq = q0.shape[0]
    q1 = as_vector(goal, "goal", nq)
    v = _as_limit(v_max, "v_max", nq)
    a = _as_limit(a_max, "a_max", nq)
    j = _as_limit(j_max, "j_max", nq)
    delta = np.abs(q1 - q0)
    results = [
        _double_s_time(float(delta[i]), float(v[i]), float(a[i]), float(j[i])) for i in range(nq)
    ]
    times = np.array([r[0] for r in results])
    limiting = int(np.argmax(times))
    return KinematicBound(
        times=times,
        delta=delta,
        cases=tuple(r[1] for r in results),
        T_min=float(times[limiting]),
        limiting_joint=limiting,
    )
