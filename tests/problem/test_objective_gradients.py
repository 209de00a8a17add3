"""Gradients of the objectives z1…z6 against central differences of the evaluator."""

from __future__ import annotations

import numpy as np
import pytest

from adept_traj import TrajectoryProblem
from adept_traj.errors import ConfigurationError
from adept_traj.optimise import RampSampling
from adept_traj.problem import local_constraints, objective_gradients
from adept_traj.testing.paper_moves import lift_then_lower

#: Central-difference step in the decision vector (relative to max(1, |x|)).
_STEP = 1e-6


def _central_differences(problem: TrajectoryProblem, x: np.ndarray) -> np.ndarray:
    """(6, n_var) central differences of the evaluator's objectives, one batched call."""
    h = _STEP * np.maximum(1.0, np.abs(x))
    steps = np.diag(h)
    z = problem.evaluate_batch(np.concatenate([x + steps, x - steps])).objectives
    n = problem.n_var
    return ((z[:n] - z[n:]) / (2.0 * h[:, None])).T


@pytest.fixture(scope="module")
def moves(problem: TrajectoryProblem) -> np.ndarray:
    """Two seeded ramps with seeded noise on their control points (no flat stretch: no
    joint at rest inside the move, no tie of the minima), and a move that comes within the
    influence distance of an obstacle (z3 > 0)."""
    rng = np.random.default_rng(3)
    x = np.concatenate([RampSampling().ramps(problem, 2, rng), lift_then_lower(problem)[None]])
    x[:, 1:] += rng.normal(0.0, [[0.01], [0.01], [0.002]], x[:, 1:].shape)
    return np.clip(x, problem.xl, problem.xu)


def test_values_are_the_evaluators(problem, moves) -> None:
    og = objective_gradients(problem, moves)
    np.testing.assert_allclose(og.values, problem.evaluate_batch(moves).objectives, rtol=1e-9)
    assert og.values[2, 2] > 0.0  # the close move has a clearance penalty


@pytest.mark.parametrize("row", [0, 1, 2])
def test_gradients_match_central_differences(problem, moves, row) -> None:
    """Every objective's gradient (z4: zero, its minimum is at the fixed start or goal)."""
    og = objective_gradients(problem, moves[row])
    fd = _central_differences(problem, moves[row])
    scale = np.abs(fd).max(axis=1, keepdims=True) + 1e-12
    np.testing.assert_array_less(np.abs(og.jacobian[0] - fd) / scale, 1e-5)
    assert np.all(np.abs(fd[[0, 1, 4, 5]]).max(axis=1) > 0.0)
    if row == 2:
        assert np.abs(fd[2]).max() > 0.0


def test_z4_gradient_at_an_interior_minimum(problem) -> None:
    """A move whose elbow passes nearer to its singular pose than at the ends: the
    minimum of |det J| is inside the move, and its gradient is non-zero."""
    x = RampSampling().ramps(problem, 1, np.random.default_rng(5))[0]
    n_free = problem.trajectory.n_free
    elbow = 1 + n_free + np.arange(n_free // 3, 2 * n_free // 3)  # joint 2, middle points
    x[elbow] = 0.12  # [rad]; the goal's elbow is at 0.245 rad
    x[1:] += np.random.default_rng(6).normal(0.0, 0.01, problem.n_var - 1)
    x = np.clip(x, problem.xl, problem.xu)
    og = objective_gradients(problem, x)
    k = int(np.argmin(og.manipulability[0]))
    assert 0 < k < len(problem.s) - 1
    fd = _central_differences(problem, x)[3]
    assert np.abs(fd).max() > 1e-3
    np.testing.assert_allclose(og.jacobian[0, 3], fd, atol=1e-6 * np.abs(fd).max())


def test_per_sample_pieces_match_the_library(problem, moves) -> None:
    """Manipulability and distances at the samples against the robot and the checker
    called directly."""
    og = objective_gradients(problem, moves)
    smp = problem.trajectory.sample(moves, problem.s, orders=(0,))
    np.testing.assert_allclose(og.manipulability, problem.robot.manipulability(smp.q))
    d = problem.checker.distances(smp.q, smp.t).distance.min(axis=-2)
    np.testing.assert_allclose(og.distance, np.minimum(d, problem.settings.influence), atol=1e-12)


def test_reuses_local_constraints(problem, moves) -> None:
    lc = local_constraints(problem, moves)
    a, b = objective_gradients(problem, moves, local=lc), objective_gradients(problem, moves)
    np.testing.assert_array_equal(a.jacobian, b.jacobian)
    with pytest.raises(ConfigurationError, match="vectors"):
        objective_gradients(problem, moves[:1], local=lc)


def test_paper_penalty_is_refused(problem) -> None:
    other = TrajectoryProblem(
        problem.robot, problem.scene, problem.start, problem.goal, z3="paper-sphere"
    )
    with pytest.raises(ConfigurationError, match="clearance"):
        objective_gradients(other, other.trajectory.straight_line(other.xl[0]))
