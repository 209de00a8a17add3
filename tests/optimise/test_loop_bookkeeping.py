"""Issue #15, the optimiser's own time: the bookkeeping done on arrays or later gives what
pymoo's per-member bookkeeping gives — the evaluator's members (pymoo's ``Evaluator`` and
the lazy CV as the reference), a captured checkpoint's arrays (those made at the time of
capture, after later generations rewrote the members' data), the duplicate decisions when
many rows share a sum (pymoo's elimination as the reference)."""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.core.duplicate import DefaultDuplicateElimination
from pymoo.core.evaluator import Evaluator
from pymoo.core.population import Population
from pymoo.core.problem import Problem

from adept_traj.optimise import (
    ArrayEvaluator,
    BlockedDuplicateElimination,
    capture_checkpoint,
    checkpoint_arrays,
    make_algorithm,
)


class Toy(Problem):
    """Three objectives and four constraints (about half of the box feasible) over [0, 1]^5."""

    def __init__(self) -> None:
        super().__init__(n_var=5, n_obj=3, n_ieq_constr=4, xl=0.0, xu=1.0)

    def _evaluate(self, x, out, *args, **kwargs) -> None:
        out["F"] = np.column_stack([x[:, 0], 1.0 - x[:, 0] ** 0.5 + x[:, 1], x[:, 2:].sum(axis=1)])
        out["G"] = np.column_stack(
            [x[:, 1] + x[:, 2] - 0.8, x[:, 3] - 0.9, -x[:, 4], x[:, 0] - x[:, 4]]
        )


def _member_state(pop: Population) -> list[dict[str, object]]:
    """Every attribute of every member, arrays as (dtype, shape, bytes, owns its data)."""
    out = []
    for ind in pop:
        state: dict[str, object] = {}
        for key, value in vars(ind).items():
            if isinstance(value, np.ndarray):
                state[key] = (value.dtype, value.shape, value.tobytes(), value.flags["OWNDATA"])
            else:
                state[key] = value
        out.append(state)
    return out


@pytest.mark.parametrize("seed", [0, 1])
def test_the_array_evaluator_sets_what_pymoo_and_the_lazy_cv_set(seed: int) -> None:
    X = np.random.default_rng(seed).uniform(size=(40, 5))
    ours, theirs = Population.new(X=X), Population.new(X=X)
    evaluator, reference = ArrayEvaluator(), Evaluator()
    evaluator.eval(Toy(), ours)
    reference.eval(Toy(), theirs)
    for ind in theirs:
        ind.CV  # noqa: B018  (pymoo computes and caches it on this first read)
    assert _member_state(ours) == _member_state(theirs)
    assert evaluator.n_eval == reference.n_eval == 40
    evaluator.eval(Toy(), ours)  # evaluated members are skipped, as by pymoo
    assert evaluator.n_eval == 40


def test_a_captured_checkpoint_is_the_one_made_at_capture() -> None:
    problem = Toy()
    algorithm, _ = make_algorithm(
        "nsga2",
        pop_size=12,
        sampling=np.random.default_rng(3).uniform(size=(12, 5)),
        repair=False,
        fast_end=0,
    )
    algorithm.setup(problem, seed=5, termination=("n_gen", 6), verbose=False)

    def generation() -> None:
        infills = algorithm.ask()
        algorithm.evaluator.eval(problem, infills, algorithm=algorithm)
        algorithm.tell(infills=infills)

    for _ in range(2):
        generation()
    meta = {"fingerprint": {"a": 1}, "history": [{"generation": 2}]}
    expected = checkpoint_arrays(algorithm, meta, {"fronts": np.ones((2, 3))})
    captured = capture_checkpoint(algorithm)
    for _ in range(3):  # the survivors' rank and crowding are rewritten meanwhile
        generation()
    got = captured.arrays(meta, {"fronts": np.ones((2, 3))})
    assert sorted(got) == sorted(expected)
    for key, value in expected.items():
        assert got[key].dtype == value.dtype, key
        assert got[key].tobytes() == value.tobytes(), key
    assert "data.rank" in got


@pytest.mark.parametrize("block_pairs", [1, 13, 2**21])
def test_rows_sharing_a_sum_get_pymoos_decisions(block_pairs: int) -> None:
    rng = np.random.default_rng(7)
    base = rng.uniform(size=(6, 4))
    # Permutations of a row share its sum (to the rounding): many candidates per row.
    X = np.concatenate([row[rng.permutation(4)][None] for row in base for _ in range(6)])
    X[30:] = X[3:9]  # and exact copies
    pop = Population.new(X=X)
    reference = DefaultDuplicateElimination().do(pop, return_indices=True)
    ours = BlockedDuplicateElimination(block_pairs=block_pairs).do(pop, return_indices=True)
    assert [list(a) for a in ours] == [list(a) for a in reference]
    assert len(reference[2]) > 0


def test_the_nsga2_of_make_algorithm_runs_as_pymoos_nsga2() -> None:
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.operators.crossover.sbx import SBX
    from pymoo.operators.mutation.pm import PM
    from pymoo.operators.selection.tournament import TournamentSelection

    from adept_traj.optimise import ArrayMating, RankAndCrowdingSurvival, binary_tournament

    start = np.random.default_rng(2).uniform(size=(16, 5))
    ours, _ = make_algorithm("nsga2", pop_size=16, sampling=start, repair=False, fast_end=0)
    theirs = NSGA2(
        pop_size=16,
        sampling=start,
        selection=TournamentSelection(func_comp=binary_tournament),
        crossover=SBX(prob=0.7, eta=10.0),
        mutation=PM(prob=1.0, prob_var=0.01, eta=100.0),
        survival=RankAndCrowdingSurvival(),
        eliminate_duplicates=BlockedDuplicateElimination(),
        evaluator=ArrayEvaluator(),
    )
    theirs.mating = ArrayMating.of(theirs.mating)
    runs = []
    for algorithm in (ours, theirs):
        problem = Toy()
        algorithm.setup(problem, seed=11, termination=("n_gen", 8), verbose=False)
        opts = []
        while algorithm.has_next():
            infills = algorithm.ask()
            algorithm.evaluator.eval(problem, infills, algorithm=algorithm)
            algorithm.tell(infills=infills)
            opts.append(algorithm.opt.get("X").tobytes())
        runs.append((algorithm.pop.get("X").tobytes(), algorithm.pop.get("F").tobytes(), opts))
        assert algorithm.tournament_type == "comp_by_dom_and_crowding"
    assert runs[0] == runs[1]
    assert type(ours.termination) is type(theirs.termination)


def test_duplicates_of_rows_whose_sums_are_not_finite_match_pymoo() -> None:
    """Rows whose sum overflows (or holds inf or NaN) are compared with every row: the
    decisions are pymoo's, and no numpy warning is raised."""
    big, inf, nan = 1e308, np.inf, np.nan
    X = np.array([[big, big], [big, big], [0, 1], [inf, 1], [inf, 1], [nan, 0], [0, 1.0]])
    with np.errstate(all="ignore"):
        expected = DefaultDuplicateElimination()._do(
            Population.new(X=X), None, np.zeros(len(X), dtype=bool)
        )
    with np.errstate(all="raise"):
        ours = BlockedDuplicateElimination().duplicates(X)
    np.testing.assert_array_equal(ours, expected)
    assert ours.tolist() == [False, True, False, False, False, False, True]
