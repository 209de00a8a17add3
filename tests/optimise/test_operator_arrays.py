"""The optimiser's operators and bookkeeping on arrays give the same numbers, bit for bit, as
their plain per-member or full-table formulations (kept here as independent references)
and as pymoo's own functions: the kinematic time repair, the ramps' S-curves, the cached
constraint violations and the stored optimum (issue #15: same seed, same front)."""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.core.individual import Individual
from pymoo.core.population import Population
from pymoo.util.optimum import filter_optimum

from adept_traj.optimise import (
    RampSampling,
    cache_violations,
    kinematic_time,
    make_algorithm,
    optimum,
    population_values,
)
from adept_traj.optimise.search.sampling import _s_curve
from adept_traj.problem import derivative_abs_max


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def _candidates(problem, seed: int) -> np.ndarray:
    """Ramps (smooth, near the feasible region) and uniform random decision vectors."""
    rng = np.random.default_rng(seed)
    ramps = RampSampling().ramps(problem, 40, rng)
    uniform = rng.uniform(problem.xl, problem.xu, size=(40, problem.n_var))
    straight = problem.trajectory.straight_line(1.5)[None]  # zero velocity, c3 = 0 spans
    return np.concatenate([ramps, uniform, straight])


@pytest.mark.parametrize("seed", [0, 1])
def test_derivative_extrema_are_those_of_the_full_bounds(problem, seed: int) -> None:
    x = _candidates(problem, seed)
    qd, qdd, qddd = derivative_abs_max(problem.trajectory, x)
    b = problem.trajectory.bounds(x)
    assert _same_bits(qd, b.qd_abs_max)
    assert _same_bits(qdd, b.qdd_abs_max)
    assert _same_bits(qddd, b.qddd_abs_max)


@pytest.mark.parametrize("seed", [0, 1])
def test_kinematic_time_equals_the_per_candidate_formula(problem, seed: int) -> None:
    """Reference: each candidate alone, from the full bounds at T = 1, limit by limit."""
    x = _candidates(problem, seed)
    lim = problem.robot.limits
    reference = []
    for row in x:
        unit = row.copy()
        unit[0] = 1.0
        b = problem.trajectory.bounds(unit)
        times = [
            b.qd_abs_max / lim.velocity,
            np.sqrt(b.qdd_abs_max / lim.acceleration),
            np.cbrt(b.qddd_abs_max / lim.jerk),
        ]
        reference.append(max(float(np.max(t)) for t in times))
    assert _same_bits(kinematic_time(problem, x), reference)


def _s_curve_reference(u: np.ndarray, r: float) -> np.ndarray:
    """The S-curve of one joint, tabulated and normalised on the whole grid, then read."""
    g = np.linspace(0.0, 1.0, 2001)
    half = np.minimum(g, 1.0 - g)
    acc = np.minimum(np.clip(half / r, 0.0, 1.0), np.clip((0.5 - half) / r, 0.0, 1.0))
    acc = np.where(g < 0.5, acc, -acc)
    pos = np.cumsum(np.cumsum(acc))
    pos = (pos - pos[0]) / (pos[-1] - pos[0])
    uu = np.clip(u, 0.0, 1.0)
    idx = np.minimum((uu * 2000).astype(int), 1999)
    w = uu * 2000 - idx
    return pos[idx] * (1 - w) + pos[idx + 1] * w


def test_s_curves_equal_the_per_curve_table() -> None:
    rng = np.random.default_rng(7)
    r = rng.uniform(0.05, 0.25, size=(6, 4))
    u = rng.uniform(-0.2, 1.2, size=(6, 4, 15))  # outside [0, 1] too (clipped)
    u[0, 0, :3] = [0.0, 1.0, 0.5]
    got = _s_curve(u, r)
    for i in range(6):
        for j in range(4):
            assert _same_bits(got[i, j], _s_curve_reference(u[i, j], r[i, j]))


def _evaluated(seed: int, n: int, share_feasible: float, n_obj: int = 3) -> Population:
    """n members as pymoo's evaluator leaves them: X, F, G set; CV not yet computed."""
    rng = np.random.default_rng(seed)
    G = rng.normal(0.0, 1.0, size=(n, 21)) * 10.0 ** rng.integers(-12, 3, size=(n, 21))
    G[rng.uniform(size=n) < share_feasible] = -np.abs(G[0])  # feasible rows
    G[1, :3] = 0.0  # on the boundary
    F = rng.integers(0, 5, size=(n, n_obj)).astype(float)  # ties and duplicates
    pop = Population.new(X=rng.uniform(size=(n, 4)))
    pop.set("F", F)
    pop.set("G", G)
    return pop


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_cached_violations_equal_pymoos_lazy_ones(seed: int) -> None:
    ours, pymoos = _evaluated(seed, 60, 0.3), _evaluated(seed, 60, 0.3)
    cache_violations(ours)
    assert _same_bits(population_values(ours, "CV"), population_values(pymoos, "CV"))


def test_members_of_another_configuration_are_left_to_pymoo() -> None:
    def population() -> Population:
        pop = _evaluated(3, 10, 0.5)
        pop[2].G = np.ones(21)
        pop[2].config["cv_ieq"]["eps"] = 0.5  # a member of its own configuration
        pop[4].H = np.array([0.3])  # and one with an equality constraint
        return pop

    pop = population()
    cache_violations(pop)
    cv = population_values(pop, "CV")
    assert _same_bits(cv, population_values(population(), "CV"))
    assert cv[2, 0] == 21 * 0.5
    assert cv[4, 0] > 0.0


@pytest.mark.parametrize(
    ("seed", "share", "n_obj"), [(0, 0.0, 3), (1, 0.5, 3), (2, 1.0, 3), (3, 0.6, 1)]
)
def test_optimum_is_pymoos_filter_optimum(seed: int, share: float, n_obj: int) -> None:
    pop = _evaluated(seed, 40, share, n_obj)
    expected = filter_optimum(pop, least_infeasible=True)
    got = optimum(pop)
    assert [id(ind) for ind in got] == [id(ind) for ind in expected]
    assert optimum(Population()) is None
    assert optimum(None) is None


def test_a_single_optimum_is_a_population() -> None:
    pop = _evaluated(4, 5, 0.0)
    assert isinstance(optimum(pop), Population)
    assert len(optimum(pop)) == 1
    assert isinstance(optimum(pop)[0], Individual)


def test_mode_stores_pymoos_optimum(problem) -> None:
    """After a generation MODE's ``opt`` is pymoo's filter of its population."""
    algorithm, _ = make_algorithm("mode", pop_size=12, n_gen=2)
    algorithm.setup(problem, seed=4, termination=("n_gen", 2), verbose=False)
    for _ in range(2):
        infills = algorithm.ask()
        algorithm.evaluator.eval(problem, infills, algorithm=algorithm)
        algorithm.tell(infills=infills)
    expected = filter_optimum(algorithm.pop, least_infeasible=True)
    assert [id(ind) for ind in algorithm.opt] == [id(ind) for ind in expected]
