"""A scanned point cloud of 10⁶ points for ``benchmarks/bench_cells.py``: the safety fence
around the robot (a cylinder of radius ``radius`` about the base axis, 0–1.5 m high, as a
laser scan of the cell would see it) sampled uniformly, as a 1 cm octree, added to the
paper scene. The fence's bounding box holds the whole robot, so only the cloud's own
distance field (:meth:`~adept_traj.scene.PointCloud.lower_bound`) keeps the broad phase
from calling coal at every sample."""

from __future__ import annotations

import numpy as np

from adept_traj.scene import FixedPose, Obstacle, PointCloud, Scene


def cloud_scene(
    paper: Scene, n_points: int = 1_000_000, resolution: float = 0.01, radius: float = 1.1
) -> Scene:
    """The paper scene with a fence cloud of ``n_points`` at ``resolution`` [m], ``radius``
    [m] from the robot base axis."""
    rng = np.random.default_rng(0)
    angle = rng.uniform(0.0, 2.0 * np.pi, n_points)
    points = np.column_stack(
        [radius * np.cos(angle), radius * np.sin(angle), rng.uniform(0.0, 1.5, n_points)]
    )
    base = paper.robot_base[:3, 3]
    fence = Obstacle(
        "fence", PointCloud(points, resolution), FixedPose.from_xyz_rpy((base[0], base[1], 0.0))
    )
    return Scene(
        (*paper.obstacles, fence), robot_base=paper.robot_base, start=paper.start, goal=paper.goal
    )
