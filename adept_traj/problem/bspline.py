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
(population) axes. The methods check and normalise their input; the arithmetic on the
per-segment polynomials (samples, exact bounds of :math:`q, \dot q, \ddot q, \dddot q` and
exact integrals of :math:`\ddot q^2, \dddot q^2`) is in
:mod:`adept_traj.problem.spline_segments`. The kinematic lower bound of ``T``:
:mod:`adept_traj.problem.time_bound`.
"""

from __future__ import annotations

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
from adept_traj.problem.spline_segments import (
    TrajectoryBounds,
    TrajectoryIntegrals,
    TrajectorySamples,
    exact_bounds,
    exact_integrals,
    gauss_legendre,
    segment_basis,
    segment_samples,
)
from adept_traj.validation import (
    as_batch,
    as_finite_array,
    as_integer,
    as_vector,
    describe_bad_values,
    readonly_copy,
)

__all__ = ["BSplineTrajectory"]

#: Number of control points fixed at each end of every joint (rest-to-rest conditions).
_N_FIXED_END = 3

_ALL_ORDERS = (0, 1, 2, 3)


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


@dataclass(frozen=True, eq=False)
class BSplineTrajectory:
    r"""Rest-to-rest uniform cubic B-spline trajectories from ``start`` to ``goal``.

    Parameters
    ----------
    start: start configuration [rad] or [m] per joint, shape ``(nq,)``.
    goal: goal configuration [rad] or [m] per joint, shape ``(nq,)``.
    n_knots: number of knots :math:`m \ge 4` (paper: 20); segments ``S = m − 1``, control points
        per joint ``n_control = m + 2``, free per joint ``n_free = m − 4``.

    The object is immutable (``start`` and ``goal`` are stored as read-only copies). See the
    module docstring for the decision-vector layout
    ``x = [T, free control points joint-major]``, shape ``(n_var,) = (1 + nq·n_free,)``.

    Raises
    ------
    InvalidInputError
        ``start`` or ``goal`` not finite.
    InputShapeError
        ``start`` not 1-D and non-empty, or ``goal`` of another shape.
    ConfigurationError
        ``n_knots`` not an integer ≥ 4.
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
        n_knots = as_integer(self.n_knots, "n_knots", minimum=4, error=ConfigurationError)
        object.__setattr__(self, "start", readonly_copy(start))
        object.__setattr__(self, "goal", readonly_copy(goal))
        object.__setattr__(self, "n_knots", n_knots)
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

        Parameters
        ----------
        x: decision vectors, shape ``(..., n_var)``; ``x[..., 0]`` is ``T`` [s] (> 0).

        Returns
        -------
        ``(T, P)``: ``T`` [s] of shape ``(...)`` and control points ``P`` [rad] or [m] of
        shape ``(..., n_control, nq)`` (``P[..., :3, :] = start``,
        ``P[..., -3:, :] = goal``). New arrays; ``x`` is not modified.

        Raises
        ------
        InputShapeError
            wrong last axis.
        InvalidInputError
            NaN/inf or ``T ≤ 0``.
        """
        return self._decode_clean(self._check_x(x))

    def encode(self, T: Any, free: Any) -> np.ndarray:
        """Build decision vectors from travel times and free control points (inverse of decode).

        Parameters
        ----------
        T: travel times [s] (> 0), shape ``(...)`` (broadcast against ``free``).
        free: free control points [rad] or [m], shape ``(..., n_free, nq)`` — the same
            layout as ``P[..., 3:-3, :]`` returned by :meth:`decode`: after
            ``T, P = traj.decode(x)``, ``traj.encode(T, P[..., 3:-3, :])`` equals ``x``.

        Returns
        -------
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

        Parameters
        ----------
        T: travel time(s) [s] (> 0), scalar or shape ``(...)``.

        Returns
        -------
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

        Parameters
        ----------
        s: normalised times in [0, 1], shape ``(n_s,)`` (``s = 1`` uses the last segment).
        order: derivative order ``r`` in 0..3.

        Returns
        -------
        ``B`` of shape ``(n_s, n_control)`` (dimensionless, scaled by :math:`S^r`).
        """
        (order,) = _check_orders([order])
        return segment_basis(self._check_s(s), order, self.n_segments)

    def sample(self, x: Any, s: Any, orders: Sequence[int] = _ALL_ORDERS) -> TrajectorySamples:
        r"""Evaluate positions and derivatives at normalised times shared by the population.

        One matrix product per derivative order:

        .. math::

            q^{(r)}(T s_k) = T^{-r} \sum_c B^{(r)}_{kc} P_c .

        Parameters
        ----------
        x: decision vectors, shape ``(..., n_var)``.
        s: normalised times in [0, 1], shape ``(n_s,)``.
        orders: derivative orders to compute (subset of ``(0, 1, 2, 3)``); the others
            are ``None`` in the result.

        Returns
        -------
        :class:`TrajectorySamples` with ``t`` [s] ``(..., n_s)`` and
        ``q, qd, qdd, qddd`` [rad, rad/s, rad/s², rad/s³ or m…] ``(..., n_s, nq)``.
        """
        wanted = _check_orders(orders)
        T, P = self._decode_clean(self._check_x(x))
        return segment_samples(T, P, self._check_s(s), wanted)

    # ---- exact per-segment analysis ----------------------------------------------------

    def bounds(self, x: Any) -> TrajectoryBounds:
        r"""Exact per-joint minima and maxima of :math:`q, \dot q, \ddot q, \dddot q` over [0, T].

        On each segment, with :math:`q(u) = c_3 u^3 + c_2 u^2 + c_1 u + c_0`:

        .. math::

            q:&\ u \in \{0, 1\} \cup \{u \in (0,1): 3c_3u^2 + 2c_2u + c_1 = 0\} \\
            \dot q:&\ u \in \{0, 1, -c_2/(3c_3)\} \cap [0,1] \\
            \ddot q:&\ u \in \{0, 1\}, \qquad \dddot q = 6 c_3 (S/T)^3 .

        Parameters
        ----------
        x: decision vectors, shape ``(..., n_var)``.

        Returns
        -------
        :class:`TrajectoryBounds`, every field of shape ``(..., nq)`` in SI units.
        """
        return exact_bounds(*self._decode_clean(self._check_x(x)))

    def integrals(self, x: Any) -> TrajectoryIntegrals:
        r"""Exact per-joint integrals of squared acceleration and squared jerk over [0, T].

        With :math:`q''(u) = A u + B` on a segment (:math:`A = 6c_3`, :math:`B = 2c_2`) and
        :math:`\mathrm{d}t = (T/S)\,\mathrm{d}u`:

        .. math::

            \int_0^T \ddot q^2 \mathrm{d}t = \Bigl(\frac{S}{T}\Bigr)^3
                \sum_{\text{seg}} \Bigl(\frac{A^2}{3} + AB + B^2\Bigr), \qquad
            \int_0^T \dddot q^2 \mathrm{d}t = \Bigl(\frac{S}{T}\Bigr)^5
                \sum_{\text{seg}} A^2 .

        Parameters
        ----------
        x: decision vectors, shape ``(..., n_var)``.

        Returns
        -------
        :class:`TrajectoryIntegrals` with ``acc_sq`` and ``jerk_sq`` of shape ``(..., nq)``;
        ``.z6`` and ``.z5`` give the paper's sums over joints, shape ``(...)``.
        """
        return exact_integrals(*self._decode_clean(self._check_x(x)))

    def quadrature(self, n_per_segment: int) -> tuple[np.ndarray, np.ndarray]:
        r"""Composite Gauss–Legendre rule on the spline segments, in normalised time.

        .. math::

            \int_0^T f(t)\,\mathrm{d}t \approx T \sum_k w_k\, f(T s_k),

        exact when ``f`` is a polynomial of degree ≤ ``2·n_per_segment − 1`` on every segment.

        Parameters
        ----------
        n_per_segment: Gauss–Legendre nodes per segment (≥ 1).

        Returns
        -------
        ``(s, w)``: increasing normalised nodes in (0, 1) and weights (sum 1), both of shape
        ``(n_segments·n_per_segment,)``.
        """
        n = as_integer(n_per_segment, "n_per_segment", minimum=1)
        return gauss_legendre(self.n_segments, n)

    # ---- box bounds for optimisers -----------------------------------------------------

    def decision_bounds(
        self, q_lower: Any, q_upper: Any, T_min: float, T_max: float
    ) -> tuple[np.ndarray, np.ndarray]:
        r"""Box bounds of the decision vector for a population-based optimiser.

        Free control points are confined to the joint limits; by the convex-hull property
        of B-splines (and because the fixed points ``start``/``goal`` are inside the limits)
        every trajectory in the box then satisfies
        :math:`q_\text{lower} \le q(t) \le q_\text{upper}` for all t.

        Parameters
        ----------
        q_lower: lower joint limits [rad] or [m], shape ``(nq,)``.
        q_upper: upper joint limits [rad] or [m], shape ``(nq,)``, ``> q_lower``.
        T_min: smallest travel time [s], ``> 0`` (e.g. from
            :func:`~adept_traj.problem.time_bound.kinematic_lower_bound`).
        T_max: largest travel time [s], ``> T_min``.

        Returns
        -------
        ``(xl, xu)``, each of shape ``(n_var,)``.

        Raises
        ------
        InvalidInputError
            bad times or limits.
        JointLimitError
            (an InvalidInputError) ``start`` or ``goal`` outside the limits (the message
            names joint, value, range).
        """
        lo = as_vector(q_lower, "q_lower", self.nq, "[rad or m]")
        hi = as_vector(q_upper, "q_upper", self.nq, "[rad or m]")
        t_lo = float(as_finite_array(T_min, "T_min"))
        t_hi = float(as_finite_array(T_max, "T_max"))
        if not t_lo > 0.0:
            raise InvalidInputError(f"T_min must be > 0 s; got {t_lo!r}")
        if not t_lo < t_hi:
            raise InvalidInputError(f"T_min must be < T_max; got T_min={t_lo!r}, T_max={t_hi!r}")
        if not (lo < hi).all():
            i = int(np.argmin(lo < hi))
            raise InvalidInputError(
                f"joint {i}: q_lower must be < q_upper; got {float(lo[i])!r} >= {float(hi[i])!r}"
            )
        for name, q in (("start", self.start), ("goal", self.goal)):
            inside = (lo <= q) & (q <= hi)
            if not inside.all():
                i = int(np.argmin(inside))
                raise JointLimitError(
                    f"{name}[{i}] = {float(q[i])!r} (joint {i}) lies outside the joint range "
                    f"[{float(lo[i])!r}, {float(hi[i])!r}]"
                )
        xl = np.concatenate([[t_lo], np.repeat(lo, self.n_free)])
        xu = np.concatenate([[t_hi], np.repeat(hi, self.n_free)])
        return xl, xu
