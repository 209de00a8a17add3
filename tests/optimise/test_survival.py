"""RankAndCrowdingSurvival takes pymoo's RankAndCrowding decisions (same survivors in the
same order, same rank and crowding data, same random draws), and population_values stacks
a population's attributes as Population.get does."""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.operators.survival.rank_and_crowding import RankAndCrowding

from adept_traj.optimise import RankAndCrowdingSurvival, population_values


def _population(seed: int, n: int, share_feasible: float) -> Population:
    """n members, 3 objectives on a coarse grid (ties and duplicates), CV 0 for about
    ``share_feasible`` of them, else one of a few values (ties in CV too)."""
    rng = np.random.default_rng(seed)
    F = rng.integers(0, 6, size=(n, 3)).astype(float)
    cv = np.where(rng.uniform(size=n) < share_feasible, 0.0, rng.choice([0.5, 1.0, 2.5], n))
    G = np.column_stack([cv, -np.ones(n)])
    return Population.new(X=rng.uniform(size=(n, 2)), F=F, G=G, CV=cv[:, None])


CASES = [(seed, n, share) for seed in (1, 2) for n in (7, 60) for share in (0.0, 0.4, 1.0)]


@pytest.mark.parametrize(("seed", "n", "share"), CASES)
@pytest.mark.parametrize("return_indices", [False, True])
def test_same_survivors_data_and_draws_as_pymoo(
    seed: int, n: int, share: float, return_indices: bool
) -> None:
    problem = Problem(n_var=2, n_obj=3, n_ieq_constr=2, xl=0.0, xu=1.0)
    out = {}
    for name, survival in (("pymoo", RankAndCrowding()), ("ours", RankAndCrowdingSurvival())):
        pop, rng = _population(seed, n, share), np.random.default_rng(seed)
        chosen = survival.do(
            problem, pop, n_survive=n // 2, random_state=rng, return_indices=return_indices
        )
        index = chosen if return_indices else [int(np.flatnonzero(pop == s)[0]) for s in chosen]
        data = [(ind.data.get("rank"), ind.data.get("crowding")) for ind in pop]
        out[name] = (index, data, rng.uniform())
    assert len(out["ours"][0]) == n // 2
    assert out["ours"][0] == out["pymoo"][0]
    assert out["ours"][1] == out["pymoo"][1]  # rank and crowding, exactly
    assert out["ours"][2] == out["pymoo"][2]  # the generator is left in the same state


def test_all_members_survive_by_default_and_an_empty_population_is_returned() -> None:
    problem = Problem(n_var=2, n_obj=3, n_ieq_constr=2, xl=0.0, xu=1.0)
    pop = _population(3, 9, 0.5)
    assert (
        len(RankAndCrowdingSurvival().do(problem, pop, random_state=np.random.default_rng(0))) == 9
    )
    assert len(RankAndCrowdingSurvival().do(problem, Population())) == 0


@pytest.mark.parametrize("key", ["X", "F", "G", "CV"])
def test_population_values_equal_pymoo_get(key: str) -> None:
    pop = _population(4, 11, 0.5)
    ours, theirs = population_values(pop, key), pop.get(key)
    assert ours.dtype == theirs.dtype
    np.testing.assert_array_equal(ours, theirs)
    assert population_values(Population(), key).shape == Population().get(key).shape
