"""Robot dynamics of the AdeptOne XL: torques, friction and manipulability along a move.

Run: ``python examples/robot_dynamics.py``.
"""

from __future__ import annotations

import numpy as np

import adept_traj as at


def main() -> None:
    robot = at.Robot.adept_one_xl()
    scene = at.Scene.paper()
    # A rest-to-rest B-spline move from the paper's start to its goal in 1.3 s.
    trajectory = at.BSplineTrajectory(scene.start, scene.goal)
    x = trajectory.straight_line(1.3)
    samples = trajectory.sample(x, np.linspace(0.0, 1.0, 201))
    tau = robot.inverse_dynamics(samples.q, samples.qd, samples.qdd)  # (201, 4) [N·m | N]
    w = robot.manipulability(samples.q)  # (201,) [m²]
    print(f"{robot.name}: {robot.nq} joints {robot.joint_names}")
    print(f"rotor inertia (armature) {robot.model.armature}  viscous {robot.model.damping}")
    for k, name in enumerate(robot.joint_names):
        unit = "N" if robot.limits.units[k] == "m" else "N·m"
        peak = np.abs(tau[:, k]).max()
        print(
            f"  {name}: peak |τ| = {peak:7.2f} {unit} ({peak / robot.limits.torque[k]:.0%} of UC)"
        )
    print(f"manipulability along the move: {w.min():.4f} … {w.max():.4f} m²")
    bound = at.kinematic_lower_bound(
        scene.start, scene.goal, robot.limits.velocity, robot.limits.acceleration, robot.limits.jerk
    )
    print(f"kinematic lower bound on T: {bound.T_min:.3f} s (joint {bound.limiting_joint + 1})")


if __name__ == "__main__":
    main()
