"""Real cells: evaluation rates of mesh obstacles, point clouds and machines that move,
each against the paper scene (or a fixed obstacle) in the same run, alternately.

- a cell of 200 fixed mesh obstacles: the paper's two cubes as tessellated meshes
  (588 triangles each) and 198 more tessellated boxes out of the arm's reach (as
  ``benchmarks/cell_scene.py``), ≥ 100 000 triangles in all, with the pendulum: rate vs
  the paper scene (target ≥ 0.3×);
- a point cloud of 10⁶ points (octree at 1 cm) beside the path, with the paper's
  obstacles: rate vs the paper scene (target ≥ 0.2×), if point clouds are available;
- each motion law (conveyor, turntable, recorded trajectory) moving a box next to the
  path vs the same box fixed: time per evaluation (target ≤ 1.5×).

``python benchmarks/bench_cells.py [--pop 200] [--repeat 5] [--cloud-radius R ...]``; one
worker throughout; the clouds' ratios from CPU times (the process's own).
"""

from __future__ import annotations

import argparse
import datetime
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _results import figure, recorded  # benchmarks/_results.py
from _timing import load_average
from cell_scene import cell_scene

import adept_traj as at
from adept_traj.scene import (
    Box,
    FixedPose,
    LinearMotion,
    Mesh,
    Obstacle,
    RecordedMotion,
    RotationMotion,
    Scene,
)
from adept_traj.testing.cad_meshes import box_mesh
from adept_traj.transforms import transform_from_xyz_rpy


def mesh_cell(subdivisions: int = 7) -> Scene:
    """:func:`cell_scene` (200) with every box a tessellated mesh of the same box."""
    unit_v, unit_t = box_mesh((1.0, 1.0, 1.0), subdivisions)
    cell = cell_scene(200)
    obstacles = []
    for ob in cell.obstacles:
        if isinstance(ob.shape, Box) and not ob.is_moving:
            mesh = Mesh(unit_v * ob.shape.size, unit_t)
            obstacles.append(Obstacle(ob.name, mesh, ob.motion, ob.offset))
        else:
            obstacles.append(ob)
    return Scene(tuple(obstacles), robot_base=cell.robot_base, start=cell.start, goal=cell.goal)


def machines(paper: Scene) -> dict[str, Scene]:
    """The paper scene plus one 10 cm box beside the straight path, fixed or moved."""
    where = (0.45, 1.0, 0.85)  # world; above the paper's straight move (see tests)
    laws = {
        "fixed": FixedPose(np.eye(4)),
        "linear": LinearMotion([0.3, 0.0, 0.0], wrap=0.2),
        "rotation": RotationMotion([0, 0, 1], [0.45, 0.9, 0.0], omega=0.5),
        "recorded": RecordedMotion(
            [0.0, 1.0, 2.0, 3.0],
            [[0, 0, 0], [0.1, 0, 0], [0.1, 0.05, 0], [0, 0, 0]],
            [[0, 0, 0], [0, 0, 0.3], [0, 0.1, 0.3], [0, 0, 0]],
            periodic=True,
        ),
    }
    box = Box([0.1, 0.1, 0.1])
    out = {}
    for name, law in laws.items():
        ob = Obstacle("machine", box, law, transform_from_xyz_rpy(where))
        out[name] = Scene(
            (*paper.obstacles, ob), robot_base=paper.robot_base, start=paper.start, goal=paper.goal
        )
    return out


def timed(problem, x) -> tuple[float, float]:
    """Wall and CPU time [s] of one batch evaluation (one worker: the CPU time is the
    process's own, less distorted by other load on the machine)."""
    t0, c0 = time.perf_counter(), time.process_time()
    problem.evaluate_batch(x)
    return time.perf_counter() - t0, time.process_time() - c0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pop", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--no-cloud", action="store_true", help="skip the point cloud")
    parser.add_argument(
        "--cloud-radius", type=float, nargs="+", default=[1.1],
        help="the fence's distances from the base axis [m], one cloud each (1.0: the arm's "
        "boxes within 5 cm of it at many samples; 0.97: every motion's within 3.4–3.7 cm)",
    )  # fmt: skip
    args = parser.parse_args()
    robot, paper = at.Robot.adept_one_xl(), Scene.paper()
    problems = {"paper": at.TrajectoryProblem(robot, paper, paper.start, paper.goal, workers=1)}
    t0 = time.perf_counter()
    cell = mesh_cell()
    n_tri = sum(ob.shape.n_triangles for ob in cell.obstacles if isinstance(ob.shape, Mesh))
    problems["mesh cell"] = at.TrajectoryProblem(robot, cell, cell.start, cell.goal, workers=1)
    built = time.perf_counter() - t0
    cloud_note: dict[str, str] = {}
    if not args.no_cloud:
        from bench_cloud import cloud_scene

        for radius in args.cloud_radius:
            t1 = time.perf_counter()
            scene = cloud_scene(paper, radius=radius)
            problems[f"cloud {radius}"] = at.TrajectoryProblem(
                robot, scene, scene.start, scene.goal, workers=1
            )
            cloud_note[f"cloud {radius}"] = f"built in {time.perf_counter() - t1:.1f} s"
    for name, scene in machines(paper).items():
        problems[name] = at.TrajectoryProblem(robot, scene, scene.start, scene.goal, workers=1)
    rng = np.random.default_rng(0)
    base = problems["paper"]
    x = base.xl + (base.xu - base.xl) * rng.uniform(size=(args.pop, base.n_var))
    times: dict[str, list[float]] = {k: [] for k in problems}
    cpu: dict[str, list[float]] = {k: [] for k in problems}
    for p in problems.values():
        p.evaluate_batch(x[:20])  # warm-up
    for i in range(args.repeat):
        order = list(problems) if i % 2 == 0 else list(reversed(problems))
        for name in order:
            wall, used = timed(problems[name], x)
            times[name].append(wall)
            cpu[name].append(used)
    med = {k: statistics.median(v) for k, v in times.items()}
    med_cpu = {k: statistics.median(v) for k, v in cpu.items()}
    print(f"date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, "
          f"load {load_average()}, {os.cpu_count()} cores; population {args.pop}, "
          f"{args.repeat} alternating runs, medians")  # fmt: skip
    rate = {k: args.pop / v for k, v in med.items()}
    print("| figure | measured | target |")
    print("|---|---|---|")
    share = rate["mesh cell"] / rate["paper"]
    print(f"| 200 meshes ({n_tri} triangles) vs paper | {share:.2f}× ({rate['mesh cell']:.0f}/s "
          f"vs {rate['paper']:.0f}/s; built in {built:.1f} s) | ≥ 0.3× |")  # fmt: skip
    figure("mesh_cell", f"200 meshes ({n_tri} triangles) vs the paper scene, evaluations/s",
           round(share, 2), "×", target="≥ 0.3×", met=share >= 0.3)  # fmt: skip
    for i, name in enumerate(cloud_note):
        radius = name.split()[1]
        share = rate[name] / rate["paper"]
        share_cpu = med_cpu["paper"] / med_cpu[name]
        print(f"| 10⁶-point cloud at {radius} m, 1 cm octree vs paper | "
              f"{share:.2f}× wall, {share_cpu:.2f}× CPU ({rate[name]:.0f}/s; CPU "
              f"{med_cpu[name]:.3f} s vs {med_cpu['paper']:.3f} s a batch; "
              f"{cloud_note[name]}) | ≥ 0.2× |")  # fmt: skip
        key = "cloud" if i == 0 else f"cloud_{radius}"
        figure(key, f"10⁶-point cloud {radius} m from the base axis, 1 cm octree, vs the "
               "paper scene, evaluations/s (CPU time)", round(share_cpu, 3), "×",
               target="≥ 0.2×", met=share_cpu >= 0.2)  # fmt: skip
    for name in ("linear", "rotation", "recorded"):
        total = med[name] / med["fixed"]
        print(f"| {name} box vs the same box fixed, per evaluation | {total:.2f}× "
              f"({1e3 * med[name] / args.pop:.2f} vs {1e3 * med['fixed'] / args.pop:.2f} ms) "
              "| ≤ 1.5× |")  # fmt: skip
        figure(name, f"{name} box vs the same box fixed, time per evaluation", round(total, 2),
               "×", target="≤ 1.5×", met=total <= 1.5)  # fmt: skip


if __name__ == "__main__":
    with recorded(
        __file__,
        "real cells: meshes, point clouds and moving machines vs the paper scene (issue #28)",
    ):
        main()
