"""One scene clock: a move that starts at scene time t0 is evaluated, certified, saved,
re-verified and played with the obstacles at scene time t0 + t (issue 25).

The oracle is :mod:`adept_traj.testing.scene_clock`: coal called directly on shapes built
from the scene file's numbers, the pendulum placed by its closed form written out again
(no code shared with the checker, the scene or the motion laws).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import adept_traj as at
from adept_traj.certification import certify
from adept_traj.cli import main
from adept_traj.collision import CollisionChecker
from adept_traj.collision.distance_gradient import distance_gradients
from adept_traj.errors import ConfigurationError, InvalidInputError
from adept_traj.problem import ProblemSettings
from adept_traj.testing.reference import evaluate_reference
from adept_traj.testing.scene_clock import clearance_by_hand, pendulum_bob_by_hand

MOVES = json.loads((Path(__file__).parents[1] / "data" / "detour_moves.json").read_text())


@pytest.fixture(scope="module")
def robot() -> at.Robot:
    return at.Robot.adept_one_xl()


@pytest.fixture(scope="module")
def detour() -> at.Scene:
    return at.Scene.shipped("detour")


@pytest.mark.parametrize("bad", [-0.1, float("nan"), float("inf"), "soon", None])
def test_start_time_is_checked(robot, detour, bad) -> None:
    with pytest.raises(
        ConfigurationError,
        match=r"start_time must be a finite number ≥ 0 \[s\]; got",
    ):
        ProblemSettings(start_time=bad)
    with pytest.raises(ConfigurationError, match="start_time"):
        at.TrajectoryProblem(robot, detour, detour.start, detour.goal, start_time=bad)


def test_start_time_defaults_to_zero(robot, detour) -> None:
    problem = at.TrajectoryProblem(robot, detour, detour.start, detour.goal)
    assert problem.settings.start_time == 0.0
    assert problem.checker.start_time == 0.0
    with pytest.raises(InvalidInputError, match="start_time"):
        CollisionChecker(robot, detour, start_time=-1.0)


@pytest.mark.parametrize("t0", [0.0, 1.0, 1.5, 2.0])
def test_a_move_is_certified_at_its_scene_time(robot, detour, t0: float) -> None:
    """The fastest move found without the pendulum, started at t0: the certificate's dense
    distances are the hand-made ones at scene time t0 + t, and it is certified exactly
    when the hand-made check clears the margin (it hits the rod at t0 = 0 and 2.0, passes
    at 1.0; 1.5 is within the margin)."""
    x = np.array(MOVES["fast_without_pendulum"])
    problem = at.TrajectoryProblem(robot, detour, detour.start, detour.goal, start_time=t0)
    cert = certify(problem, x, exact=False)
    dense = cert.dense
    grid = np.linspace(0, dense.n_samples - 1, 150).astype(int)
    rows = np.unique(np.r_[grid, np.argmin(dense.min_distance)])
    hand, names = clearance_by_hand(robot, detour.to_dict(), dense.q[rows], t0 + dense.t[rows])
    influence = problem.settings.influence
    np.testing.assert_allclose(
        np.minimum(dense.min_distance[rows], influence), np.minimum(hand, influence), atol=1e-6
    )
    expected = {0.0: False, 1.0: True, 1.5: False, 2.0: False}[t0]
    assert bool(cert.certified) is expected
    assert bool(hand.min() >= problem.settings.margin) is expected
    if not expected:
        assert names[int(np.argmin(hand))].startswith("pendulum.")


def test_evaluation_at_a_start_time_equals_the_reference(robot, detour) -> None:
    problem = at.TrajectoryProblem(robot, detour, detour.start, detour.goal, start_time=1.3)
    x = np.vstack([MOVES["fast_without_pendulum"], MOVES["fastest_nsga2_seed1"]])
    batched = problem.evaluate_batch(x)
    reference = evaluate_reference(problem, x)
    np.testing.assert_allclose(batched.objectives, reference.objectives, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(batched.min_distance, reference.min_distance, rtol=0, atol=1e-9)
    at_zero = at.TrajectoryProblem(robot, detour, detour.start, detour.goal).evaluate_batch(x)
    assert not np.allclose(at_zero.min_distance, batched.min_distance)  # the clock matters


def test_parallel_workers_use_the_start_time(robot, detour) -> None:
    """The forked evaluation workers see the same clock as the main process."""
    x = np.vstack([MOVES["fast_without_pendulum"], MOVES["fastest_nsga2_seed1"]] * 8)
    serial = at.TrajectoryProblem(robot, detour, detour.start, detour.goal, start_time=2.0)
    with at.TrajectoryProblem(
        robot, detour, detour.start, detour.goal, start_time=2.0, workers=2
    ) as parallel:
        both = parallel.evaluate_batch(x)
    np.testing.assert_array_equal(both.min_distance, serial.evaluate_batch(x).min_distance)
    assert both.min_distance[0].min() < 0  # the rod, at 2.0 + t


def test_distance_time_derivative_at_a_start_time(robot, detour) -> None:
    """∂d/∂t of the distance rows (the obstacle's motion at scene time t0 + t) against a
    central difference of the distance in t0 at fixed joints."""
    x = np.array(MOVES["fast_without_pendulum"])
    problem = at.TrajectoryProblem(robot, detour, detour.start, detour.goal, start_time=2.0)
    t = np.linspace(1.2, 1.5, 7)
    q = problem.trajectory.sample(x, t / x[0], orders=(0,)).q
    grad = distance_gradients(problem.checker, q, t)
    h = 1e-6
    plus = CollisionChecker(robot, detour, start_time=2.0 + h).distances(q, t, exact=True)
    minus = CollisionChecker(robot, detour, start_time=2.0 - h).distances(q, t, exact=True)
    rod = list(problem.checker.obstacle_names).index("pendulum.rod")
    near = grad.distance[:, rod] < problem.settings.influence
    assert near.any()
    fd = (plus.distance.min(axis=-2)[:, rod] - minus.distance.min(axis=-2)[:, rod]) / (2 * h)
    np.testing.assert_allclose(grad.dt[near, rod], fd[near], rtol=1e-4, atol=1e-5)
    assert np.abs(grad.dt[near, rod]).max() > 0.1  # the rod moves there


@pytest.mark.slow  # ~9 s: plan with the polish's global stage, verify, playback
def test_plan_verify_and_playback_at_a_start_time(tmp_path: Path, capsys) -> None:
    """``plan --start-time`` records t0; ``verify`` re-certifies at it (no mismatch), a
    tampered t0 is a mismatch; the playback draws the bob at t0 + t."""
    out = tmp_path / "run"
    argv = ["plan", "--scene", "paper", "--pop", "8", "--gens", "2", "--no-html", "--no-plots"]
    assert main([*argv, "--quiet", "--start-time", "1.25", "--out", str(out)]) == 0
    assert "t0 = 1.25 s" in capsys.readouterr().out
    stored = json.loads((out / "result.json").read_text())
    assert stored["problem_settings"]["start_time"] == 1.25
    result = at.PlanningResult.load(out)
    assert result.problem_settings.start_time == 1.25
    capsys.readouterr()
    main(["verify", str(out)])
    text = capsys.readouterr().out
    assert "t0 = 1.25 s" in text
    assert "no mismatch" in text
    stored["problem_settings"]["start_time"] = 2.0  # another clock: other distances
    (out / "result.json").write_text(json.dumps(stored))
    assert main(["verify", str(out)]) == 3
    assert "mismatch:" in capsys.readouterr().out

    from adept_traj.viz.playback import build_animation

    play = build_animation(result, fps=10)
    bob = next(o for o in play.objects if o.path == "obstacles/pendulum.bob")
    entry = result.scene["pendulum"][0]
    hand = np.array([pendulum_bob_by_hand(entry, 1.25 + t) for t in play.times])
    np.testing.assert_allclose(bob.poses[:, :3, 3], hand, atol=1e-12)


def test_default_start_time_is_left_out_of_result_json(tmp_path: Path) -> None:
    out = tmp_path / "run"
    argv = ["plan", "--scene", "paper", "--pop", "8", "--gens", "2", "--no-html", "--no-plots"]
    assert main([*argv, "--quiet", "--out", str(out)]) == 0
    stored = json.loads((out / "result.json").read_text())
    assert "start_time" not in stored["problem_settings"]  # files as before the field
    assert at.PlanningResult.load(out).problem_settings.start_time == 0.0
