"""FastEndSearch: local perturbations of the fastest feasible members inside a mating."""

from __future__ import annotations

import numpy as np
import pytest
from pymoo.core.evaluator import Evaluator
from pymoo.core.population import Population

from adept_traj import TrajectoryProblem
from adept_traj.errors import ConfigurationError
from adept_traj.optimise import FastEndSearch, kinematic_time, make_algorithm
from adept_traj.testing.paper_moves import lift_then_lower


class Recorder:
    """A stand-in mating that returns copies of the first members and records the call."""

    def __init__(self) -> None:
        self.asked: list[int] = []
        self.repair = "the wrapped mating's repair"

    def do(self, problem, pop, n_offsprings, **kwargs):
        self.asked.append(n_offsprings)
        return Population.new(X=pop.get("X")[:n_offsprings].copy())


def evaluated_population(problem: TrajectoryProblem, x: np.ndarray) -> Population:
    ev = problem.evaluate_batch(x)
    pop = Population.new(X=x)
    cv = np.maximum(ev.constraints, 0.0).sum(axis=1, keepdims=True)
    pop.set("CV", cv)
    return pop


def test_children_perturb_the_fastest_feasible_members(problem: TrajectoryProblem) -> None:
    x0 = lift_then_lower(problem)
    rng = np.random.default_rng(0)
    others = problem.xl + (problem.xu - problem.xl) * rng.uniform(size=(9, problem.n_var))
    pop = evaluated_population(problem, np.vstack([x0, others]))
    feasible = pop.get("CV")[:, 0] <= 0
    assert feasible[0]
    assert not feasible[1:].any()  # random moves collide or break limits
    mating = Recorder()
    search = FastEndSearch(mating, fraction=0.3, n_elite=1, immigrants=0.0)
    off = search.do(problem, pop, 10, random_state=np.random.default_rng(1))
    assert len(off) == 10  # same number of offspring: 7 of the mating's 10 kept, 3 local
    assert mating.asked == [10]
    assert search.repair == "the wrapped mating's repair"  # attributes pass through
    children = off.get("X")[7:]
    # the travel time is each child's own kinematic minimum
    np.testing.assert_allclose(children[:, 0], kinematic_time(problem, children), rtol=1e-8)
    # small, smooth changes of the only feasible member's control points
    change = np.abs(children[:, 1:] - x0[1:])
    assert change.max() > 0
    assert change.max() < 0.01 * 4 * np.max(problem.robot.limits.upper - problem.robot.limits.lower)
    _, P = problem.trajectory.decode(children)
    np.testing.assert_array_equal(P[:, :3], np.broadcast_to(problem.start, (3, 3, 4)))
    np.testing.assert_array_equal(P[:, -3:], np.broadcast_to(problem.goal, (3, 3, 4)))
    # smooth: no child is much slower than its parent's shape allows (a rough one would be)
    assert np.all(children[:, 0] < 1.5 * kinematic_time(problem, x0[None])[0])


def test_no_feasible_member_means_no_perturbation(problem: TrajectoryProblem) -> None:
    rng = np.random.default_rng(2)
    x = problem.xl + (problem.xu - problem.xl) * rng.uniform(size=(6, problem.n_var))
    pop = evaluated_population(problem, x)
    assert not (pop.get("CV")[:, 0] <= 0).any()
    mating = Recorder()
    off = FastEndSearch(mating, fraction=0.5, immigrants=0.0).do(problem, pop, 6, random_state=rng)
    assert mating.asked == [6]
    np.testing.assert_array_equal(off.get("X"), x)
    # with immigrants: a third of the 3 local children (1) is a fresh ramp, the rest the
    # mating's own (nothing to perturb)
    off = FastEndSearch(Recorder(), fraction=0.5).do(problem, pop, 6, random_state=rng)
    X = off.get("X")
    assert len(X) == 6
    mating_children = [i for i in range(6) if any(np.array_equal(X[i], xi) for xi in x)]
    assert len(mating_children) == 5


def test_immigrants_are_fresh_ramps_at_their_kinematic_minimum(
    problem: TrajectoryProblem,
) -> None:
    x0 = lift_then_lower(problem)
    pop = evaluated_population(problem, x0[None])
    assert pop.get("CV")[0, 0] <= 0
    search = FastEndSearch(Recorder(), fraction=1.0, immigrants=1.0)
    rng = np.random.default_rng(4)
    off = search.do(problem, Population.merge(*[pop] * 8), 8, random_state=rng)
    X = off.get("X")
    assert len(X) == 8
    expected = np.clip(kinematic_time(problem, X), problem.xl[0], problem.xu[0])
    np.testing.assert_allclose(X[:, 0], expected, rtol=1e-8)  # T_max caps slow shapes
    _, P = problem.trajectory.decode(X)
    np.testing.assert_array_equal(P[:, :3], np.broadcast_to(problem.start, (8, 3, 4)))
    np.testing.assert_array_equal(P[:, -3:], np.broadcast_to(problem.goal, (8, 3, 4)))
    # not perturbations of the elite (at most a few σ_hi = 1 % of a range): fresh ramps
    span = problem.xu[1:] - problem.xl[1:]
    assert np.all((np.abs(X[:, 1:] - x0[1:]) / span).max(axis=1) > 0.05)
    assert len(np.unique(X, axis=0)) == 8
    # ramps are monotone between start and goal unless a detour was drawn: most are
    d = np.diff(P, axis=1) * np.sign(problem.goal - problem.start)
    assert np.mean(np.all(d >= -1e-12, axis=(1, 2))) > 0.2


def test_same_generator_same_children(problem: TrajectoryProblem) -> None:
    pop = evaluated_population(problem, np.repeat(lift_then_lower(problem)[None], 4, axis=0))
    a, b = (
        FastEndSearch(Recorder(), fraction=1.0)
        .do(problem, pop, 4, random_state=np.random.default_rng(5))
        .get("X")
        for _ in range(2)
    )
    np.testing.assert_array_equal(a, b)


def test_settings_and_validation() -> None:
    alg, settings = make_algorithm("nsga2")
    assert isinstance(alg.mating, FastEndSearch)
    assert settings.params["fast_end"] == 0.3
    plain, settings = make_algorithm("nsga2", fast_end=0)
    assert not isinstance(plain.mating, FastEndSearch)
    assert settings.params["fast_end"] == 0.0
    for bad in (-0.1, 1.5, True, "x"):
        with pytest.raises(ConfigurationError, match="fast_end"):
            make_algorithm("mode", fast_end=bad)
    with pytest.raises(ConfigurationError, match="n_elite"):
        FastEndSearch(None, n_elite=0)
    with pytest.raises(ConfigurationError, match="sigma"):
        FastEndSearch(None, sigma=(0.1, 0.01))
    for bad in (-0.1, 1.5):
        with pytest.raises(ConfigurationError, match="immigrants"):
            FastEndSearch(None, immigrants=bad)
    assert settings.params["fast_end_immigrants"] == 0.0
    assert make_algorithm("mode")[1].params["fast_end_immigrants"] == pytest.approx(1 / 3)


@pytest.mark.parametrize("name", ["mode", "nsga2"])
def test_all_offspring_local_with_the_real_matings(problem: TrajectoryProblem, name: str) -> None:
    """fast_end = 1: every child is local, with MODE's DE variant and NSGA-II's SBX + PM
    (MODE's DE once failed when asked for no child)."""
    alg, _ = make_algorithm(name, pop_size=4, fast_end=1.0)
    alg.setup(problem, seed=1)
    pop = Population.new(X=np.repeat(lift_then_lower(problem)[None], 4, axis=0))
    Evaluator().eval(problem, pop)
    rng = np.random.default_rng(3)
    pop = alg.survival.do(problem, pop, n_survive=4, algorithm=alg, random_state=rng)  # ranks
    assert (pop.get("CV")[:, 0] <= 0).all()
    off = alg.mating.do(problem, pop, 4, algorithm=alg, random_state=np.random.default_rng(3))
    assert len(off) == 4
    x = off.get("X")
    np.testing.assert_allclose(x[:, 0], kinematic_time(problem, x), rtol=1e-8)


def test_numpy_numbers_are_accepted() -> None:
    _, settings = make_algorithm("nsga2", fast_end=np.float64(0.5))
    assert settings.params["fast_end"] == 0.5
    _, settings = make_algorithm("nsga2", fast_end=np.int64(0))
    assert settings.params["fast_end"] == 0.0
