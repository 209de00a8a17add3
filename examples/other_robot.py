"""Another robot from a URDF: a planar two-link arm (``examples/data/planar_2link.urdf``).

Run: ``python examples/other_robot.py [--gens 20]``. The arm moves in the x–z plane (its
joints turn about −y); its parameter file gives the acceleration and jerk limits, a rotor
inertia and the task rows (v_x, v_z) for the manipulability.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import adept_traj as at

DATA = Path(__file__).resolve().parent / "data"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--gens", type=int, default=20, help="generations")
    parser.add_argument("--pop", type=int, default=40, help="population")
    args = parser.parse_args()
    robot = at.Robot.from_urdf(DATA / "planar_2link.urdf", DATA / "planar_2link.toml")
    print(robot, robot.limits.names, "armature", robot.model.armature)
    q = np.array([[0.3, 0.9], [1.0, -0.4]])
    print("tool positions [m]:", robot.tool_pose(q)[:, :3, 3].round(3).tolist())
    print("manipulability [m²]:", robot.manipulability(q).round(4).tolist())
    # A sphere on the hand's straight path, in the arm's plane (y = 0): folding the elbow
    # while passing avoids it.
    scene = at.Scene(
        obstacles=(
            at.Obstacle("ball", at.Sphere(0.06), at.FixedPose.from_xyz_rpy((0.67, 0.0, 0.67))),
        )
    )
    start, goal = np.array([-0.2, 0.6]), np.array([1.4, 0.4])
    problem = at.TrajectoryProblem(robot, scene, start, goal, n_knots=10)
    result = at.plan(problem, "nsga2", seed=2, pop_size=args.pop, n_gen=args.gens)
    print(
        f"planned T = {result.best_objectives[0]:.3f} s (lower bound "
        f"{problem.lower_bound.T_min:.3f} s); verified "
        f"{'feasible' if result.feasible else 'NOT feasible'}; min distance "
        f"{result.certificate.min_distance:.3f} m"
    )


if __name__ == "__main__":
    main()
