"""The ε-constraint polish of front members and the polish settings of plan."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from adept_traj import TrajectoryProblem, plan
from adept_traj.analysis import PAPER_WEIGHTS
from adept_traj.certification import certify_members
from adept_traj.errors import ConfigurationError
from adept_traj.optimise import (
    MAX_EVALUATIONS,
    RunState,
    epsilon_step,
    polish_members,
    polish_mode,
    polish_run,
)
from adept_traj.problem import MAXIMISED, to_pymoo

#: Three members of a paper-budget NSGA-II front (see the file's "source").
MEMBERS = Path(__file__).parents[1] / "data" / "paper_front_members.json"

#: σ of the sign convention: −1 where maximised (z4).
SIGN = np.where(MAXIMISED, -1.0, 1.0)


@pytest.fixture(scope="module")
def members(problem: TrajectoryProblem) -> np.ndarray:
    x = np.array(json.loads(MEMBERS.read_text())["x"])
    assert np.all(problem.evaluate_batch(x).constraints <= 0.0)
    return x


@pytest.fixture(scope="module")
def scale() -> np.ndarray:
    """Typical ranges of z1…z6 on a paper front [objective units]."""
    return np.array([1.14, 2.9e3, 0.73, 0.012, 3.7e3, 65.0])


@pytest.fixture(scope="module")
def step(problem, members, scale):
    return epsilon_step(problem, members[2], 0, scale)


def _dominates(a: np.ndarray, b: np.ndarray) -> bool:
    """a Pareto-dominates b (objectives as reported, z4 maximised)."""
    return bool(np.all(SIGN * a <= SIGN * b) and np.any(SIGN * a < SIGN * b))


def test_step_dominates_its_start_and_is_certified(problem, members, step) -> None:
    """Lower travel time, no other objective worse, by the evaluator called directly;
    feasible and certified; its figures as returned."""
    start = problem.evaluate_batch(members[2])
    again = problem.evaluate_batch(step.x)
    np.testing.assert_array_equal(again.objectives, step.objectives)
    assert step.x[0] < members[2, 0]
    assert _dominates(again.objectives, start.objectives)
    assert np.all(again.constraints <= 0.0)
    assert certify_members(problem, step.x[None])[0].feasible
    assert step.n_evaluations <= 2 * MAX_EVALUATIONS


def test_step_is_deterministic(problem, members, scale, step) -> None:
    np.testing.assert_array_equal(epsilon_step(problem, members[2], 0, scale).x, step.x)


def test_input_is_checked_before_any_work(problem, members, scale) -> None:
    with pytest.raises(ConfigurationError, match="objective"):
        epsilon_step(problem, members[0], 6, scale)
    with pytest.raises(ConfigurationError, match=r"scale\[0\]"):
        epsilon_step(problem, members[0], 0, np.zeros(6))
    with pytest.raises(ConfigurationError, match="inside the decision bounds"):
        epsilon_step(problem, problem.xu + 1.0, 0, scale)
    paper = TrajectoryProblem(
        problem.robot, problem.scene, problem.start, problem.goal, z3="paper-sphere"
    )
    with pytest.raises(ConfigurationError, match="clearance"):
        epsilon_step(paper, members[0], 0, scale)


def _state(problem: TrajectoryProblem, x: np.ndarray, n_evaluations: int) -> RunState:
    ev = problem.evaluate_batch(x)
    return RunState(
        X=x,
        F=to_pymoo(ev.objectives),
        G=ev.constraints,
        CV=np.maximum(ev.constraints, 0.0).sum(axis=1),
        n_generations=1,
        n_evaluations=n_evaluations,
        total_s=1.0,
        evaluation_s=0.5,
    )


def test_polish_members_appends_the_dominating_move(problem, members, scale, step) -> None:
    """The kept step joins the population (its start stays: the front extraction drops
    it); evaluations and time are counted."""
    state = _state(problem, members, 100)
    out = polish_members(problem, state, [2], scale, 1000.0)
    assert len(out.X) == len(members) + 1
    np.testing.assert_array_equal(out.X[-1], step.x)
    np.testing.assert_array_equal(out.X[:-1], members)
    assert out.n_evaluations == 100 + step.n_evaluations
    assert out.total_s > state.total_s
    none = polish_members(problem, state, [2], scale, 1000.0, max_evaluations=MAX_EVALUATIONS - 1)
    assert len(none.X) == len(members)
    assert none.n_evaluations == 100


def test_front_mode_of_a_small_run_polishes_only_the_fastest(problem, members, monkeypatch) -> None:
    """A quarter of 100 evaluations pays for no member step: "front" leaves the members
    alone (the fastest member's polish, tested in test_polish.py, is left out here)."""
    import adept_traj.optimise.local.polish_modes as polish_step

    monkeypatch.setattr(polish_step, "_polish_fastest", lambda problem, state, rate, made: state)
    state = _state(problem, members, 100)
    out = polish_run(problem, state, 1000.0, "front", PAPER_WEIGHTS)
    assert out is state


def test_polish_settings(problem) -> None:
    assert [polish_mode(v) for v in (True, False, "all")] == ["front", "off", "all"]
    for bad in ("everything", 1, None):
        with pytest.raises(ConfigurationError, match="polish"):
            plan(problem, "nsga2", pop_size=8, n_gen=1, polish=bad)


def test_cli_refuses_no_polish_with_another_polish(tmp_path, capsys) -> None:
    from adept_traj.cli.app import main

    code = main(["plan", "--out", str(tmp_path / "r"), "--polish", "all", "--no-polish"])
    assert code != 0
    assert "--no-polish conflicts with --polish all" in capsys.readouterr().err
    assert not (tmp_path / "r").exists()


@pytest.mark.slow
def test_all_mode_keeps_hypervolume_and_certifies(problem) -> None:
    """A moderate run polished with "all": every front member certified, and the front's
    hypervolume on common bounds at least the unpolished one's."""
    from adept_traj.analysis import normalised_hypervolume, objective_bounds

    options = {"seed": 2, "pop_size": 24, "n_gen": 30}
    raw = plan(problem, "nsga2", polish="off", **options)
    full = plan(problem, "nsga2", polish="all", **options)
    assert full.algorithm_settings["polish"] == "all"
    fronts = [r.feasible_front.objectives for r in (raw, full)]
    lo, hi = objective_bounds(*fronts)
    assert normalised_hypervolume(fronts[1], lo, hi) >= normalised_hypervolume(fronts[0], lo, hi)
    assert full.front.n_certified == int(np.all(full.front.constraints <= 0.0, axis=1).sum())


def test_no_member_step_without_objective_gradients(problem, members, scale) -> None:
    """A problem whose objectives have no gradients (the paper's z3 penalty) keeps its
    members: the default polish of plan must not fail there."""
    paper = TrajectoryProblem(
        problem.robot, problem.scene, problem.start, problem.goal, z3="paper-sphere"
    )
    state = _state(paper, members, 10_000)
    assert polish_members(paper, state, [0, 1, 2], scale, 1000.0) is state
