"""The weighted-sum mode: f_w, its gradient, the descent from the minimum-T move, plan."""

from __future__ import annotations

import json

import numpy as np
import pytest

from adept_traj import Robot, Scene, TrajectoryProblem, plan
from adept_traj.analysis import WeightedSum, weighted_sum
from adept_traj.certification import certify_members
from adept_traj.certification.audit import audit
from adept_traj.errors import ConfigurationError, InputShapeError, InvalidInputError
from adept_traj.optimise import RampSampling, time_optimal, weighted_descent
from adept_traj.results import PlanningResult
from adept_traj.testing.paper_moves import lift_then_lower

#: Weights on the energy z2 alone, and the paper's.
ENERGY = (0.0, 1.0, 0.0, 0.0, 0.0, 0.0)
PAPER = (0.25, 0.25, 0.1, 0.1, 0.15, 0.15)


@pytest.fixture(scope="module")
def fastest(problem: TrajectoryProblem):
    """The minimum-T move from the straight start (T = 1.0765924346 s)."""
    return time_optimal(problem, seed=1, n_starts=1)[0]


def test_values_are_the_documented_sum(problem) -> None:
    """f_w = Σ ŵ σ z / r with r the straight move's objectives at T_lb (r3 = 1), written
    out by hand from the evaluator called directly."""
    ws = weighted_sum(problem, [2.0, 1.0, 0.0, 1.0, 0.0, 0.0])
    straight = problem.trajectory.straight_line(problem.lower_bound.T_min)
    z_ref = problem.evaluate_batch(straight).objectives
    np.testing.assert_array_equal(ws.weights, [0.5, 0.25, 0.0, 0.25, 0.0, 0.0])
    np.testing.assert_array_equal(ws.scale[[0, 1, 3, 4, 5]], z_ref[[0, 1, 3, 4, 5]])
    assert ws.scale[0] == problem.lower_bound.T_min
    assert ws.scale[2] == 1.0
    z = problem.evaluate_batch(lift_then_lower(problem)).objectives
    by_hand = 0.5 * z[0] / z_ref[0] + 0.25 * z[1] / z_ref[1] - 0.25 * z[3] / z_ref[3]
    assert ws.values(z) == pytest.approx(by_hand, rel=1e-12)
    assert ws.values(z_ref) == pytest.approx(0.5 + 0.25 - 0.25, rel=1e-12)


def test_gradient_matches_central_differences(problem) -> None:
    """The gradient of f_w (every weight > 0) against central differences of the
    evaluator's f_w, on a move with a clearance penalty (z3 > 0)."""
    rng = np.random.default_rng(3)  # the moves of tests/problem/test_objective_gradients.py
    moves = np.concatenate([RampSampling().ramps(problem, 2, rng), lift_then_lower(problem)[None]])
    moves[:, 1:] += rng.normal(0.0, [[0.01], [0.01], [0.002]], moves[:, 1:].shape)
    x = np.clip(moves[2], problem.xl, problem.xu)
    ws = weighted_sum(problem, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    value, grad = ws.gradient(problem, x)
    z = problem.evaluate_batch(x).objectives
    assert z[2] > 0.0
    assert value[0] == pytest.approx(ws.values(z), rel=1e-9)
    h = 1e-6 * np.maximum(1.0, np.abs(x))
    steps = np.diag(h)
    f = ws.values(problem.evaluate_batch(np.concatenate([x + steps, x - steps])).objectives)
    fd = (f[: problem.n_var] - f[problem.n_var :]) / (2.0 * h)
    np.testing.assert_allclose(grad[0], fd, atol=1e-5 * np.abs(fd).max())
    assert np.abs(fd).max() > 0.0


@pytest.mark.parametrize(
    ("weights", "error", "text"),
    [
        ((1.0, 0.0, 0.0), InputShapeError, "(6,)"),
        ((1.0, -0.5, 0.0, 0.0, 0.0, 0.0), InvalidInputError, "non-negative"),
        ((0.0,) * 6, InvalidInputError, "positive sum"),
        ((1.0, np.nan, 0.0, 0.0, 0.0, 0.0), InvalidInputError, "nan"),
        ((np.inf, 0.0, 0.0, 0.0, 0.0, 0.0), InvalidInputError, "inf"),
    ],
)
def test_bad_weights_are_refused_before_any_solve(
    problem, monkeypatch, weights, error, text
) -> None:
    def no_solve(*args, **kwargs):
        raise AssertionError("a solve started")

    monkeypatch.setattr("adept_traj.optimise.local.weighted_move.time_optimal_run", no_solve)
    monkeypatch.setattr("adept_traj.optimise.planner.time_optimal_run", no_solve)
    with pytest.raises(error, match="weights") as caught:
        plan(problem, "time-optimal", weights=weights)
    assert text in str(caught.value)


def test_bad_scales_and_settings_are_refused() -> None:
    with pytest.raises(InvalidInputError, match="scale must be > 0"):
        WeightedSum(np.ones(6), [1.0, 1.0, 0.0, 1.0, 1.0, 1.0])
    with pytest.raises(InvalidInputError, match="'weights' and 'scale'"):
        WeightedSum.from_settings({"weighted_sum": {"weights": [1.0] * 6}})
    assert WeightedSum.from_settings({"name": "time-optimal"}) is None


def test_the_paper_penalty_has_no_weighted_mode() -> None:
    scene = Scene.paper()
    paper = TrajectoryProblem(
        Robot.adept_one_xl(), scene, scene.start, scene.goal, z3="paper-sphere", workers=1
    )
    with pytest.raises(ConfigurationError, match="z3='clearance'"):
        weighted_sum(paper, PAPER)


def test_cli_refuses_bad_weights_before_writing(tmp_path, capsys) -> None:
    from adept_traj.cli.app import main

    out = tmp_path / "r"
    code = main(["plan", "--algorithm", "time-optimal", "--weights", "1,2", "--out", str(out)])
    assert code != 0
    assert "--weights must be 6 finite numbers ≥ 0; got 1.0,2.0" in capsys.readouterr().err
    assert not out.exists()


def test_weights_on_t_keep_the_minimum_t_move(problem, fastest) -> None:
    """From the minimum-T move, weights on z1 alone find nothing lower (a KKT point)."""
    ws = weighted_sum(problem, (1.0, 0.0, 0.0, 0.0, 0.0, 0.0))
    out = weighted_descent(problem, fastest.x, ws, max_evaluations=20)
    assert out.x[0] == pytest.approx(fastest.x[0], rel=1e-6)
    assert ws.values(out.objectives) >= ws.values(fastest.objectives) - 1e-6
    assert out.feasible


def test_weights_on_energy_trade_time_for_energy(problem, fastest) -> None:
    """One step with the weights on z2: a certified move of lower f_w and lower energy
    than the minimum-T move, and slower (a real trade-off); the same bits again."""
    ws = weighted_sum(problem, ENERGY)
    out = weighted_descent(problem, fastest.x, ws, max_evaluations=20)
    again = problem.evaluate_batch(out.x)
    np.testing.assert_array_equal(again.objectives, out.objectives)
    assert ws.values(out.objectives) < ws.values(fastest.objectives) - 0.05
    assert out.objectives[1] < fastest.objectives[1]
    assert out.x[0] > fastest.x[0]
    assert np.all(again.constraints <= 0.0)
    assert certify_members(problem, out.x[None])[0].feasible


@pytest.mark.slow
def test_plan_weighted_mode_round_trips_verifies_and_repeats(problem, tmp_path) -> None:
    """plan with weights: the best is the certified member of lowest f_w, below the
    minimum-T move's and slower; the result saves, loads and passes the audit with the
    stored weights; the same seed gives the same bits."""
    first = plan(problem, "time-optimal", seed=1, weights=ENERGY, n_starts=2, max_evaluations=60)
    again = plan(problem, "time-optimal", seed=1, weights=ENERGY, n_starts=2, max_evaluations=60)
    np.testing.assert_array_equal(first.front.x, again.front.x)
    assert first.best.index == again.best.index
    settings = first.algorithm_settings["weighted_sum"]
    assert settings["weights"] == list(ENERGY)
    ws = WeightedSum.from_settings(first.algorithm_settings)
    f = ws.values(first.front.objectives)
    certified = np.flatnonzero(first.front.feasible)
    assert first.feasible
    assert first.best.index == certified[np.argmin(f[certified])]
    fastest = certified[np.argmin(first.front.objectives[certified, 0])]
    assert f[first.best.index] < f[fastest]
    assert first.best_objectives[0] > first.front.objectives[fastest, 0]
    assert first.metrics.t_best == pytest.approx(1.0765924346, abs=1e-9)
    first.save(tmp_path / "r")
    loaded = PlanningResult.load(tmp_path / "r")
    assert loaded.algorithm_settings == first.algorithm_settings
    assert audit(loaded, problem=problem).ok
    # a tampered scale is found
    path = tmp_path / "r" / "result.json"
    doc = json.loads(path.read_text())
    doc["algorithm"]["settings"]["weighted_sum"]["scale"][1] *= 2.0
    path.write_text(json.dumps(doc))
    found = audit(PlanningResult.load(tmp_path / "r"), problem=problem)
    assert any("weighted_sum.scale" in m.field for m in found.mismatches)


@pytest.mark.slow
def test_cli_weights_turn_the_time_optimal_mode_into_the_weighted_sum(tmp_path, capsys) -> None:
    """``--algorithm time-optimal`` without ``--weights`` stays minimum T; with them the
    summary prints f_w, the result stores the weights, and ``verify`` passes."""
    from adept_traj.cli.app import main

    quiet = ["--no-html", "--no-plots", "--quiet", "--workers", "1"]
    assert main(["plan", "--algorithm", "time-optimal", "--out", str(tmp_path / "t"), *quiet]) == 0
    plain = PlanningResult.load(tmp_path / "t")
    assert "weighted_sum" not in plain.algorithm_settings
    assert "weighted sum" not in capsys.readouterr().out
    args = ["--weights", "0,1,0,0,0,0", "--out", str(tmp_path / "w"), *quiet]
    assert main(["plan", "--algorithm", "time-optimal", *args]) == 0
    assert "weighted sum f_w = " in capsys.readouterr().out
    weighted = PlanningResult.load(tmp_path / "w")
    assert weighted.algorithm_settings["weighted_sum"]["weights"] == list(ENERGY)
    assert weighted.best_objectives[0] > plain.best_objectives[0]
    assert main(["verify", str(tmp_path / "w")]) == 0


def _resume_options(folder, saved: dict, *extra: str):
    """The options ``plan --resume folder`` would run with, for a run file ``saved``."""
    import argparse

    from adept_traj.cli import plan as cli_plan
    from adept_traj.cli._run_folder import write_arguments

    parser = argparse.ArgumentParser()
    cli_plan.add_parser(parser.add_subparsers())
    write_arguments(folder, saved)
    return cli_plan._options(parser.parse_args(["plan", "--resume", str(folder), *extra]))[0]


def _run_file(tmp_path, *options: str) -> dict:
    """The run file a new ``plan --out`` with ``options`` writes (without planning)."""
    import argparse

    from adept_traj.cli import plan as cli_plan

    parser = argparse.ArgumentParser()
    cli_plan.add_parser(parser.add_subparsers())
    opts = cli_plan._options(parser.parse_args(["plan", "--out", str(tmp_path), *options]))[0]
    return {k: getattr(opts, k) for k in cli_plan._SAVED}


def test_an_earlier_versions_time_optimal_run_resumes_as_minimum_t(tmp_path) -> None:
    """A time-optimal run file written before the weighted-sum mode holds the paper's
    default weights, which that version ignored: it resumes as minimum T (review finding:
    it resumed in the weighted-sum mode, another objective); a run file of this version
    keeps its mode."""
    from adept_traj.analysis import PAPER_WEIGHTS

    old = {**_run_file(tmp_path, "--algorithm", "time-optimal"), "weights": list(PAPER_WEIGHTS)}
    assert _resume_options(tmp_path, old).weights is None
    with pytest.raises(ConfigurationError, match="--weights"):
        _resume_options(tmp_path, old, "--weights", "1,1,1,1,1,1")
    weighted = {
        **_run_file(tmp_path, "--algorithm", "time-optimal", "--weights", "0,1,0,0,0,0"),
        "time_optimal_weights": True,
    }
    assert _resume_options(tmp_path, weighted).weights == [0.0, 1.0, 0.0, 0.0, 0.0, 0.0]
    nsga2 = _run_file(tmp_path)  # an NSGA-II run file of either version: the weights of f_c
    assert _resume_options(tmp_path, nsga2).weights == list(PAPER_WEIGHTS)


def test_a_new_run_file_marks_the_weighted_mode(tmp_path, monkeypatch) -> None:
    """``plan`` writes the key that tells its run file from an earlier version's."""
    from adept_traj.cli import main
    from adept_traj.cli import plan as cli_plan

    monkeypatch.setattr(cli_plan, "_run", lambda *args: 0)  # stop after the run file
    assert main(["plan", "--algorithm", "time-optimal", "--out", str(tmp_path / "run")]) == 0
    saved = json.loads((tmp_path / "run" / "run.json").read_text())
    assert saved["time_optimal_weights"] is True
    assert saved["weights"] is None
