"""BlockedDuplicateElimination takes pymoo's DefaultDuplicateElimination's decisions (pymoo's
class is the independent reference) with a memory bounded whatever the population size."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from pymoo.core.duplicate import DefaultDuplicateElimination
from pymoo.core.population import Population

import adept_traj as at
from adept_traj.errors import ConfigurationError
from adept_traj.optimise import ALGORITHMS, BlockedDuplicateElimination, make_algorithm
from adept_traj.optimise.search import algorithms as algorithms_module


def _population_with_duplicates(rng: np.random.Generator, n: int, n_var: int) -> np.ndarray:
    """Random rows with planted exact copies, copies one ulp away (distance < 1e-16), copies
    just outside pymoo's epsilon, rows holding NaN, and chains of copies."""
    X = rng.uniform(0.0, 1.0, (n, n_var))
    for _ in range(n // 5):
        i, j = rng.integers(0, n, 2)
        X[j] = X[i]  # exact copy
    for _ in range(n // 5):
        i, j = rng.integers(0, n, 2)
        X[j] = X[i]
        k = rng.integers(0, n_var)
        X[j, k] = np.nextafter(X[i, k], 2.0)  # one ulp: distance ≤ 1.1e-16 (within 1e-16 or not)
    for _ in range(n // 10):
        i, j = rng.integers(0, n, 2)
        X[j] = X[i] + 1e-15  # close, but outside epsilon
    X[rng.integers(0, n, max(1, n // 20)), rng.integers(0, n_var)] = np.nan
    return X


def _marks(elimination, X: np.ndarray, *others: np.ndarray) -> tuple[list[int], list[int]]:
    pop = Population.new(X=X)
    _, kept, removed = elimination.do(
        pop, *(Population.new(X=o) for o in others), return_indices=True
    )
    return list(kept), list(removed)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("block_pairs", [1, 7, 500, 2**21])
def test_same_decisions_as_pymoo_within_the_population(seed: int, block_pairs: int) -> None:
    rng = np.random.default_rng(seed)
    X = _population_with_duplicates(rng, 120, 5)
    reference = _marks(DefaultDuplicateElimination(), X)
    assert len(reference[1]) > 10  # the planted duplicates are there
    assert _marks(BlockedDuplicateElimination(block_pairs=block_pairs), X) == reference


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("block_pairs", [1, 33, 2**21])
def test_same_decisions_as_pymoo_against_other_populations(seed: int, block_pairs: int) -> None:
    rng = np.random.default_rng(100 + seed)
    X = _population_with_duplicates(rng, 90, 4)
    others = [X[rng.permutation(90)[:30]].copy(), rng.uniform(0, 1, (40, 4)), np.empty((0, 4))]
    others[1][:10] = X[-10:]
    reference = _marks(DefaultDuplicateElimination(), X, *others)
    blocked = _marks(BlockedDuplicateElimination(block_pairs=block_pairs), X, *others)
    assert blocked == reference


def test_epsilon_is_pymoos() -> None:
    X = np.array([[0.0, 0.0], [0.0, 1e-16], [0.0, 2e-16]])
    # 1e-16 is within the epsilon; 2e-16 is 1e-16 from the second row, so also within.
    assert _marks(BlockedDuplicateElimination(), X) == ([0], [1, 2])
    assert _marks(BlockedDuplicateElimination(epsilon=0.0), X) == ([0, 1, 2], [])


def test_bad_settings_name_the_value() -> None:
    with pytest.raises(ConfigurationError, match="block_pairs"):
        BlockedDuplicateElimination(block_pairs=0)
    with pytest.raises(ConfigurationError, match="epsilon"):
        BlockedDuplicateElimination(epsilon=-1.0)


def test_memory_is_bounded_by_the_block() -> None:
    X = np.random.default_rng(3).uniform(0.0, 1.0, (4000, 20))
    X[2000:2100] = X[:100]
    pop = Population.new(X=X)
    tracemalloc.start()
    try:
        kept = BlockedDuplicateElimination().do(pop)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert len(kept) == 3900
    # pymoo's: a (4000, 4000) float matrix and its triangle's indices, ≈ 280 MB.
    assert peak < 40 * 2**20


@pytest.mark.parametrize("name", ALGORITHMS)
def test_every_algorithm_eliminates_duplicates_in_blocks(name: str) -> None:
    algorithm, _ = make_algorithm(name, pop_size=60, n_gen=1)
    assert type(algorithm.eliminate_duplicates) is BlockedDuplicateElimination
    assert algorithm.initialization.eliminate_duplicates is algorithm.eliminate_duplicates


# NSGA-II's offspring are often copies of a parent (no crossover, no mutated variable);
# MODE eliminates duplicates in its initial population only.
@pytest.mark.parametrize(("name", "least_removed"), [("nsga2", 1), ("mode", 0)])
def test_a_seeded_run_gives_the_front_of_pymoos_elimination(
    problem: at.TrajectoryProblem, name: str, least_removed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    removed: list[int] = []

    class Counting(BlockedDuplicateElimination):
        # Every decision goes through ``duplicates`` (pymoo's ``_do`` hook and the array
        # mating of NSGA-II alike).
        def duplicates(self, X, Y=None):
            out = super().duplicates(X, Y)
            removed.append(int(out.sum()))
            return out

    monkeypatch.setattr(algorithms_module, "BlockedDuplicateElimination", Counting)
    blocked = at.plan(problem, name, seed=4, pop_size=16, n_gen=4)
    assert removed  # the run called the blocked elimination
    assert sum(removed) >= least_removed
    monkeypatch.setattr(
        algorithms_module, "BlockedDuplicateElimination", DefaultDuplicateElimination
    )
    reference = at.plan(problem, name, seed=4, pop_size=16, n_gen=4)
    np.testing.assert_array_equal(blocked.front.x, reference.front.x)
    np.testing.assert_array_equal(blocked.front.objectives, reference.front.objectives)
    assert blocked.timing.n_evaluations == reference.timing.n_evaluations
