"""Robot links with large collision meshes: the link as its convex hull, as the polytope that
replaces a hull of more than 4 000 vertices (the default, ``robot/collision_meshes.py``),
or as its triangle mesh (coal's BVH distance, exact to the triangles).

For the z1 and so101 of example-robot-data (if installed): per variant the links' sizes,
whether each mesh is closed (without an inside test a BVH link is a hollow surface: an
obstacle wholly inside it reads clear), the evaluation rate (60 random decision vectors
of a move beside an 8 cm box, one worker, median of 3) and the certificate's time (the
straight move, 1 kHz).

``python benchmarks/bench_link_meshes.py``
"""

from __future__ import annotations

import datetime
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _timing import load_average

import adept_traj as at
from adept_traj.robot.collision_meshes import triangle_corners
from adept_traj.scene import Mesh, Scene

ROBOTS = {
    "z1": "package://example-robot-data/robots/z1_description/urdf/z1.urdf",
    "so101": "package://example-robot-data/robots/so_arm_description/urdf/so101.urdf",
}


def variant(urdf: str, kind: str) -> tuple[at.Robot, list[str]]:
    """The robot with its simplified links as polytopes (``"polytope"``), exact hulls
    (``"hull"``) or meshes (``"mesh"``), and a note per simplified link."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = at.Robot.from_urdf(urdf)
    notes = []
    objects = {g.name: g for g in robot.collision_model.geometryObjects}
    for report in robot.mesh_hulls:
        if report.simplified_from is None:
            continue
        mesh, _ = report.shapes
        corners = triangle_corners(mesh)
        flat = corners.reshape(-1, 3)
        closed = Mesh(flat, np.arange(len(flat)).reshape(-1, 3)).closed  # welded inside
        shut = "closed" if closed else "open"
        notes.append(f"{report.solid}: {report.mesh_triangles} triangles, hull "
                     f"{report.simplified_from} vertices, polytope {report.hull_points} "
                     f"(+{1e3 * report.extra:.1f} mm), mesh {shut}")  # fmt: skip
        if kind == "hull":
            objects[report.solid].geometry = mesh.convex
        elif kind == "mesh":
            objects[report.solid].geometry = mesh
    return robot, notes


def measure(robot: at.Robot) -> tuple[float, float]:
    """(evaluations per second, certificate time [s]) of a move beside a box."""
    lo, hi = np.clip(robot.limits.lower, -2, 2), np.clip(robot.limits.upper, -2, 2)
    start, goal = lo + 0.3 * (hi - lo), lo + 0.6 * (hi - lo)
    a, b = robot.tool_pose(start)[:3, 3], robot.tool_pose(goal)[:3, 3]
    side = np.cross(b - a, [0.0, 0.0, 1.0])
    where = 0.5 * (a + b) + 0.12 * side / max(np.linalg.norm(side), 1e-9)
    box = {"name": "box", "shape": "box", "size": [0.08] * 3, "xyz": where.tolist()}
    scene = Scene.from_dict({"name": "box", "obstacle": [box]})
    problem = at.TrajectoryProblem(robot, scene, start, goal, workers=1)
    rng = np.random.default_rng(0)
    x = problem.xl + (problem.xu - problem.xl) * rng.uniform(size=(60, problem.n_var))
    problem.evaluate_batch(x[:5])
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        problem.evaluate_batch(x)
        times.append(time.perf_counter() - t0)
    t0 = time.perf_counter()
    at.certify(problem, problem.trajectory.straight_line(2.0), rate_hz=1000.0)
    cert = time.perf_counter() - t0
    problem.close()
    return len(x) / statistics.median(times), cert


def main() -> None:
    print(f"date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, "
          f"load {load_average()}")  # fmt: skip
    print("| robot | links as | evaluations/s | certificate (1 kHz) |")
    print("|---|---|---|---|")
    for name, urdf in ROBOTS.items():
        for kind in ("polytope", "hull", "mesh"):
            try:
                robot, notes = variant(urdf, kind)
            except at.AdeptTrajError as exc:
                print(f"| {name} | {kind} | not loaded: {exc} | |")
                break
            rate, cert = measure(robot)
            print(f"| {name} | {kind} | {rate:.0f} | {cert:.2f} s |")
        for note in notes:
            print(f"  {name} {note}")


if __name__ == "__main__":
    main()
