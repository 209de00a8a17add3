"""The timed stage (adept_traj/optimise/local/timed_edges.py, timed_roadmap.py, timed_starts.py):
trees over joint space × scene time on the unseen wall-and-crane scene, checked against
independent references — coal called directly on shapes built by hand with the pendulum
placed by its closed form (``adept_traj.testing.scene_clock``), and the spline's own
samples for the fit."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import adept_traj as at
from adept_traj.errors import ConfigurationError
from adept_traj.optimise import (
    fit_timed_path,
    shortcut,
    time_optimal,
    timed_paths,
    timed_roadmap_starts,
)
from adept_traj.optimise.local.timed_edges import EDGE_SAMPLES, characteristic_speed
from adept_traj.testing.scene_clock import clearance_by_hand

ROOT = Path(__file__).parents[2]
WALL_CRANE = ROOT / "benchmarks" / "scenes" / "wall_crane.toml"
DATA = Path(__file__).parents[1] / "data"
BEST_KNOWN = 1.7143  # Drake + SNOPT, benchmarks/reference/reference_moves.json


@pytest.fixture(scope="module")
def crane() -> at.TrajectoryProblem:
    scene = at.Scene.from_file(WALL_CRANE)
    return at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal)


@pytest.fixture(scope="module")
def relaxed() -> np.ndarray:
    """(1, n_var) the fastest move without the crane load (tests/data/wall_crane_moves.json)."""
    moves = json.loads((DATA / "wall_crane_moves.json").read_text())
    return np.array(moves["wall_crane_relaxed_optimum"])[None]


@pytest.fixture(scope="module")
def found(crane: at.TrajectoryProblem, relaxed: np.ndarray) -> at.optimise.TimedPaths:
    return timed_paths(crane, 0, guides=relaxed)


def _segment_samples(q: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every segment of a timed path at EDGE_SAMPLES instants evenly over it (its end
    included), linear between its states: (n, nq) configurations and (n,) times [s]."""
    w = np.arange(1, EDGE_SAMPLES + 1) / EDGE_SAMPLES
    qs = q[:-1, None] + w[None, :, None] * (q[1:] - q[:-1])[:, None]
    ts = t[:-1, None] + w[None] * (t[1:] - t[:-1])[:, None]
    return qs.reshape(-1, q.shape[1]), ts.reshape(-1)


def test_the_joined_paths_pass_the_swinging_load_clear_by_coal_called_directly(
    crane: at.TrajectoryProblem, found: at.optimise.TimedPaths
) -> None:
    """Every joined path runs from the start at time 0 to the goal at its arrival, fast
    enough for its edges' speeds, and at the instants its segments are checked every
    robot solid keeps the margin from the wall, the cubes and the crane's rod and load,
    placed by hand at those scene times and measured by coal pair by pair."""
    assert len(found.paths) >= 1
    assert np.all(np.diff(found.arrival) >= 0.0)
    v_fast = 2.0 * characteristic_speed(crane)  # the fastest of SPEEDS
    for q, t in zip(found.paths, found.times):
        np.testing.assert_array_equal(q[0], crane.start)
        np.testing.assert_array_equal(q[-1], crane.goal)
        assert t[0] == 0.0
        assert np.all(np.diff(t) >= 0.0)
        assert t[-1] >= crane.xl[0]  # no arrival before the kinematic lower bound
        speed = np.abs(np.diff(q, axis=0)) / np.maximum(np.diff(t), 1e-12)[:, None]
        assert np.all(speed <= v_fast * (1.0 + 1e-9))
        qs, ts = _segment_samples(q, t)
        d, _ = clearance_by_hand(crane.robot, crane.scene.to_dict(), qs, ts)
        assert d.min() >= crane.settings.margin - 1e-6
    # the load: the same path an instant earlier or later is not what was checked; the
    # goal is hit by the swinging load for t in 0.70-1.30 s (scene file), so an arrival
    # is after it
    assert found.arrival[0] > 1.3


def test_the_same_seed_gives_the_same_starts_and_another_seed_others(
    crane: at.TrajectoryProblem, relaxed: np.ndarray
) -> None:
    a = timed_paths(crane, 3, guides=relaxed, rounds=2)
    b = timed_paths(crane, 3, guides=relaxed, rounds=2)
    c = timed_paths(crane, 4, guides=relaxed, rounds=2)
    assert a.n_nodes == b.n_nodes
    assert a.n_edges == b.n_edges
    np.testing.assert_array_equal(a.arrival, b.arrival)
    for p, q in zip(a.paths + a.times, b.paths + b.times):
        np.testing.assert_array_equal(p, q)
    assert (a.n_nodes, a.n_edges) != (c.n_nodes, c.n_edges)


@pytest.mark.slow
def test_the_starts_are_decision_vectors_inside_the_bounds_and_repeat(
    crane: at.TrajectoryProblem, relaxed: np.ndarray
) -> None:
    x = timed_roadmap_starts(crane, 0, guides=relaxed, n_starts=2)
    assert x.shape == (2, crane.n_var)
    assert np.all(x >= crane.xl)
    assert np.all(x <= crane.xu)
    np.testing.assert_array_equal(x, timed_roadmap_starts(crane, 0, guides=relaxed, n_starts=2))


def test_the_fit_of_a_spline_sampled_densely_is_that_spline(
    crane: at.TrajectoryProblem, relaxed: np.ndarray
) -> None:
    """A timed path made of the relaxed optimum's own samples (400 states, linear between
    them) is fitted back to its control points (least squares without smoothing), and a
    weight on the accelerations lowers their mean square (the spline's own samples)."""
    x = relaxed[0]
    s = np.linspace(0.0, 1.0, 400)
    smp = crane.trajectory.sample(x[None], s, orders=(0, 2))
    fit = fit_timed_path(crane, smp.q[0], smp.t[0], float(x[0]))
    np.testing.assert_allclose(fit, x, atol=2e-3)
    smooth = fit_timed_path(crane, smp.q[0], smp.t[0], float(x[0]), smoothing=1.0)
    acc = crane.robot.limits.acceleration
    ms = [
        np.mean((crane.trajectory.sample(v[None], s, orders=(2,)).qdd / acc) ** 2)
        for v in (fit, smooth)
    ]
    assert ms[1] < 0.8 * ms[0]


def test_a_path_held_at_the_goal_is_fitted_at_rest_there(crane: at.TrajectoryProblem) -> None:
    """Held at the goal after its arrival: the fit's last fifth stays within 1 cm | 0.01 rad
    of the goal (a hold keeps the phase of the way, the rest is a wait)."""
    q = np.stack([crane.start, crane.goal])
    fit = fit_timed_path(crane, q, np.array([0.0, 1.2]), 1.8)
    tail = crane.trajectory.sample(fit[None], np.linspace(0.8, 1.0, 20), orders=(0,)).q[0]
    assert np.abs(tail - crane.goal).max() < 0.01


def test_a_shortcut_keeps_the_ends_and_their_times(
    crane: at.TrajectoryProblem, found: at.optimise.TimedPaths
) -> None:
    q, t = found.paths[0], found.times[0]
    q2, t2 = shortcut(crane, q, t)
    assert len(t2) <= len(t)
    np.testing.assert_array_equal(q2[[0, -1]], q[[0, -1]])
    np.testing.assert_array_equal(t2[[0, -1]], t[[0, -1]])
    assert set(map(float, t2)) <= set(map(float, t))  # kept states keep their times


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda p: timed_paths(p, -1), "seed"),
        (lambda p: timed_paths(p, 0, rounds=0), "rounds"),
        (lambda p: timed_roadmap_starts(p, 0, n_starts=0), "n_starts"),
        (lambda p: fit_timed_path(p, np.zeros((1, 4)), np.zeros(1), 1.0), "q must have"),
        (lambda p: fit_timed_path(p, np.zeros((2, 3)), np.zeros(2), 1.0), "q must have"),
        (lambda p: fit_timed_path(p, np.zeros((2, 4)), np.array([0.1, 1.0]), 1.0), "t must"),
        (lambda p: fit_timed_path(p, np.zeros((2, 4)), np.array([0.0, 1.0]), 0.5), "T must"),
        (
            lambda p: fit_timed_path(p, np.zeros((2, 4)), np.array([0.0, 1.0]), 1.0, -1.0),
            "smoothing",
        ),
    ],
)
def test_bad_inputs_are_refused_naming_the_value(
    crane: at.TrajectoryProblem, call: object, match: str
) -> None:
    with pytest.raises(ConfigurationError, match=match):
        call(crane)  # type: ignore[operator]


@pytest.mark.slow
def test_the_time_optimal_mode_ends_certified_near_the_best_known_move_past_the_crane(
    crane: at.TrajectoryProblem,
) -> None:
    """End to end on the unseen scene: ``time_optimal`` (straight move and ramps, then the
    global stage: relaxed optimum stretched, timed trees, via points) ends with a certified
    move within 1 % of the best known one, its distances re-checked by coal called
    directly with the crane load placed by hand. (Before the timed stage: no certified
    move.)"""
    outcomes = time_optimal(crane, seed=1)
    done = [o for o in outcomes if o.certified]
    assert done
    best = min(done, key=lambda o: float(o.x[0]))
    assert best.x[0] <= 1.01 * BEST_KNOWN
    c = at.certify(crane, best.x, 4000.0)
    d, _ = clearance_by_hand(crane.robot, crane.scene.to_dict(), c.dense.q, c.dense.t)
    assert d.min() >= crane.settings.margin - 1e-6
