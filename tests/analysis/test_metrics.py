"""Tests of the indicators against hand values and independent numpy oracles.

The library computes the hypervolume, dominance and IGD with moocore / pymoo; the oracles
(``adept_traj.testing.indicator_oracles``: the WFG hypervolume, the pairwise dominance test, the IGD
double loop) share no code with them.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from adept_traj.analysis import (
    algorithm_effort,
    hypervolume,
    igd,
    non_dominated,
    normalised_hypervolume,
    objective_bounds,
    optimizer_overhead,
    ratio_non_dominated,
    spread,
    to_unit_minimisation,
)
from adept_traj.errors import ConfigurationError, InputShapeError, InvalidInputError
from adept_traj.problem import MAXIMISED
from adept_traj.testing.indicator_oracles import (
    dominated_mask,
    first_copies,
    igd_loop,
    wfg_hypervolume,
)

SQ2 = np.sqrt(2.0)


def sphere_front(n: int, m: int, seed: int) -> np.ndarray:
    """n mutually non-dominated points on the positive unit sphere (minimisation)."""
    rng = np.random.default_rng(seed)
    X = np.abs(rng.normal(size=(n, m)))
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def line_front(xs: np.ndarray) -> np.ndarray:
    """Points (x, 1 - x) on a straight 2-D front."""
    xs = np.asarray(xs, dtype=float)
    return np.column_stack([xs, 1.0 - xs])


# ================================================================= hypervolume
@pytest.mark.parametrize("m", [2, 3, 4, 5, 6])
@pytest.mark.parametrize("seed", [0, 1])
def test_hypervolume_matches_wfg_random_cloud(m: int, seed: int) -> None:
    rng = np.random.default_rng(100 * m + seed)
    P = rng.random((60, m))
    ref = np.full(m, 0.9)  # some points do not dominate it
    ours = hypervolume(P, ref, maximised=False)
    assert ours > 0.0
    assert ours == pytest.approx(wfg_hypervolume(P, ref), rel=1e-12)


@pytest.mark.parametrize("m", [3, 4, 5, 6])
def test_hypervolume_matches_wfg_sphere_front(m: int) -> None:
    P = sphere_front(40, m, seed=m)
    ref = np.full(m, 1.1)
    assert hypervolume(P, ref, maximised=False) == pytest.approx(wfg_hypervolume(P, ref), rel=1e-12)


def test_hypervolume_paper_sense_matches_wfg() -> None:
    """Six objectives with z4 maximised (the default sense), raw-looking scales."""
    rng = np.random.default_rng(7)
    scale = np.array([1.0, 1e7, 1e-4, 0.16, 300.0, 300.0])
    F = rng.random((50, 6)) * scale
    ref = np.array([1.1, 1.1e7, 1.1e-4, 0.0, 330.0, 330.0])  # z4: reference lies below
    ours = hypervolume(F, ref)
    assert MAXIMISED == (False, False, False, True, False, False)
    flip = np.array([1.0, 1.0, 1.0, -1.0, 1.0, 1.0])  # z4 to minimisation form
    assert ours == pytest.approx(wfg_hypervolume(F * flip, ref * flip), rel=1e-12)


def test_hypervolume_hand_values() -> None:
    assert hypervolume([[1.0, 2.0], [2.0, 1.0]], [3.0, 3.0], maximised=False) == 3.0
    assert hypervolume([[1.0, 1.0, 1.0]], [2.0, 3.0, 4.0], maximised=False) == 6.0
    # three boxes of volume 4 in [0, 2]^3, by inclusion-exclusion
    P = [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    boxes = [np.array(p) for p in P]
    ref = np.full(3, 2.0)
    total = 0.0
    for r in range(1, 4):
        for combo in itertools.combinations(boxes, r):
            total += (-1) ** (r + 1) * np.prod(ref - np.max(combo, axis=0))
    assert hypervolume(P, ref, maximised=False) == pytest.approx(total, rel=1e-15)
    assert total == 7.0  # 4 + 4 + 4 - 2 - 2 - 2 + 1


def test_hypervolume_ignores_points_not_dominating_reference() -> None:
    P = np.array([[1.0, 2.0], [2.0, 1.0]])
    extra = np.array([[3.0, 0.0], [0.0, 3.0], [5.0, 5.0], [2.5, 3.0]])
    assert hypervolume(np.vstack([P, extra]), [3.0, 3.0], maximised=False) == 3.0
    assert hypervolume(extra, [3.0, 3.0], maximised=False) == 0.0


def test_hypervolume_dominated_and_duplicates_do_not_change_it() -> None:
    P = sphere_front(30, 5, seed=2)
    ref = np.full(5, 1.1)
    base = hypervolume(P, ref, maximised=False)
    noisy = np.vstack([P, P[:10], P[:10] + 0.05])
    assert hypervolume(noisy, ref, maximised=False) == pytest.approx(base, rel=1e-13)


def test_hypervolume_maximised_equals_negated_minimised() -> None:
    P = sphere_front(25, 4, seed=5)
    sense = (True, False, True, False)
    flipped = np.where(sense, -P, P)
    ref = np.array([-1.1, 1.1, -1.1, 1.1])
    a = hypervolume(flipped, ref, maximised=sense)
    b = hypervolume(P, np.full(4, 1.1), maximised=False)
    assert a == pytest.approx(b, rel=1e-13)
    assert a > 0.0


def test_hypervolume_does_not_mutate_input() -> None:
    F = sphere_front(20, 6, seed=9)
    F_copy = F.copy()
    ref = np.full(6, 1.1)
    hypervolume(F, ref)
    np.testing.assert_array_equal(F, F_copy)
    np.testing.assert_array_equal(ref, np.full(6, 1.1))


def test_hypervolume_100_points_6d_matches_wfg() -> None:
    """The planner's front size and dimension (WFG takes about 1 s here)."""
    F = sphere_front(100, 6, seed=42)
    value = hypervolume(F, np.full(6, 1.1), maximised=False)
    assert value == pytest.approx(wfg_hypervolume(F, np.full(6, 1.1)), rel=1e-12)


@pytest.mark.parametrize(
    ("F", "ref", "error"),
    [
        ([[np.nan, 1.0]], [2.0, 2.0], InvalidInputError),
        ([1.0, 1.0], [2.0, 2.0], InputShapeError),
        ([[1.0, 1.0]], [2.0, 2.0, 2.0], InputShapeError),
        ([[1.0, 1.0]], [2.0, np.inf], InvalidInputError),
    ],
)
def test_hypervolume_bad_inputs(F: list, ref: list, error: type[Exception]) -> None:
    with pytest.raises(error):
        hypervolume(F, ref, maximised=False)


def test_default_sense_needs_six_objectives() -> None:
    with pytest.raises(InputShapeError, match="maximised"):
        hypervolume([[1.0, 1.0]], [2.0, 2.0])


# ================================================================= normalised HV
def test_to_unit_minimisation_hand_values() -> None:
    F = np.array([[1.0, 10.0, 5.0], [3.0, 20.0, 5.0]])
    u = to_unit_minimisation(F, [1.0, 10.0, 5.0], [3.0, 30.0, 5.0], (False, True, False))
    np.testing.assert_allclose(u, [[0.0, 1.0, 0.0], [1.0, 0.5, 0.0]])
    with pytest.raises(InvalidInputError):
        to_unit_minimisation(F, [4.0, 10.0, 5.0], [3.0, 30.0, 5.0], False)


def test_normalised_hypervolume_extremes() -> None:
    lo, hi = np.zeros(6), np.ones(6)
    ideal = np.array([[0.0, 0.0, 0.0, 1.0, 0.0, 0.0]])  # z4 maximised: 1 is its ideal
    nadir = np.array([[1.0, 1.0, 1.0, 0.0, 1.0, 1.0]])
    assert normalised_hypervolume(ideal, lo, hi) == pytest.approx(1.1**6, rel=1e-14)
    assert normalised_hypervolume(nadir, lo, hi) == pytest.approx(0.1**6, rel=1e-12)
    assert normalised_hypervolume(nadir, lo, hi, reference=1.0) == 0.0


def test_normalised_hypervolume_matches_wfg_on_common_bounds() -> None:
    rng = np.random.default_rng(21)
    A = rng.random((30, 6)) * [1, 1e7, 1e-4, 0.16, 300, 300]
    B = rng.random((30, 6)) * [1, 1e7, 1e-4, 0.16, 300, 300]
    lo, hi = objective_bounds(A, B)
    np.testing.assert_array_equal(lo, np.minimum(A.min(0), B.min(0)))
    u = (A - lo) / (hi - lo)
    u[:, 3] = 1.0 - u[:, 3]
    expected = wfg_hypervolume(u, np.full(6, 1.1))
    assert normalised_hypervolume(A, lo, hi) == pytest.approx(expected, rel=1e-12)


# ================================================================= IGD
@pytest.mark.parametrize(("m", "seed"), [(2, 0), (3, 1), (6, 2)])
def test_igd_matches_double_loop(m: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    A = rng.random((40, m))
    R = sphere_front(70, m, seed)
    assert igd(A, R) == pytest.approx(igd_loop(A, R), rel=1e-12)
    np.testing.assert_array_equal(A, np.random.default_rng(seed).random((40, m)))  # unchanged


def test_igd_hand_value() -> None:
    assert igd([[0.0, 0.0]], [[3.0, 4.0], [0.0, 1.0]]) == 3.0
    assert igd([[0.0, 1.0], [3.0, 4.0]], [[3.0, 4.0], [0.0, 1.0]]) == 0.0
    with pytest.raises(InputShapeError):
        igd([[0.0, 0.0]], [[1.0, 2.0, 3.0]])


# ================================================================= dominance, RNI
@pytest.mark.parametrize("m", [2, 3, 6])
def test_non_dominated_matches_pairwise_oracle(m: int) -> None:
    rng = np.random.default_rng(m)
    P = np.round(rng.random((100, m)), 1)  # coarse grid: many ties
    P = np.vstack([P, P[::-1]])  # every point twice
    ours = non_dominated(P, maximised=False)
    np.testing.assert_array_equal(ours, ~dominated_mask(P))
    first = non_dominated(P, maximised=False, keep_duplicates=False)
    np.testing.assert_array_equal(first, ~dominated_mask(P) & first_copies(P))
    assert 0 < first.sum() < ours.sum() < 200


def test_non_dominated_paper_sense_matches_pairwise_oracle() -> None:
    rng = np.random.default_rng(5)
    F = np.round(rng.random((150, 6)), 1)
    flip = np.array([1.0, 1.0, 1.0, -1.0, 1.0, 1.0])  # z4 maximised
    np.testing.assert_array_equal(non_dominated(F), ~dominated_mask(F * flip))


def test_ratio_non_dominated_hand_value() -> None:
    P = [[1.0, 1.0], [2.0, 2.0], [0.0, 3.0], [1.0, 1.0]]
    np.testing.assert_array_equal(non_dominated(P, False), [True, False, True, True])
    assert ratio_non_dominated(P, maximised=False) == 0.75
    # both maximised: (2, 2) dominates (1, 1); (0, 3) stays non-dominated
    np.testing.assert_array_equal(non_dominated(P, True), [False, True, True, False])
    assert ratio_non_dominated(P, maximised=(True, True)) == 0.5


def test_ratio_non_dominated_matches_pairwise_oracle() -> None:
    rng = np.random.default_rng(8)
    F = rng.random((100, 6))
    flip = np.array([1.0, 1.0, 1.0, -1.0, 1.0, 1.0])  # z4 maximised
    expected = (~dominated_mask(F * flip)).mean()
    assert 0.0 < expected < 1.0
    assert ratio_non_dominated(F) == pytest.approx(expected, abs=0)


# ================================================================= spread
def deb_spread_reference(front: np.ndarray, e_first: np.ndarray, e_last: np.ndarray) -> float:
    """Deb et al. (2002) eq. (1), written out literally with a loop (raw values)."""
    pts = sorted(map(tuple, front))
    gaps = [float(np.hypot(b[0] - a[0], b[1] - a[1])) for a, b in itertools.pairwise(pts)]
    d_mean = sum(gaps) / len(gaps)
    d_f = float(np.linalg.norm(np.asarray(pts[0]) - e_first))
    d_l = float(np.linalg.norm(np.asarray(pts[-1]) - e_last))
    return (d_f + d_l + sum(abs(g - d_mean) for g in gaps)) / (d_f + d_l + len(gaps) * d_mean)


@pytest.mark.parametrize("method", ["auto", "deb", "generalized"])
def test_spread_uniform_front_is_zero(method: str) -> None:
    F = line_front(np.linspace(0.0, 1.0, 11))
    assert spread(F, maximised=False, method=method) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("method", ["deb", "generalized"])
def test_spread_clustered_front_is_positive(method: str) -> None:
    F = line_front([0.0, 0.02, 0.04, 0.06, 1.0])
    assert spread(F, maximised=False, method=method) > 0.3


def test_spread_hand_values_three_points() -> None:
    F = line_front([0.0, 0.2, 1.0])
    # Deb: gaps 0.2√2, 0.8√2, mean 0.5√2 -> 0.6√2 / (2 · 0.5√2) = 0.6
    assert spread(F, maximised=False, method="deb", normalise=False) == pytest.approx(0.6)
    # generalised: NN distances 0.2√2, 0.2√2, 0.8√2, mean 0.4√2 -> 0.8√2 / 1.2√2 = 2/3
    assert spread(F, maximised=False, method="generalized", normalise=False) == pytest.approx(
        2.0 / 3.0
    )
    # the front is already in [0, 1]^2, so normalising changes nothing
    assert spread(F, maximised=False, method="deb") == pytest.approx(0.6)


def test_spread_with_reference_extremes_hand_values() -> None:
    F = line_front([0.0, 0.5, 1.0])
    reference = np.array([[-0.5, 1.5], [1.5, -0.5], [0.5, 0.5]])
    # extremes (-0.5, 1.5) and (1.5, -0.5) are 0.5√2 from the ends
    # Deb: (√2) / (√2 + 2 · 0.5√2) = 0.5
    deb = spread(F, reference, maximised=False, method="deb", normalise=False)
    assert deb == pytest.approx(0.5)
    # generalised: √2 / (√2 + 3 · 0.5√2) = 0.4
    gen = spread(F, reference, maximised=False, method="generalized", normalise=False)
    assert gen == pytest.approx(0.4)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_spread_deb_matches_literal_formula(seed: int) -> None:
    rng = np.random.default_rng(seed)
    F = line_front(np.sort(rng.random(12))) + rng.normal(scale=0.01, size=(12, 2))
    e1, e2 = np.array([-0.1, 1.2]), np.array([1.15, -0.05])  # ends of the reference front
    reference = np.vstack([e1, e2])
    ours = spread(F, reference, maximised=False, normalise=False)  # auto -> Deb for m = 2
    assert ours == pytest.approx(deb_spread_reference(F, e1, e2), rel=1e-12)
    assert 0.0 < ours < 1.5


def test_spread_uniform_3d_simplex_is_zero_and_clustering_raises_it() -> None:
    k = 4
    grid = [(i / k, j / k, 1 - (i + j) / k) for i in range(k + 1) for j in range(k + 1 - i)]
    F = np.array(grid)
    assert spread(F, maximised=False) == pytest.approx(0.0, abs=1e-12)
    clustered = np.vstack([F, F[3] + [0.01, -0.01, 0.0]])
    assert spread(clustered, maximised=False) > 0.05
    missing_corner = F[~np.isclose(F[:, 0], 1.0)]  # drop the extreme of objective 1
    assert spread(missing_corner, F, maximised=False) > 0.05


def test_spread_normalisation_makes_units_irrelevant() -> None:
    rng = np.random.default_rng(12)
    F = sphere_front(30, 3, seed=12) + rng.normal(scale=0.02, size=(30, 3))
    scaled = F * [1.0, 1e6, 1e-3]
    assert spread(scaled, maximised=False) == pytest.approx(spread(F, maximised=False), rel=1e-10)
    raw_a = spread(scaled, maximised=False, normalise=False)
    raw_b = spread(F, maximised=False, normalise=False)
    assert abs(raw_a - raw_b) > 1e-3


def test_spread_sense_selects_the_extremes() -> None:
    F = sphere_front(25, 6, seed=3)
    R = sphere_front(60, 6, seed=4)  # reference set: its extremes are not points of F
    flip = np.array([1.0, 1.0, 1.0, -1.0, 1.0, 1.0])
    a = spread(F, R, maximised=False)
    b = spread(F * flip, R * flip)  # default MAXIMISED: z4 maximised, same geometry
    assert a == pytest.approx(b, rel=1e-13)
    wrong_sense = spread(F * flip, R * flip, maximised=False)  # picks another z4 extreme
    assert abs(wrong_sense - a) > 1e-3


def test_spread_bad_inputs() -> None:
    F = line_front([0.0, 0.5, 1.0])
    with pytest.raises(InputShapeError):
        spread(F[:1], maximised=False)
    with pytest.raises(InputShapeError):
        spread(np.ones((4, 3)), maximised=False, method="deb")
    with pytest.raises(InvalidInputError):
        spread(F, maximised=False, method="zhou")  # type: ignore[arg-type]
    with pytest.raises(InputShapeError):
        spread(F, np.ones((2, 3)), maximised=False)
    with pytest.raises(InvalidInputError):
        spread([[0.0, np.nan], [1.0, 0.0]], maximised=False)


def test_spread_collapsed_front_is_one() -> None:
    assert spread(np.ones((3, 2)), maximised=False) == 1.0
    assert spread(np.ones((3, 4)), maximised=False) == 1.0
    # the limit of Deb's formula when the extremes lie elsewhere
    assert spread(np.ones((3, 2)), [[0.0, 2.0], [2.0, 0.0]], maximised=False) == 1.0


def test_spread_duplicates_count_as_clustering() -> None:
    F = line_front(np.linspace(0.0, 1.0, 6))
    doubled = np.vstack([F, F[2:3]])
    assert spread(doubled, maximised=False, method="generalized") > 0.1
    assert spread(doubled, maximised=False, method="deb") > 0.1


# ================================================================= OO, AE
def test_optimizer_overhead_hand_values() -> None:
    assert optimizer_overhead(10.0, 9.2) == pytest.approx(0.08)
    assert optimizer_overhead(2.0, 0.0) == 1.0
    assert optimizer_overhead(5.0, 5.0) == 0.0


@pytest.mark.parametrize(
    ("total", "evaluation", "error"),
    [
        (-1.0, 0.0, InvalidInputError),
        (1.0, -0.1, InvalidInputError),
        (1.0, 1.5, ConfigurationError),
        (0.0, 0.0, InvalidInputError),
        (np.nan, 0.0, InvalidInputError),
        ([1.0, 2.0], 0.5, InputShapeError),
    ],
)
def test_optimizer_overhead_bad_inputs(
    total: float, evaluation: float, error: type[Exception]
) -> None:
    with pytest.raises(error):
        optimizer_overhead(total, evaluation)


def test_algorithm_effort_hand_values() -> None:
    assert round(algorithm_effort(2.0, 87), 5) == 0.02299  # paper Table 4, NSGA-II
    assert algorithm_effort(3.0, 6) == 0.5
    assert algorithm_effort(3.0, np.int64(6)) == 0.5


@pytest.mark.parametrize(
    ("total", "n", "error"),
    [
        (1.0, 0, InvalidInputError),
        (1.0, -3, InvalidInputError),
        (1.0, 2.5, InvalidInputError),
        (1.0, True, InvalidInputError),
        (-1.0, 10, InvalidInputError),
        (np.inf, 10, InvalidInputError),
    ],
)
def test_algorithm_effort_bad_inputs(total: float, n: object, error: type[Exception]) -> None:
    with pytest.raises(error):
        algorithm_effort(total, n)  # type: ignore[arg-type]


def test_hypervolume_methods_agree_and_wfg_is_deprecated() -> None:
    rng = np.random.default_rng(44)
    P = rng.uniform(size=(60, 5))
    ref = np.full(5, 1.1)
    with pytest.warns(DeprecationWarning, match="wfg"):
        wfg = hypervolume(P, ref, maximised=False, method="wfg")
    fast = hypervolume(P, ref, maximised=False, method="moocore")
    auto = hypervolume(P, ref, maximised=False)
    assert wfg == auto == fast == pytest.approx(wfg_hypervolume(P, ref), rel=1e-12)
    with pytest.raises(InvalidInputError, match="method"):
        hypervolume(P, ref, maximised=False, method="grid")  # type: ignore[arg-type]
