"""Fixtures shared by the collision tests."""

from __future__ import annotations

import numpy as np
import pytest

from adept_traj.scene import PointCloud


@pytest.fixture(scope="module")
def fence() -> PointCloud:
    """A scanned fence: 40 000 points on a cylinder of radius 1 m, 0–0.6 m high."""
    rng = np.random.default_rng(28)
    a = rng.uniform(0.0, 2.0 * np.pi, 40_000)
    points = np.column_stack([np.cos(a), np.sin(a), rng.uniform(0.0, 0.6, len(a))])
    return PointCloud(points, 0.01)


@pytest.fixture(scope="module")
def fence_checker(fence):
    """(robot, checker): the AdeptOne XL on the paper scene's base with the fence, shrunk to
    0.85 of its radius (within the arm's reach), 0.2 m above the floor, as the only
    obstacle; influence 0.05 m."""
    import adept_traj as at
    from adept_traj.collision import CollisionChecker
    from adept_traj.scene import FixedPose, Obstacle, Scene

    near = PointCloud(fence.points * [0.85, 0.85, 1.0], 0.01)
    robot, paper = at.Robot.adept_one_xl(), Scene.paper()
    base = paper.robot_base[:3, 3]
    ob = Obstacle("fence", near, FixedPose.from_xyz_rpy((base[0], base[1], 0.2)))
    scene = Scene((ob,), robot_base=paper.robot_base, start=paper.start, goal=paper.goal)
    return robot, CollisionChecker(robot, scene, influence=0.05)
