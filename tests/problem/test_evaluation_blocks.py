"""Pieces of the batched evaluation that are cut or shared for speed give the values of the
plain computation: populations cut into other blocks, the single-joint tables sharing their
grid positions, the pendulum's poses filled row by row."""

from __future__ import annotations

import numpy as np
import pytest

from adept_traj import Robot, Scene
from adept_traj.collision import BroadPhase, table_bounds
from adept_traj.problem import TrajectoryProblem


@pytest.fixture(scope="module")
def problem() -> TrajectoryProblem:
    scene = Scene.paper()
    return TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)


def test_blocks_do_not_change_the_values(problem: TrajectoryProblem) -> None:
    """53 trajectories are two blocks (27 + 26), 50 one block, 20 one: every row is the
    same, bit for bit, whatever block it was evaluated in (coal calls too)."""
    rng = np.random.default_rng(40)
    x = problem.xl + (problem.xu - problem.xl) * rng.uniform(size=(53, problem.n_var))
    whole = problem.evaluate_batch(x)
    parts = [problem.evaluate_batch(x[:3]), problem.evaluate_batch(x[3:])]
    for name in ("objectives", "constraints", "min_distance"):
        split = np.concatenate([getattr(p, name) for p in parts])
        np.testing.assert_array_equal(getattr(whole, name), split)
    assert whole.n_narrow == sum(p.n_narrow for p in parts)


def test_tables_on_one_grid_share_it(problem: TrajectoryProblem) -> None:
    """table_bounds equals the interpolation bound of the module docstring, sample by
    sample: max(d_i − L (q − q_i), d_{i+1} − L (q_{i+1} − q)) − 5 µm, −inf off the grid."""
    broad = BroadPhase(problem.robot, problem.scene, problem.settings.influence)
    assert len({t.grid for t in broad.tables.values()}) < len(broad.tables)  # shared grids
    lo, hi = problem.robot.limits.lower, problem.robot.limits.upper
    rng = np.random.default_rng(41)
    q = lo + (hi - lo) * rng.uniform(-0.05, 1.05, size=(300, problem.robot.nq))
    bounds = table_bounds(broad.tables, q)
    assert set(bounds) == set(broad.tables)
    for key, table in broad.tables.items():
        expected = []
        for value in q[:, table.joint].tolist():
            u = (value - table.start) / table.step
            if not 0.0 <= u <= len(table.values) - 1:
                expected.append(-np.inf)
                continue
            i = min(int(np.floor(u)), len(table.values) - 2)
            left = table.values[i] - table.lipschitz * table.step * (u - i)
            right = table.values[i + 1] - table.lipschitz * table.step * (1.0 - (u - i))
            expected.append(max(left, right) - 5e-6)
        np.testing.assert_allclose(bounds[key], expected, rtol=0.0, atol=1e-15)
        np.testing.assert_array_equal(bounds[key], table.lower_bound(q[:, table.joint]))


def test_pendulum_pose_is_the_rotation_about_its_normal() -> None:
    """Each pose of the paper's pendulum, against its definition with numpy's matrices:
    columns x = cos φ e_swing + sin φ e_z, y = e_n, z = −sin φ e_swing + cos φ e_z,
    translation = pivot."""
    law = next(ob.motion for ob in Scene.paper().obstacles if ob.is_moving)
    t = np.linspace(-3.0, 3.0, 60).reshape(3, 20, 1)
    poses = law.pose(t)
    assert poses.shape == (3, 20, 1, 4, 4)
    e_z = np.array([0.0, 0.0, 1.0])
    for ti, pose in zip(t.ravel(), poses.reshape(-1, 4, 4)):
        phi = float(law.angle(ti))
        expected = np.eye(4)
        expected[:3, 0] = np.cos(phi) * law.swing_axis + np.sin(phi) * e_z
        expected[:3, 1] = law.normal_axis
        expected[:3, 2] = -np.sin(phi) * law.swing_axis + np.cos(phi) * e_z
        expected[:3, 3] = law.pivot
        np.testing.assert_array_equal(pose, expected)
