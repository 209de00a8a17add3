r"""Exact analysis of the spline's per-segment cubic polynomials: bounds and integrals.

On segment :math:`j` of a uniform cubic B-spline (:class:`~adept_traj.problem.BSplineTrajectory`)
each joint is the cubic :math:`q(u) = c_3 u^3 + c_2 u^2 + c_1 u + c_0` of the local parameter
:math:`u \in [0, 1]`, with :math:`(c_3, c_2, c_1, c_0)^\top = M\,[P_j, P_{j+1}, P_{j+2},
P_{j+3}]^\top` and :math:`\mathrm{d}/\mathrm{d}t = (S/T)\,\mathrm{d}/\mathrm{d}u`. The extrema
of :math:`q, \dot q, \ddot q, \dddot q` (constraints 7–10 of the paper) and the integrals of
:math:`\ddot q^2, \dddot q^2` (objectives z6, z5) follow exactly from these coefficients,
batched over the population, the segments and the joints.

:meth:`BSplineTrajectory.bounds <adept_traj.problem.BSplineTrajectory.bounds>` and
:meth:`~adept_traj.problem.BSplineTrajectory.integrals` check their input and call the
hooks here; the results are :class:`TrajectoryBounds` and :class:`TrajectoryIntegrals`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = [
    "TrajectoryBounds",
    "TrajectoryIntegrals",
    "TrajectorySamples",
    "derivative_abs_max",
    "exact_bounds",
    "exact_integrals",
    "gauss_legendre",
    "segment_basis",
    "segment_samples",
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


@dataclass(frozen=True, eq=False)
class TrajectorySamples:
    """Joint trajectories sampled at shared normalised times.

    Attributes
    ----------
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


def _abs_max(order: str, doc: str) -> property:
    """A read-only property of :class:`TrajectoryBounds`: the largest absolute value of
    derivative ``order`` (``"q"``, ``"qd"``, …) from its ``<order>_min`` and
    ``<order>_max`` fields, documented by ``doc``."""
    low, high = f"{order}_min", f"{order}_max"

    def largest(self: TrajectoryBounds) -> np.ndarray:
        return np.maximum(np.abs(getattr(self, low)), np.abs(getattr(self, high)))

    return property(largest, doc=doc)


@dataclass(frozen=True, eq=False)
class TrajectoryBounds:
    r"""Exact per-joint extrema over :math:`t \in [0, T]`, each of shape ``(..., nq)``.

    Attributes
    ----------
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

    q_abs_max = _abs_max("q", r":math:`\max_t |q_i(t)|` [rad] or [m], shape ``(..., nq)``.")
    qd_abs_max = _abs_max(
        "qd", r":math:`\max_t |\dot q_i(t)|` [rad/s] or [m/s], shape ``(..., nq)``."
    )
    qdd_abs_max = _abs_max(
        "qdd", r":math:`\max_t |\ddot q_i(t)|` [rad/s²] or [m/s²], shape ``(..., nq)``."
    )
    qddd_abs_max = _abs_max(
        "qddd", r":math:`\max_t |\dddot q_i(t)|` [rad/s³] or [m/s³], shape ``(..., nq)``."
    )


@dataclass(frozen=True, eq=False)
class TrajectoryIntegrals:
    r"""Exact per-joint integrals of squared acceleration and jerk over :math:`[0, T]`.

    Attributes
    ----------
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


def segment_basis(s: np.ndarray, order: int, n_segments: int) -> np.ndarray:
    """The B-spline basis (the math: :meth:`BSplineTrajectory.basis_matrix`).

    Parameters
    ----------
    s:
        (n_s,) normalised times in [0, 1].
    order:
        Derivative order (0…3) in normalised time.
    n_segments:
        Spline segments S.

    Returns
    -------
    numpy.ndarray
        (n_s, S + 3).
    """
    S = n_segments
    seg = np.minimum(np.floor(s * S).astype(np.intp), S - 1)
    u = s * S - seg
    rows = _monomial_derivative_rows(u, order) @ _M * float(S) ** order  # (n_s, 4)
    B = np.zeros((s.shape[0], S + 3))
    cols = seg[:, None] + np.arange(4)
    np.put_along_axis(B, cols, rows, axis=1)
    return B


#: Grids of at most this many times keep their basis (:func:`_shared_basis`; 0.7 MB at 19 segments).
_SHARED_GRID = 4096


@functools.lru_cache(maxsize=16)
def _shared_basis(s_bytes: bytes, order: int, n_segments: int) -> np.ndarray:
    """:func:`segment_basis` at the times ``np.frombuffer(s_bytes)``, made once per grid (a
    problem samples every population at the same times) and read-only."""
    basis = segment_basis(np.frombuffer(s_bytes), order, n_segments)
    basis.flags.writeable = False
    return basis


def segment_samples(
    T: np.ndarray, P: np.ndarray, s: np.ndarray, orders: tuple[int, ...]
) -> TrajectorySamples:
    """Samples of splines (the math: :meth:`BSplineTrajectory.sample`).

    Parameters
    ----------
    T:
        (...) travel times [s].
    P:
        (..., S + 3, nq) control points [rad | m].
    s:
        (n_s,) normalised times in [0, 1].
    orders:
        Derivative orders (0…3) wanted.

    Returns
    -------
    TrajectorySamples
        ``t`` (..., n_s) [s] and the wanted derivatives (..., n_s, nq).
    """
    out: list[np.ndarray | None] = [None, None, None, None]
    for r in orders:
        P_r = P if r == 0 else P * (T[..., None, None] ** (-r))  # small: scale before
        S = P.shape[-2] - 3
        basis = (
            _shared_basis(s.tobytes(), r, S) if len(s) <= _SHARED_GRID else segment_basis(s, r, S)
        )
        out[r] = basis @ P_r
    t = T[..., None] * s
    return TrajectorySamples(t=t, q=out[0], qd=out[1], qdd=out[2], qddd=out[3])


def gauss_legendre(n_segments: int, n_per_segment: int) -> tuple[np.ndarray, np.ndarray]:
    """Composite Gauss–Legendre nodes and weights in normalised time (the math:
    :meth:`BSplineTrajectory.quadrature`).

    Parameters
    ----------
    n_segments:
        Spline segments S.
    n_per_segment:
        Nodes per segment.

    Returns
    -------
    tuple of numpy.ndarray
        Nodes and weights, each (S·n_per_segment,).
    """
    S = n_segments
    xg, wg = np.polynomial.legendre.leggauss(n_per_segment)
    s = (np.arange(S)[:, None] + 0.5 * (xg + 1.0)) / S
    w = np.broadcast_to(wg / (2.0 * S), s.shape)
    return s.ravel(), w.ravel().copy()


def _clip_candidates(u: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """Map candidate parameters to [0, 1]; NaN/inf (no root) become 0 (an endpoint)
    (into ``out`` if given)."""
    u = np.where(np.isfinite(u), u, 0.0)
    return np.clip(u, 0.0, 1.0, out=out)


def _candidates(*roots: np.ndarray) -> np.ndarray:
    """Parameters (..., 2 + len(roots), S, nq): u = 0, u = 1, then each of ``roots``
    (..., S, nq) clipped (:func:`_clip_candidates`), written in place (no stack)."""
    u = np.empty((*roots[0].shape[:-2], 2 + len(roots), *roots[0].shape[-2:]))
    u[..., 0, :, :] = 0.0
    u[..., 1, :, :] = 1.0
    for i, r in enumerate(roots, start=2):
        _clip_candidates(r, out=u[..., i, :, :])
    return u


def _cubic_at(
    c3: np.ndarray, c2: np.ndarray, c1: np.ndarray, c0: np.ndarray, u: np.ndarray
) -> np.ndarray:
    """:math:`((c_3 u + c_2) u + c_1) u + c_0` (in that order) of coefficients (..., 1, S,
    nq) at parameters ``u`` (..., k, S, nq), in place on one new array."""
    out = c3 * u
    out += c2
    out *= u
    out += c1
    out *= u
    out += c0
    return out


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


def _segment_coefficients(P: np.ndarray) -> np.ndarray:
    """Monomial coefficients in ``u`` per segment, shape ``(..., S, 4, nq)`` (u³, u², u, 1),
    of control points ``P`` of shape ``(..., S + 3, nq)``."""
    n_segments = P.shape[-2] - 3
    idx = np.arange(n_segments)[:, None] + np.arange(4)
    windows = P[..., idx, :]  # (..., S, 4, nq)
    return np.einsum("ab,...sbj->...saj", _M, windows)


def exact_bounds(T: np.ndarray, P: np.ndarray) -> TrajectoryBounds:
    r"""Exact extrema over [0, T] of splines (the math: :meth:`BSplineTrajectory.bounds`).

    Parameters
    ----------
    T:
        (...) travel times [s].
    P:
        (..., S + 3, nq) control points [rad | m].

    Returns
    -------
    TrajectoryBounds
        Per spline and joint (..., nq): ``q_min``, ``q_max`` [rad | m] and the largest
        :math:`|\dot q|, |\ddot q|, |\dddot q|`.
    """
    c = _segment_coefficients(P)
    c3, c2, c1, c0 = c[..., 0, :], c[..., 1, :], c[..., 2, :], c[..., 3, :]  # (..., S, nq)
    a3, b2 = 3.0 * c3, 2.0 * c2
    u_q = _candidates(*_quadratic_roots(a3, b2, c1))  # (..., 4, S, nq)
    cc3, cc2, cc1, cc0 = (ci[..., None, :, :] for ci in (c3, c2, c1, c0))
    q_val = _cubic_at(cc3, cc2, cc1, cc0, u_q)  # (..., k, S, nq)
    qd_val, qdd_val, qddd_val = _derivative_candidates(T, c, a3, b2)

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


def _derivative_candidates(
    T: np.ndarray, c: np.ndarray, a3: np.ndarray, b2: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""The values among which :math:`\dot q, \ddot q, \dddot q` reach their extrema, of
    travel times ``T`` (...) [s] and segment coefficients ``c`` (..., S, 4, nq) (with
    ``a3`` = 3 c₃ and ``b2`` = 2 c₂ (..., S, nq)): velocities (..., 3, S, nq) at
    u ∈ {0, 1, the vertex} [rad/s], accelerations (..., 2, S, nq) at u ∈ {0, 1} [rad/s²],
    jerks (..., S, nq) [rad/s³]. Each value in the order of the formula
    :math:`((3c_3 u + 2c_2) u + c_1)\,r`, :math:`(6 c_3 u + 2 c_2)\,r^2`, in place."""
    c3, c2, c1 = c[..., 0, :], c[..., 1, :], c[..., 2, :]  # (..., S, nq)
    rate = c.shape[-3] / T[..., None, None]  # (..., 1, 1) d/dt = rate·d/du
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = -c2 / a3
    u_qd = _candidates(vertex)  # (..., 3, S, nq): 0, 1, the vertex
    rate4 = rate[..., None, :, :]
    qd_val = a3[..., None, :, :] * u_qd
    qd_val += b2[..., None, :, :]
    qd_val *= u_qd
    qd_val += c1[..., None, :, :]
    qd_val *= rate4
    qdd_val = (6.0 * c3)[..., None, :, :] * u_qd[..., :2, :, :]
    qdd_val += b2[..., None, :, :]
    qdd_val *= rate4**2
    qddd_val = 6.0 * c3 * rate**3  # (..., S, nq)
    return qd_val, qdd_val, qddd_val


def derivative_abs_max(trajectory: Any, x: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Exact :math:`\max_t |\dot q_i|` [rad/s], :math:`\max_t |\ddot q_i|` [rad/s²] and
    :math:`\max_t |\dddot q_i|` [rad/s³] over [0, T], each of shape ``(..., nq)``, of the
    decision vectors ``x`` (..., n_var) of ``trajectory`` (a
    :class:`~adept_traj.problem.BSplineTrajectory`).

    The same numbers, bit for bit, as ``trajectory.bounds(x).qd_abs_max``,
    ``.qdd_abs_max`` and ``.qddd_abs_max``, without the position extrema (the roots of
    :math:`\dot q`), which the kinematic time repair
    (:func:`~adept_traj.optimise.kinematic_time`) does not need. The candidates are those
    of :meth:`~adept_traj.problem.BSplineTrajectory.bounds`, each evaluated on its own:
    at u = 0 the Horner forms reduce to :math:`c_1\,(S/T)` and :math:`2c_2\,(S/T)^2`
    exactly up to the sign of a zero (the products by u = 0 are zeros), at u = 1 to
    sums in the same order (products by 1 are exact), and only magnitudes are kept.

    Raises
    ------
    InputShapeError, InvalidInputError
        As :meth:`~adept_traj.problem.BSplineTrajectory.decode`.
    """
    T, P = trajectory.decode(x)
    return _derivative_abs_max(T, _segment_coefficients(P))


def _derivative_abs_max(T: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`derivative_abs_max` of travel times ``T`` (...) [s] and segment coefficients
    ``c`` (..., S, 4, nq)."""
    c3, c2, c1 = c[..., 0, :], c[..., 1, :], c[..., 2, :]  # (..., S, nq)
    rate = c.shape[-3] / T[..., None, None]  # (..., 1, 1) d/dt = rate·d/du
    with np.errstate(divide="ignore", invalid="ignore"):
        vertex = _clip_candidates(-c2 / (3.0 * c3))
    a3, b2 = 3.0 * c3, 2.0 * c2
    qd = np.maximum(np.abs(c1 * rate), np.abs(((a3 + b2) + c1) * rate))  # u = 0, 1
    np.maximum(qd, np.abs(((a3 * vertex + b2) * vertex + c1) * rate), out=qd)
    rate2 = rate**2
    j3 = 6.0 * c3
    qdd = np.maximum(np.abs(b2 * rate2), np.abs((j3 + b2) * rate2))  # u = 0, 1
    return qd.max(axis=-2), qdd.max(axis=-2), np.abs(j3 * rate**3).max(axis=-2)


def exact_integrals(T: np.ndarray, P: np.ndarray) -> TrajectoryIntegrals:
    """Exact integrals over [0, T] of the squared acceleration and jerk of splines (the math:
    :meth:`BSplineTrajectory.integrals`).

    Parameters
    ----------
    T, P:
        As :func:`exact_bounds`: travel times (...) [s] and control points.

    Returns
    -------
    TrajectoryIntegrals
        ``z5`` and ``z6`` (...).
    """
    c = _segment_coefficients(P)
    A = 6.0 * c[..., 0, :]
    B = 2.0 * c[..., 1, :]
    rate = c.shape[-3] / T[..., None]  # d/dt = rate·d/du
    acc = (A * A / 3.0 + A * B + B * B).sum(axis=-2) * rate**3
    jerk = (A * A).sum(axis=-2) * rate**5
    return TrajectoryIntegrals(acc_sq=acc, jerk_sq=jerk)
