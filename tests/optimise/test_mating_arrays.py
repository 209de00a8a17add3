"""NSGA-II's mating and binary tournament and MODE's DE variation on arrays make pymoo's
offspring and winners (pymoo's Mating, binary_tournament and Variant are the references),
bit for bit, with the same draws from the algorithm's generator."""

from __future__ import annotations

import copy
from types import SimpleNamespace

import numpy as np
import pytest
from pymoo.algorithms.moo.nsga2 import binary_tournament as pymoo_binary_tournament
from pymoo.algorithms.soo.nonconvex.de import Variant
from pymoo.core.mating import Mating
from pymoo.core.population import Population
from pymoo.operators.control import NoParameterControl

from adept_traj.errors import ConfigurationError
from adept_traj.optimise import (
    ArrayMating,
    ArrayVariant,
    binary_tournament,
    make_algorithm,
    optimise,
    population_values,
)


@pytest.fixture(scope="module")
def evolved(problem):
    """NSGA-II (paper operators, no fast-end search) after 3 generations of 16."""
    algorithm, _ = make_algorithm("nsga2", pop_size=16, n_gen=3, fast_end=0.0)
    optimise(problem, algorithm, 3, seed=5)
    return algorithm


def _offspring(mating, problem, algorithm, state, **kwargs) -> tuple[np.ndarray, float]:
    rng = algorithm.random_state
    rng.bit_generator.state = copy.deepcopy(state)
    off = mating.do(problem, algorithm.pop, 16, random_state=rng, algorithm=algorithm, **kwargs)
    return population_values(off, "X"), rng.random()


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
@pytest.mark.parametrize("rounds", [None, 1])
def test_array_mating_makes_pymoos_offspring(problem, evolved, seed: int, rounds) -> None:
    ours = evolved.mating
    assert isinstance(ours, ArrayMating)
    reference = Mating(
        ours.selection,
        ours.crossover,
        ours.mutation,
        repair=ours.repair,
        eliminate_duplicates=ours.eliminate_duplicates,
        n_max_iterations=ours.n_max_iterations,
    )
    state = np.random.default_rng(seed).bit_generator.state
    kwargs = {} if rounds is None else {"n_max_iterations": rounds}
    X, after = _offspring(ours, problem, evolved, state, **kwargs)
    X_ref, after_ref = _offspring(reference, problem, evolved, state, **kwargs)
    assert X.shape == X_ref.shape
    assert np.array_equal(X.view(np.int64), X_ref.view(np.int64))
    assert after == after_ref  # the generator is left in the same state


def test_without_a_generator_or_with_other_operators_it_is_pymoos_mating(problem, evolved):
    ours = ArrayMating.of(evolved.mating)
    assert ours._plain()
    ours.mutation = copy.copy(ours.mutation)
    ours.mutation.vtype = float  # an operator-level cast: pymoo's path
    assert not ours._plain()
    state = np.random.default_rng(9).bit_generator.state
    X, after = _offspring(ours, problem, evolved, state)
    X_ref, after_ref = _offspring(evolved.mating, problem, evolved, state)
    assert np.array_equal(X, X_ref)
    assert after == after_ref


def _ranked(seed: int, n: int) -> Population:
    """Members with ties everywhere: equal CVs, equal and infinite crowding distances,
    duplicate objective vectors, a NaN objective."""
    rng = np.random.default_rng(seed)
    cv = np.where(rng.uniform(size=n) < 0.5, 0.0, rng.choice([0.5, 2.0], n))
    F = rng.integers(0, 3, size=(n, 3)).astype(float)
    F[0, 1] = np.nan
    pop = Population.new(X=rng.uniform(size=(n, 2)), F=F, CV=cv[:, None])
    crowding = rng.choice([0.1, 0.7, np.inf], n)
    for ind, r, c in zip(pop, rng.integers(0, 3, n), crowding, strict=True):
        ind.set("rank", int(r))
        ind.set("crowding", float(c))
    return pop


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("kind", ["comp_by_dom_and_crowding", "comp_by_rank_and_crowding"])
def test_binary_tournament_picks_pymoos_winners(seed: int, kind: str) -> None:
    pop = _ranked(seed, 30)
    P = np.random.default_rng(seed + 10).integers(0, 30, size=(200, 2))
    out = {}
    for name, func in (("ours", binary_tournament), ("pymoo", pymoo_binary_tournament)):
        algorithm = SimpleNamespace(tournament_type=kind, random_state=np.random.default_rng(4))
        out[name] = (func(pop, P, algorithm), algorithm.random_state.random())
    assert out["ours"][0].shape == (200, 1)
    assert np.array_equal(out["ours"][0], out["pymoo"][0])
    assert out["ours"][1] == out["pymoo"][1]


def test_binary_tournament_refuses_bad_input() -> None:
    pop = _ranked(0, 5)
    algorithm = SimpleNamespace(tournament_type="comp_by_dom_and_crowding", random_state=None)
    with pytest.raises(ConfigurationError, match="shape"):
        binary_tournament(pop, np.zeros((4, 3), dtype=int), algorithm)
    algorithm.tournament_type = "by_luck"
    with pytest.raises(ConfigurationError, match="by_luck"):
        binary_tournament(pop, np.zeros((4, 2), dtype=int), algorithm)


@pytest.fixture(scope="module")
def evolved_mode(problem):
    """MODE (paper operators, no fast-end search) after 2 generations of 12."""
    algorithm, _ = make_algorithm("mode", pop_size=12, n_gen=2, fast_end=0.0)
    optimise(problem, algorithm, 2, seed=6)
    return algorithm


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize(("crossover", "prob_mut"), [("bin", 0.0), ("bin", 0.5), ("exp", 0.0)])
def test_array_variant_makes_pymoos_trial_vectors(
    problem, evolved_mode, seed: int, crossover: str, prob_mut: float
) -> None:
    ours = evolved_mode.mating
    assert isinstance(ours, ArrayVariant)
    settings = {
        "selection": "rand",
        "n_diffs": 1,
        "F": 0.5,
        "crossover": crossover,
        "CR": 0.9,
        "prob_mut": prob_mut,
        "control": NoParameterControl,
        "repair": ours.repair,
    }
    state = np.random.default_rng(seed).bit_generator.state
    out = {}
    for name, variant in (("ours", ArrayVariant(**settings)), ("pymoo", Variant(**settings))):
        rng = evolved_mode.random_state
        rng.bit_generator.state = copy.deepcopy(state)
        off = variant.do(problem, evolved_mode.pop, 12, algorithm=evolved_mode, random_state=rng)
        out[name] = (population_values(off, "X"), rng.random())
    assert np.array_equal(out["ours"][0].view(np.int64), out["pymoo"][0].view(np.int64))
    assert out["ours"][1] == out["pymoo"][1]
