"""Plan around obstacles of your own: a TOML scene file with a box, a sphere and a pendulum.

Run: ``python examples/custom_scene.py [--gens 30]``. The scene format is in
``docs/scene-files.md``.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import adept_traj as at

SCENE = """
name = "custom"

[robot]                      # the robot base in the world
xyz = [0.0, 0.0, -0.25]
rpy = [0.0, 0.0, 0.0]

[task]                       # theta1 [rad], theta2 [rad], d3 [m], theta4 [rad]
start = [0.9, 1.2, 0.10, 0.0]
goal = [-0.9, 1.2, 0.10, 1.0]

[[obstacle]]                 # a post in front of the robot, below the outer arm
name = "post"
shape = "cylinder"
radius = 0.04
length = 0.6
xyz = [0.72, 0.0, 0.3]

[[obstacle]]
name = "ball"
shape = "sphere"
radius = 0.06
xyz = [0.35, -0.45, 0.25]

[[pendulum]]
name = "pendulum"
pivot = [-0.7, 0.5, 1.6]
length = 1.0
v0 = 2.0
omega = 3.14
bob_radius = 0.06
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--gens", type=int, default=30, help="generations")
    parser.add_argument("--pop", type=int, default=60, help="population")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "custom.toml"
        path.write_text(SCENE)
        scene = at.Scene.from_file(path)
    problem = at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal)
    straight = problem.evaluate_batch(problem.trajectory.straight_line(2.0))
    print(f"obstacles: {scene.names}")
    print(f"straight move: min distance per obstacle {straight.min_distance.round(3)} m")
    result = at.plan(problem, "nsga2", seed=3, pop_size=args.pop, n_gen=args.gens)
    cert = result.certificate
    print(
        f"best trade-off T = {result.best_objectives[0]:.3f} s; verified "
        f"{'feasible' if cert.feasible else 'NOT feasible'} (min distance "
        f"{cert.min_distance:.3f} m)"
    )
    for violation in cert.violations:
        print(f"  {violation}")


if __name__ == "__main__":
    main()
