"""A UR5 (from example-robot-data) swinging around a box, certified, played back in meshcat.

Run: ``python examples/ur5_around_a_box.py [--gens 30] [--pop 60] [--html playback.html]``
(needs ``pip install "adept_traj[robots]"``). The scene file
``examples/data/ur5_box.toml`` names the robot in its ``[robot]`` table (a ``package://``
URDF, found in the installed robot data) and its parameter file ``examples/data/ur5.toml``
(the acceleration and jerk limits the URDF lacks). The collision meshes are replaced by
their convex hulls (sound clearances, see ``docs/your-robot.md``); the playback page shows
the visual meshes. Self-collision is on (the default for a robot with checked link pairs),
with the SRDF of example-robot-data leaving out the link pairs that touch by design.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import adept_traj as at
from adept_traj.robot import installed_data_dirs

DATA = Path(__file__).resolve().parent / "data"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--gens", type=int, default=30, help="generations")
    parser.add_argument("--pop", type=int, default=60, help="population")
    parser.add_argument("--html", type=Path, help="write a meshcat playback page here")
    args = parser.parse_args()
    share = [d for d in installed_data_dirs() if (d / "example-robot-data").is_dir()]
    if not share:
        print('example-robot-data is not installed: pip install "adept_traj[robots]"')
        sys.exit(0)
    scene_file = DATA / "ur5_box.toml"
    robot = at.Robot.from_urdf(
        "package://example-robot-data/robots/ur_description/urdf/ur5_robot.urdf",
        DATA / "ur5.toml",
        srdf=share[0] / "example-robot-data/robots/ur_description/srdf/ur5.srdf",
    )
    scene = at.Scene.from_file(scene_file)
    print(robot, "meshes as hulls:", [h.solid for h in robot.mesh_hulls])
    problem = at.TrajectoryProblem(robot, scene, scene.start, scene.goal)
    result = at.plan(problem, "nsga2", seed=1, pop_size=args.pop, n_gen=args.gens)
    cert = result.certificate
    print(
        f"planned T = {result.best_objectives[0]:.3f} s (lower bound "
        f"{problem.lower_bound.T_min:.3f} s); certified "
        f"{'feasible' if cert.feasible else 'NOT feasible'}; min distance "
        f"{cert.min_distance:.3f} m to {cert.closest_pair}; self-distance "
        f"{cert.self_distance.min_distance:.3f} m ({problem.self_check.n_pairs} link pairs)"
    )
    if args.html is not None:
        from adept_traj.viz import meshcat_scene  # lazy: meshcat is heavy to import

        print("playback:", meshcat_scene.static_html(result, args.html))


if __name__ == "__main__":
    main()
