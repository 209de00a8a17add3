"""Tests of adept_traj.problem.bspline against independent references.

References used: a Cox–de Boor B-spline evaluation written here, scipy.interpolate.BSpline,
central finite differences, dense sampling, composite Simpson integration, monomial
integrals, hand-derived minimum times and a linear-programming brute force of the
jerk-limited minimum-time problem.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy import interpolate, optimize

from adept_traj.errors import (
    AdeptTrajError,
    ConfigurationError,
    InputShapeError,
    InvalidInputError,
)
from adept_traj.problem import (
    BSplineTrajectory,
    KinematicBound,
    TrajectoryBounds,
    kinematic_lower_bound,
)

# Paper-like scenario (θ1, θ2, d3 [m], θ4): see docs/trajectory.md.
START = np.array([0.1682, 1.3849, 0.10, -0.7555])
GOAL = np.array([-0.7610, 0.2450, 0.15, 1.0095])
A_MAX, J_MAX = 9.5, 50.0


def random_x(traj: BSplineTrajectory, rng: np.random.Generator, shape: tuple[int, ...]):
    """Random decision vectors: T in [0.5, 3] s, free control points in [-2, 2]."""
    T = rng.uniform(0.5, 3.0, size=shape)
    free = rng.uniform(-2.0, 2.0, size=(*shape, traj.n_free, traj.nq))
    return traj.encode(T, free)


def uniform_knots(n_segments: int) -> np.ndarray:
    """Knot vector of a uniform cubic B-spline on [0, 1] with n_segments segments."""
    return np.arange(-3, n_segments + 4, dtype=float) / n_segments


def cox_de_boor(knots: np.ndarray, coeffs: np.ndarray, s: np.ndarray, degree: int = 3):
    """Direct Cox–de Boor evaluation of sum_c coeffs[c] N_{c,degree}(s), s in [0, 1]."""
    s = np.asarray(s, dtype=float)
    n_c = len(coeffs)
    # Half-open intervals; s = 1 is put into the last basis interval [t_{n_c-1}, t_{n_c}).
    s_eval = np.minimum(s, np.nextafter(knots[n_c], -np.inf))
    N = np.array(
        [
            ((knots[i] <= s_eval) & (s_eval < knots[i + 1])).astype(float)
            for i in range(len(knots) - 1)
        ]
    )
    for p in range(1, degree + 1):
        N_new = np.zeros((len(knots) - 1 - p, s.size))
        for i in range(len(knots) - 1 - p):
            left = (s_eval - knots[i]) / (knots[i + p] - knots[i]) * N[i]
            right = (knots[i + p + 1] - s_eval) / (knots[i + p + 1] - knots[i + 1]) * N[i + 1]
            N_new[i] = left + right
        N = N_new
    return coeffs @ N[:n_c]


@pytest.fixture
def traj() -> BSplineTrajectory:
    return BSplineTrajectory(START, GOAL)


# --------------------------------------------------------------------------------------------
# Construction and layout
# --------------------------------------------------------------------------------------------


def test_paper_sizes(traj: BSplineTrajectory) -> None:
    assert (traj.nq, traj.n_segments, traj.n_control, traj.n_free, traj.n_var) == (
        4,
        19,
        22,
        16,
        65,
    )
    # 88 paper coefficients = 24 fixed by rest-to-rest + 64 free; we add T.
    assert traj.nq * traj.n_control == 88
    assert traj.n_var - 1 + 4 * 6 == 88


def test_frozen_and_inputs_copied() -> None:
    start, goal = START.copy(), GOAL.copy()
    traj = BSplineTrajectory(start, goal)
    start[0] = 99.0
    assert traj.start[0] == START[0]
    with pytest.raises(dataclasses.FrozenInstanceError):
        traj.n_knots = 5  # type: ignore[misc]
    with pytest.raises(ValueError, match="read-only"):
        traj.goal[0] = 1.0


def test_encode_decode_round_trip(traj: BSplineTrajectory) -> None:
    rng = np.random.default_rng(1)
    x = random_x(traj, rng, (7,))
    x_before = x.copy()
    T, P = traj.decode(x)
    np.testing.assert_array_equal(x, x_before)  # caller array untouched
    assert T.shape == (7,)
    assert P.shape == (7, 22, 4)
    np.testing.assert_array_equal(P[:, :3, :], np.broadcast_to(START, (7, 3, 4)))
    np.testing.assert_array_equal(P[:, -3:, :], np.broadcast_to(GOAL, (7, 3, 4)))
    # Joint-major layout: x[1:17] are joint 0's free points, x[17:33] joint 1's, ...
    for j in range(4):
        np.testing.assert_array_equal(x[:, 1 + 16 * j : 1 + 16 * (j + 1)], P[:, 3:-3, j])
    np.testing.assert_array_equal(traj.encode(T, P[..., 3:-3, :]), x)
    # Decoded arrays are independent of x.
    P[...] = 0.0
    np.testing.assert_array_equal(x, x_before)


def test_encode_broadcasts_scalar_T(traj: BSplineTrajectory) -> None:
    free = np.zeros((3, traj.n_free, traj.nq))
    x = traj.encode(1.5, free)
    assert x.shape == (3, 65)
    np.testing.assert_array_equal(x[:, 0], 1.5)


def test_minimal_knots() -> None:
    traj = BSplineTrajectory(START, GOAL, n_knots=4)
    assert (traj.n_segments, traj.n_control, traj.n_free, traj.n_var) == (3, 6, 0, 1)
    x = traj.straight_line(2.0)
    np.testing.assert_array_equal(x, [2.0])
    smp = traj.sample(x, [0.0, 1.0])
    np.testing.assert_allclose(smp.q, [START, GOAL], atol=1e-14)
    # Three segments of width h = 1/3 with P0..P2 = start and P3..P5 = goal: the constant jerk
    # of the first and last segment is (P3 - 3 P2 + 3 P1 - P0) / (h³ T³) = 27 (goal - start) / T³.
    np.testing.assert_allclose(smp.qddd, [27.0 * (GOAL - START) / 8.0] * 2, rtol=1e-12)


# --------------------------------------------------------------------------------------------
# Evaluation against independent references
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("n_knots", [4, 7, 20])
def test_boundary_conditions(n_knots: int) -> None:
    traj = BSplineTrajectory(START, GOAL, n_knots=n_knots)
    rng = np.random.default_rng(2)
    x = random_x(traj, rng, (50,))
    smp = traj.sample(x, np.array([0.0, 1.0]))
    np.testing.assert_allclose(smp.q[:, 0, :], np.broadcast_to(START, (50, 4)), atol=1e-13)
    np.testing.assert_allclose(smp.q[:, 1, :], np.broadcast_to(GOAL, (50, 4)), atol=1e-13)
    np.testing.assert_allclose(smp.qd, 0.0, atol=1e-11)
    np.testing.assert_allclose(smp.qdd, 0.0, atol=1e-9)
    np.testing.assert_allclose(smp.t[:, 1], x[:, 0])
    # the jerk is not zero at the ends (documented)
    assert np.all(np.abs(smp.qddd).max(axis=(1, 2)) > 1e-3)


@pytest.mark.parametrize("n_knots", [4, 7, 20])
def test_position_vs_cox_de_boor(n_knots: int) -> None:
    traj = BSplineTrajectory(START, GOAL, n_knots=n_knots)
    rng = np.random.default_rng(3)
    x = random_x(traj, rng, (5,))
    s = np.concatenate([rng.uniform(0.0, 1.0, 200), np.arange(n_knots) / (n_knots - 1)])
    q = traj.sample(x, s, orders=(0,)).q
    _, P = traj.decode(x)
    knots = uniform_knots(traj.n_segments)
    for i in range(5):
        for j in range(4):
            ref = cox_de_boor(knots, P[i, :, j], s)
            np.testing.assert_allclose(q[i, :, j], ref, rtol=0, atol=1e-12)


def test_all_derivatives_vs_scipy_bspline(traj: BSplineTrajectory) -> None:
    rng = np.random.default_rng(4)
    x = random_x(traj, rng, (4,))
    s = rng.uniform(0.0, 1.0, 300)
    smp = traj.sample(x, s)
    T, P = traj.decode(x)
    knots = uniform_knots(traj.n_segments)
    for i in range(4):
        for j in range(4):
            spl = interpolate.BSpline(knots, P[i, :, j], 3)
            for r, got in enumerate((smp.q, smp.qd, smp.qdd, smp.qddd)):
                ref = spl.derivative(r)(s) / T[i] ** r if r else spl(s)
                scale = max(1.0, np.abs(ref).max())
                np.testing.assert_allclose(got[i, :, j], ref, rtol=0, atol=1e-11 * scale)


def test_derivatives_vs_finite_differences(traj: BSplineTrajectory) -> None:
    rng = np.random.default_rng(5)
    x = random_x(traj, rng, (6,))
    T = x[:, 0]
    S = traj.n_segments
    # Points strictly inside segments, so that all derivatives are smooth around them.
    s = (np.arange(S) + rng.uniform(0.2, 0.8, S)) / S
    h = 1e-4 / S  # step in normalised time
    plus, mid, minus = (traj.sample(x, s + d) for d in (h, 0.0, -h))
    dt = (h * T)[:, None, None]
    fd = {
        "qd": (plus.q - minus.q) / (2 * dt),
        "qdd": (plus.qd - minus.qd) / (2 * dt),
        "qdd2": (plus.q - 2 * mid.q + minus.q) / dt**2,
        "qddd": (plus.qdd - minus.qdd) / (2 * dt),
    }
    np.testing.assert_allclose(mid.qd, fd["qd"], rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(mid.qdd, fd["qdd"], rtol=1e-6, atol=1e-5)
    np.testing.assert_allclose(mid.qdd, fd["qdd2"], rtol=1e-3, atol=1e-2)
    np.testing.assert_allclose(mid.qddd, fd["qddd"], rtol=1e-6, atol=1e-4)


def test_sample_orders_and_basis(traj: BSplineTrajectory) -> None:
    rng = np.random.default_rng(6)
    x = random_x(traj, rng, (3,))
    s = np.linspace(0.0, 1.0, 11)
    full = traj.sample(x, s)
    part = traj.sample(x, s, orders=(2,))
    assert part.q is None
    assert part.qd is None
    assert part.qddd is None
    np.testing.assert_array_equal(part.qdd, full.qdd)
    # Partition of unity; derivatives of the basis sum to zero.
    np.testing.assert_allclose(traj.basis_matrix(s, 0).sum(axis=1), 1.0, atol=1e-14)
    for r in (1, 2, 3):
        np.testing.assert_allclose(traj.basis_matrix(s, r).sum(axis=1), 0.0, atol=1e-9)
    # Column c is the basis function N_c: Cox–de Boor with the unit coefficient vector e_c.
    knots, unit = uniform_knots(traj.n_segments), np.eye(traj.n_control)
    reference = np.column_stack([cox_de_boor(knots, e, s) for e in unit])
    np.testing.assert_allclose(traj.basis_matrix(s, 0), reference, rtol=0, atol=1e-14)
    _, P = traj.decode(x)
    np.testing.assert_allclose(
        full.qd, traj.basis_matrix(s, 1) @ P / x[:, 0, None, None], rtol=1e-12, atol=1e-12
    )


def test_straight_line_is_straight(traj: BSplineTrajectory) -> None:
    x = traj.straight_line(np.array([0.9, 1.5, 3.0]))
    assert x.shape == (3, 65)
    s = np.linspace(0.0, 1.0, 2001)
    smp = traj.sample(x, s)
    d = GOAL - START
    sigma = (smp.q - START) / d  # same σ for every joint ⇔ straight line in joint space
    np.testing.assert_allclose(sigma, np.broadcast_to(sigma[..., :1], sigma.shape), atol=1e-13)
    sig = sigma[..., 0]
    np.testing.assert_allclose(sig[:, 0], 0.0, atol=1e-14)
    np.testing.assert_allclose(sig[:, -1], 1.0, atol=1e-14)
    assert np.all(np.diff(sig, axis=-1) >= -1e-15)  # monotone: no overshoot
    # Same σ(s) for every T; velocities scale like 1/T.
    np.testing.assert_allclose(sig, np.broadcast_to(sig[0], sig.shape), atol=1e-14)
    np.testing.assert_allclose(smp.qd[0] * 0.9, smp.qd[2] * 3.0, atol=1e-12)
    assert traj.straight_line(1.0).shape == (65,)


# --------------------------------------------------------------------------------------------
# Exact bounds and integrals
# --------------------------------------------------------------------------------------------


def _dense_s(traj: BSplineTrajectory, n: int = 20_000) -> np.ndarray:
    knots = np.arange(traj.n_knots) / traj.n_segments
    return np.unique(np.concatenate([np.linspace(0.0, 1.0, n + 1), knots]))


def _check_bounds_vs_dense(traj: BSplineTrajectory, x: np.ndarray, n: int = 20_000) -> None:
    b = traj.bounds(x)
    smp = traj.sample(x, _dense_s(traj, n))
    T2 = (x[..., 0] ** 2)[..., None]
    h = 1.0 / n  # largest sample spacing in s
    # A sampled extremum misses the true one by at most h²/8 · max|d²f/ds²| (nearest
    # sample within h/2 of a stationary point); q̈ (linear) and q⃛ (constant) are sampled
    # exactly at their extrema (knots and segment interiors are in the grid).
    gaps = (h**2 / 8 * T2 * b.qdd_abs_max, h**2 / 8 * T2 * b.qddd_abs_max, 0.0, 0.0)
    pairs = [
        (b.q_min, b.q_max, smp.q),
        (b.qd_min, b.qd_max, smp.qd),
        (b.qdd_min, b.qdd_max, smp.qdd),
        (b.qddd_min, b.qddd_max, smp.qddd),
    ]
    for (lo, hi, vals), gap in zip(pairs, gaps, strict=True):
        smin, smax = vals.min(axis=-2), vals.max(axis=-2)
        eps = 1e-12 * np.maximum(1.0, np.abs(vals).max(axis=-2))
        assert np.all(lo <= smin + eps), "exact minimum above a sampled value"
        assert np.all(hi >= smax - eps), "exact maximum below a sampled value"
        assert np.all(smin - lo <= gap + eps), "exact minimum far below the samples"
        assert np.all(hi - smax <= gap + eps), "exact maximum far above the samples"


def test_bounds_vs_dense_sampling(traj: BSplineTrajectory) -> None:
    rng = np.random.default_rng(7)
    x = random_x(traj, rng, (20,))
    _check_bounds_vs_dense(traj, x)
    # Interior extrema matter: sampling only the knots would miss them.
    b = traj.bounds(x)
    knot_q = traj.sample(x, np.arange(traj.n_knots) / traj.n_segments, orders=(0,)).q
    assert np.any(b.q_max > knot_q.max(axis=-2) + 1e-3)
    assert isinstance(b, TrajectoryBounds)
    assert b.q_min.shape == b.qddd_max.shape == (20, 4)
    np.testing.assert_array_equal(b.qd_abs_max, np.maximum(-b.qd_min, b.qd_max))


def test_bounds_degenerate_polynomials() -> None:
    # Joint 1 does not move (all control points equal: every coefficient but c0 is 0) and
    # joint 0 is linear in the middle segments (c3 = c2 = 0 there): no NaN may leak.
    traj = BSplineTrajectory([0.0, 0.5], [1.0, 0.5], n_knots=12)
    lam = (np.arange(3, traj.n_control - 3) - 2.0) / (traj.n_control - 5.0)
    free = np.stack([lam, np.full_like(lam, 0.5)], axis=-1)
    x = traj.encode(2.0, free)
    b = traj.bounds(x)
    for field in dataclasses.fields(b):
        assert np.all(np.isfinite(getattr(b, field.name)))
    np.testing.assert_allclose([b.q_min[1], b.q_max[1]], 0.5, atol=1e-15)
    for abs_max in (b.qd_abs_max, b.qdd_abs_max, b.qddd_abs_max):
        assert abs_max[1] < 1e-12
    np.testing.assert_allclose([b.q_min[0], b.q_max[0]], [0.0, 1.0], atol=1e-15)
    _check_bounds_vs_dense(traj, x)


def simpson_integrals(traj: BSplineTrajectory, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """∫₀ᵀ q̈² dt and ∫₀ᵀ q⃛² dt per joint, (..., nq), by composite Simpson on the samples.

    An even number of panels per segment: exact for the piecewise quadratic q̈² and the
    piecewise constant q⃛² (up to rounding).
    """
    per_seg = 40
    n = traj.n_segments * per_seg
    s = np.linspace(0.0, 1.0, n + 1)
    s[per_seg::per_seg] = np.arange(1, traj.n_segments + 1) / traj.n_segments
    w = np.ones(n + 1)
    w[1:-1:2], w[2:-1:2] = 4.0, 2.0
    w /= 3.0 * n
    # At knots the jerk jumps: use one-sided values (left/right limits) from each side.
    smp_left = traj.sample(x, np.clip(s - 1e-13, 0.0, 1.0))
    smp_right = traj.sample(x, np.clip(s + 1e-13, 0.0, 1.0))
    T = x[..., 0, None]
    ref_acc = T * np.einsum("k,...kj->...j", w, 0.5 * (smp_left.qdd**2 + smp_right.qdd**2))
    ref_jerk = T * np.einsum("k,...kj->...j", w, 0.5 * (smp_left.qddd**2 + smp_right.qddd**2))
    return ref_acc, ref_jerk


def test_integrals_vs_simpson(traj: BSplineTrajectory) -> None:
    rng = np.random.default_rng(8)
    x = random_x(traj, rng, (10,))
    ref_acc, ref_jerk = simpson_integrals(traj, x)
    got = traj.integrals(x)
    np.testing.assert_allclose(got.acc_sq, ref_acc, rtol=1e-9)
    np.testing.assert_allclose(got.jerk_sq, ref_jerk, rtol=1e-9)
    np.testing.assert_allclose(got.z6, ref_acc.sum(axis=-1), rtol=1e-9)
    np.testing.assert_allclose(got.z5, ref_jerk.sum(axis=-1), rtol=1e-9)


def test_integrals_scale_with_time(traj: BSplineTrajectory) -> None:
    # Same path, time scaled by c: ∫q̈² scales by c⁻³ and ∫q⃛² by c⁻⁵.
    x1 = traj.straight_line(1.0)
    x2 = traj.straight_line(2.0)
    i1, i2 = traj.integrals(x1), traj.integrals(x2)
    np.testing.assert_allclose(i2.acc_sq, i1.acc_sq / 8.0, rtol=1e-13)
    np.testing.assert_allclose(i2.jerk_sq, i1.jerk_sq / 32.0, rtol=1e-13)


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_quadrature_exactness(traj: BSplineTrajectory, n: int) -> None:
    s, w = traj.quadrature(n)
    S = traj.n_segments
    assert s.shape == w.shape == (S * n,)
    assert np.all(np.diff(s) > 0)
    assert s[0] > 0.0
    assert s[-1] < 1.0
    np.testing.assert_allclose(w.sum(), 1.0, rtol=1e-14)
    # Piecewise monomials u^p in each segment's local parameter: ∫₀¹ = 1/(p+1).
    u = s * S - np.floor(s * S)
    for p in range(2 * n):
        np.testing.assert_allclose(w @ u**p, 1.0 / (p + 1), rtol=1e-13)
    # One degree more is no longer exact (the claimed degree is sharp).
    assert abs(w @ u ** (2 * n) - 1.0 / (2 * n + 1)) > 1e-8


@pytest.mark.parametrize("n", [2, 3, 5])
def test_quadrature_integrates_acceleration_squared(traj: BSplineTrajectory, n: int) -> None:
    """∫₀ᵀ q̈² dt with n ≥ 2 points per segment (q̈² is of degree 2 per segment) equals
    composite Simpson's value."""
    s, w = traj.quadrature(n)
    x = random_x(traj, np.random.default_rng(9), (3,))
    qdd = traj.sample(x, s, orders=(2,)).qdd
    approx = x[:, 0, None] * np.einsum("k,pkj->pj", w, qdd**2)
    np.testing.assert_allclose(approx, simpson_integrals(traj, x)[0], rtol=1e-9)


def test_one_point_quadrature_misses_acceleration_squared(traj: BSplineTrajectory) -> None:
    """One midpoint per segment integrates degree 1 only: q̈² (degree 2) is missed."""
    s, w = traj.quadrature(1)
    x = random_x(traj, np.random.default_rng(9), (3,))
    qdd = traj.sample(x, s, orders=(2,)).qdd
    approx = x[:, 0, None] * np.einsum("k,pkj->pj", w, qdd**2)
    exact = simpson_integrals(traj, x)[0]
    assert np.all(np.abs(approx - exact) > 1e-6 * exact)


# --------------------------------------------------------------------------------------------
# Batching
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("shape", [(6,), (2, 3)])
def test_batched_equals_loop(traj: BSplineTrajectory, shape: tuple[int, ...]) -> None:
    rng = np.random.default_rng(10)
    x = random_x(traj, rng, shape)
    s = np.linspace(0.0, 1.0, 37)
    smp, b, integ = traj.sample(x, s), traj.bounds(x), traj.integrals(x)
    T, P = traj.decode(x)
    assert smp.t.shape == (*shape, 37)
    assert smp.q.shape == smp.qddd.shape == (*shape, 37, 4)
    assert b.q_min.shape == integ.acc_sq.shape == (*shape, 4)
    assert T.shape == shape
    assert P.shape == (*shape, 22, 4)
    for idx in np.ndindex(*shape):
        one = x[idx]
        s1, b1, i1 = traj.sample(one, s), traj.bounds(one), traj.integrals(one)
        for name in ("t", "q", "qd", "qdd", "qddd"):
            np.testing.assert_allclose(getattr(smp, name)[idx], getattr(s1, name), rtol=1e-14)
        for f in dataclasses.fields(b):
            np.testing.assert_allclose(getattr(b, f.name)[idx], getattr(b1, f.name), rtol=1e-14)
        np.testing.assert_allclose(integ.acc_sq[idx], i1.acc_sq, rtol=1e-14)
        np.testing.assert_allclose(integ.jerk_sq[idx], i1.jerk_sq, rtol=1e-14)
    # Deterministic.
    np.testing.assert_array_equal(traj.sample(x, s).q, smp.q)
    np.testing.assert_array_equal(traj.bounds(x).q_max, b.q_max)


# --------------------------------------------------------------------------------------------
# Decision bounds
# --------------------------------------------------------------------------------------------


def test_decision_bounds_layout_and_convex_hull(traj: BSplineTrajectory) -> None:
    lo = np.array([-2.618, -2.4435, 0.0, -4.7124])
    hi = -lo
    hi[2] = 0.203
    xl, xu = traj.decision_bounds(lo, hi, 0.5, 4.0)
    assert xl.shape == xu.shape == (65,)
    assert (xl[0], xu[0]) == (0.5, 4.0)
    for j in range(4):
        np.testing.assert_array_equal(xl[1 + 16 * j : 1 + 16 * (j + 1)], lo[j])
        np.testing.assert_array_equal(xu[1 + 16 * j : 1 + 16 * (j + 1)], hi[j])
    rng = np.random.default_rng(11)
    x = rng.uniform(xl, xu, size=(200, 65))
    x[:100, 1:] = np.where(rng.random((100, 64)) < 0.5, xl[1:], xu[1:])  # box corners
    b = traj.bounds(x)
    # Convex hull: inside the limits up to rounding of the basis sums.
    assert np.all(b.q_min >= lo - 1e-12)
    assert np.all(b.q_max <= hi + 1e-12)


# --------------------------------------------------------------------------------------------
# Kinematic lower bound
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("delta", "expected"), [(0.929, 0.844), (1.140, 0.908), (1.765, 1.073)])
def test_kinematic_bound_paper_values(delta: float, expected: float) -> None:
    kb = kinematic_lower_bound([0.0], [delta], np.inf, A_MAX, J_MAX)
    assert round(kb.T_min, 3) == expected
    # a reached, v not: T = a/j + sqrt((a/j)² + 4Δ/a)  (hand formula)
    ref = A_MAX / J_MAX + np.sqrt((A_MAX / J_MAX) ** 2 + 4 * delta / A_MAX)
    assert kb.T_min == pytest.approx(ref, rel=1e-14)
    assert kb.cases == ("acc",)


def test_kinematic_bound_paper_joints() -> None:
    kb = kinematic_lower_bound(START, GOAL, [11.3446, 16.057, 1.2, 57.5959], A_MAX, J_MAX)
    assert isinstance(kb, KinematicBound)
    assert kb.times.shape == (4,)
    np.testing.assert_allclose(kb.delta, np.abs(GOAL - START))
    # |Δ| = 0.9292, 1.1399, 1.765 (the notes round to 0.929, 1.140, 1.765).
    np.testing.assert_allclose(kb.times[[0, 1, 3]], [0.844, 0.908, 1.073], atol=5e-4)
    assert kb.limiting_joint == 3
    assert kb.T_min == kb.times[3]


def test_kinematic_bound_zero_and_infinite() -> None:
    kb = kinematic_lower_bound([1.0, 2.0], [1.0, 2.0], 1.0, 1.0, 1.0)
    np.testing.assert_array_equal(kb.times, 0.0)
    assert kb.T_min == 0.0
    assert kb.limiting_joint == 0
    assert kb.cases == ("rest", "rest")
    h = 2.0
    assert kinematic_lower_bound([0], [h], np.inf, np.inf, np.inf).T_min == 0.0
    assert kinematic_lower_bound([0], [h], 0.5, np.inf, np.inf).T_min == pytest.approx(h / 0.5)
    # Jerk unlimited: triangular / trapezoidal velocity.
    assert kinematic_lower_bound([0], [h], np.inf, 2.0, np.inf).T_min == pytest.approx(2.0)
    assert kinematic_lower_bound([0], [h], 1.0, 2.0, np.inf).T_min == pytest.approx(2.5)
    # Acceleration unlimited: pure jerk profile, T = 4 (h / 2j)^(1/3).
    assert kinematic_lower_bound([0], [h], np.inf, np.inf, 8.0).T_min == pytest.approx(2.0)
    # Large finite limits tend to the infinite-limit answers.
    big = kinematic_lower_bound([0], [h], 1e9, 2.0, 1e12).T_min
    assert big == pytest.approx(2.0, rel=1e-6)


def test_kinematic_bound_all_cases_by_hand() -> None:
    # Velocity limiting, a not reached (v·j < a²): T = Δ/v + 2 sqrt(v/j).
    kb = kinematic_lower_bound([0.0], [2.0], 1.0, A_MAX, J_MAX)
    assert kb.cases == ("vel",)
    assert kb.T_min == pytest.approx(2.0 + 2.0 * np.sqrt(1.0 / J_MAX), rel=1e-14)
    # Velocity and acceleration reached: T = Δ/v + v/a + a/j.
    kb = kinematic_lower_bound([0.0], [3.0], 1.0, 2.0, J_MAX)
    assert kb.cases == ("acc+vel",)
    assert kb.T_min == pytest.approx(3.0 + 0.5 + 0.04, rel=1e-14)
    # Neither reached: T = 4 (Δ / 2j)^(1/3).
    kb = kinematic_lower_bound([0.0], [-0.1], np.inf, A_MAX, J_MAX)
    assert kb.cases == ("jerk",)
    assert kb.T_min == pytest.approx(0.4, rel=1e-14)


@pytest.mark.parametrize(
    ("v", "cases"), [(3.0, {"jerk", "acc", "acc+vel"}), (1.5, {"jerk", "vel"})]
)
def test_kinematic_bound_continuous_across_cases(v: float, cases: set[str]) -> None:
    # T(Δ) is continuous and increasing through every case boundary.
    deltas = np.linspace(1e-4, 6.0, 3001)
    kb = kinematic_lower_bound(np.zeros_like(deltas), deltas, v, A_MAX, J_MAX)
    assert set(kb.cases) == cases
    diffs = np.diff(kb.times)
    assert np.all(diffs > 0)
    # No jump where the case changes: the step there is like its neighbours' steps.
    changes = [i for i in range(1, len(deltas) - 2) if kb.cases[i] != kb.cases[i + 1]]
    assert len(changes) == len(cases) - 1
    for i in changes:
        assert diffs[i] <= 1.01 * max(diffs[i - 1], diffs[i + 1])


def _lp_max_distance(T: float, v: float, a: float, j: float, n: int = 240) -> float:
    """Largest rest-to-rest distance with piecewise-constant jerk on n steps (LP)."""
    dt = T / n
    L = np.tril(np.ones((n + 1, n)), -1)  # row k sums steps i < k
    acc = dt * L  # a_k
    vel = L @ (dt * acc[:n] + 0.5 * dt**2 * np.eye(n))
    pos = L @ (dt * vel[:n] + 0.5 * dt**2 * acc[:n] + dt**3 / 6.0 * np.eye(n))
    A_ub = np.vstack([acc, -acc, vel, -vel])
    b_ub = np.concatenate([np.full(2 * (n + 1), a), np.full(2 * (n + 1), v)])
    A_eq = np.vstack([acc[n], vel[n]])
    res = optimize.linprog(
        -pos[n], A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=[0.0, 0.0], bounds=(-j, j), method="highs"
    )
    assert res.status == 0
    return -res.fun


@pytest.mark.parametrize(
    ("delta", "v"),
    [(0.929, np.inf), (1.765, 57.6), (0.1, np.inf), (2.0, 1.0), (3.0, 1.0e3)],
)
def test_kinematic_bound_brute_force_lp(delta: float, v: float) -> None:
    a, j = (2.0, J_MAX) if delta == 3.0 else (A_MAX, J_MAX)
    v_lp = 1e6 if np.isinf(v) else v
    T_min = kinematic_lower_bound([0.0], [delta], v, a, j).T_min
    # Slightly faster is impossible, slightly slower is possible (discretised jerk).
    assert _lp_max_distance(0.985 * T_min, v_lp, a, j) < delta
    assert _lp_max_distance(1.015 * T_min, v_lp, a, j) >= delta


# --------------------------------------------------------------------------------------------
# Bad inputs
# --------------------------------------------------------------------------------------------


def test_bad_construction() -> None:
    with pytest.raises(InvalidInputError, match="nan"):
        BSplineTrajectory([0.0, np.nan], [1.0, 1.0])
    with pytest.raises(InputShapeError, match=r"\(3,\)"):
        BSplineTrajectory([0.0, 1.0], [1.0, 1.0, 1.0])
    with pytest.raises(InputShapeError, match="start"):
        BSplineTrajectory([[0.0, 1.0]], [1.0, 1.0])
    with pytest.raises(ConfigurationError, match="3"):
        BSplineTrajectory(START, GOAL, n_knots=3)
    with pytest.raises(ConfigurationError, match=r"4\.5"):
        BSplineTrajectory(START, GOAL, n_knots=4.5)  # type: ignore[arg-type]
    with pytest.raises(ConfigurationError, match="True"):
        BSplineTrajectory(START, GOAL, n_knots=True)


def test_bad_decision_vectors(traj: BSplineTrajectory) -> None:
    x = traj.straight_line(1.0)
    with pytest.raises(InputShapeError, match="65"):
        traj.decode(x[:-1])
    bad_T = np.stack([x, x])
    bad_T[1, 0] = -1.5
    for method in (traj.decode, traj.bounds, traj.integrals):
        with pytest.raises(InvalidInputError, match=r"-1\.5"):
            method(bad_T)
    x_nan = x.copy()
    x_nan[5] = np.nan
    with pytest.raises(InvalidInputError, match="nan"):
        traj.sample(x_nan, [0.5])
    with pytest.raises(InvalidInputError, match=r"T.*0\.0"):
        traj.straight_line(0.0)
    with pytest.raises(InputShapeError, match=r"\(\.\.\., 16, 4\)"):
        traj.encode(1.0, np.zeros((4, 16)))


def test_bad_sample_arguments(traj: BSplineTrajectory) -> None:
    x = traj.straight_line(1.0)
    with pytest.raises(InvalidInputError, match=r"1\.5"):
        traj.sample(x, [0.0, 1.5])
    with pytest.raises(InputShapeError, match="n_s"):
        traj.sample(x, [[0.0, 1.0]])
    with pytest.raises(InvalidInputError, match="orders"):
        traj.sample(x, [0.5], orders=(4,))
    with pytest.raises(InvalidInputError, match="orders"):
        traj.sample(x, [0.5], orders=())
    with pytest.raises(InvalidInputError, match="n_per_segment"):
        traj.quadrature(0)


def test_bad_decision_bounds(traj: BSplineTrajectory) -> None:
    lo, hi = np.full(4, -3.0), np.full(4, 3.0)
    with pytest.raises(InvalidInputError, match=r"T_min must be > 0.*0\.0"):
        traj.decision_bounds(lo, hi, 0.0, 2.0)
    with pytest.raises(InvalidInputError, match=r"T_min=2\.0, T_max=1\.0"):
        traj.decision_bounds(lo, hi, 2.0, 1.0)
    with pytest.raises(InvalidInputError, match="nan"):
        traj.decision_bounds(lo, hi, 1.0, np.nan)
    tight = hi.copy()
    tight[1] = 1.0
    with pytest.raises(InvalidInputError, match=r"start\[1\] = 1\.3849.*joint 1.*\[-3\.0, 1\.0\]"):
        traj.decision_bounds(lo, tight, 0.5, 2.0)
    low = lo.copy()
    low[3] = 0.0
    with pytest.raises(InvalidInputError, match=r"start\[3\] = -0\.7555"):
        traj.decision_bounds(low, hi, 0.5, 2.0)
    with pytest.raises(InvalidInputError, match="joint 0"):
        traj.decision_bounds(hi, lo, 0.5, 2.0)
    with pytest.raises(InputShapeError, match="q_lower"):
        traj.decision_bounds(lo[:3], hi, 0.5, 2.0)


def test_bad_kinematic_bound_arguments() -> None:
    with pytest.raises(InvalidInputError, match=r"a_max.*-1\.0"):
        kinematic_lower_bound([0.0], [1.0], 1.0, -1.0, 1.0)
    with pytest.raises(InvalidInputError, match=r"j_max.*nan"):
        kinematic_lower_bound([0.0], [1.0], 1.0, 1.0, np.nan)
    with pytest.raises(InvalidInputError, match=r"v_max.*0\.0"):
        kinematic_lower_bound([0.0], [1.0], 0.0, 1.0, 1.0)
    with pytest.raises(InputShapeError, match="v_max"):
        kinematic_lower_bound([0.0, 0.0], [1.0, 1.0], [1.0, 1.0, 1.0], 1.0, 1.0)
    with pytest.raises(InputShapeError, match="goal"):
        kinematic_lower_bound([0.0, 0.0], [1.0], 1.0, 1.0, 1.0)
    with pytest.raises(InvalidInputError, match="inf"):
        kinematic_lower_bound([0.0], [np.inf], 1.0, 1.0, 1.0)


def test_all_errors_are_adept_traj_errors(traj: BSplineTrajectory) -> None:
    with pytest.raises(AdeptTrajError):
        traj.decode(np.zeros(3))
    with pytest.raises(AdeptTrajError):
        kinematic_lower_bound([0.0], [1.0], "fast", 1.0, 1.0)
