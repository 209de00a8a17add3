"""A work cell of real size: the paper's scene plus fixed boxes out of the robot's reach.

``cell_scene(200)`` is the paper scene (two cubes and the pendulum) with 198 more boxes
(fixtures, conveyors, guards) of 0.1–0.5 m, spread on a ring 1.2–4 m around the robot
base in the floor plane, beyond the arm's reach (0.8 m) plus the influence distance. The
obstacles near the path are the paper's, so a planner that prunes far obstacles should
evaluate it nearly as fast as the paper scene. Run as a script to write the scene TOML:
``python benchmarks/cell_scene.py [--boxes 200] [--out cell.toml]``.
"""

from __future__ import annotations

import argparse

import numpy as np

from adept_traj import Box, FixedPose, Obstacle, Scene

#: Ring around the robot base (floor plane) where the extra boxes stand [m].
RING = (1.2, 4.0)


def cell_scene(n_boxes: int = 200, seed: int = 0) -> Scene:
    """The paper scene with ``n_boxes`` boxes in all (its two cubes included): the others
    (size 0.1–0.5 m, heights 0.1–1.5 m, standing on the floor z = 0) at 1.2–4 m from the
    robot base axis, placed by ``numpy.random.default_rng(seed)``."""
    paper = Scene.paper()
    n_extra = n_boxes - sum(isinstance(ob.shape, Box) for ob in paper.obstacles)
    rng = np.random.default_rng(seed)
    base_xy = paper.robot_base[:2, 3]
    radius = rng.uniform(*RING, n_extra)
    angle = rng.uniform(0.0, 2.0 * np.pi, n_extra)
    size = np.column_stack([rng.uniform(0.1, 0.5, (n_extra, 2)), rng.uniform(0.1, 1.5, n_extra)])
    extra = []
    for k in range(n_extra):
        # a box's far corner is at most |size|/2 ≈ 0.8 m from its centre: keep it out of reach
        r = radius[k] + 0.5 * float(np.linalg.norm(size[k, :2]))
        xy = base_xy + r * np.array([np.cos(angle[k]), np.sin(angle[k])])
        pose = FixedPose.from_xyz_rpy([xy[0], xy[1], 0.5 * size[k, 2]], [0.0, 0.0, angle[k]])
        extra.append(Obstacle(f"box{k:03d}", Box(size[k]), pose))
    return Scene(
        paper.obstacles + tuple(extra),
        robot_base=paper.robot_base,
        start=paper.start,
        goal=paper.goal,
        name=f"cell{n_boxes}",
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--boxes", type=int, default=200, help="boxes in all (default 200)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--out", default="cell.toml", help="scene file to write")
    args = parser.parse_args()
    cell_scene(args.boxes, args.seed).save(args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
