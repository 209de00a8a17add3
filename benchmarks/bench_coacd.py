"""Closed obstacle meshes: the exact distance (coal's BVH distance to the triangles and the
winding-number inside test, ``adept_traj.collision.mesh_distance``) against a convex
decomposition by coacd (the smallest coal distance to its convex parts).

For each mesh (the shipped example cell's fixture, guard, belt and jig, a tessellated box
of the 200-box cell of ``bench_cells.py``, and a table of 116 160 triangles):

- the decomposition's time and number of parts;
- whether the parts contain the mesh: the largest distance of a mesh vertex outside every
  part (coal: a 1 µm ball at the vertex), which a clearance to the parts over-reports;
- over 2 000 probe poses (a 4 cm cube at random positions and orientations within 10 cm
  of the mesh's box): how often the parts report more clearance than the exact answer
  (a collision reported clear, or a larger positive distance, beyond 1 µm), the largest
  such excess, and the time per distance of each method.

``python benchmarks/bench_coacd.py``; coacd is an optional dependency
(``pip install adept-traj[decomposition]``).
"""

from __future__ import annotations

import datetime
import os
import sys
import time
from pathlib import Path

import coal
import numpy as np
from scipy.spatial.transform import Rotation

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _timing import load_average

from adept_traj.collision.mesh_distance import MeshDistance
from adept_traj.scene import Mesh, Scene
from adept_traj.testing.cad_meshes import box_mesh, table_mesh

N_PROBES = 2000


def meshes() -> dict[str, Mesh]:
    """The meshes measured (see the module docstring)."""
    cell = Scene.shipped("cell")
    out = {ob.name: ob.shape for ob in cell.obstacles if isinstance(ob.shape, Mesh)}
    v, t = box_mesh((0.2, 0.3, 0.25), 7)
    out["cell box (588)"] = Mesh(v, t)
    v, t = table_mesh(subdivisions=44)
    out[f"table ({len(t)})"] = Mesh(v, t)
    return out


def convex_parts(mesh: Mesh) -> tuple[list[coal.ConvexBase], float]:
    """coacd's convex parts (default settings) as coal convexes, and its time [s]."""
    import coacd

    coacd.set_log_level("error")
    t0 = time.perf_counter()
    parts = coacd.run_coacd(coacd.Mesh(mesh.vertices, mesh.triangles.astype(np.int32)))
    elapsed = time.perf_counter() - t0
    out = []
    for vertices, _ in parts:
        pts = coal.StdVec_Vec3s()
        for p in np.asarray(vertices, dtype=float):
            pts.append(p)
        out.append(coal.ConvexBase.convexHull(pts, False, "Qt"))
    return out, elapsed


def outside(mesh: Mesh, parts: list[coal.ConvexBase]) -> float:
    """Largest distance [m] of a mesh vertex outside every part (0: all inside one)."""
    ball, request, at = coal.Sphere(1e-6), coal.DistanceRequest(), coal.Transform3s()
    worst = 0.0
    for p in mesh.vertices:
        tf = coal.Transform3s(np.eye(3), p)
        d = min(coal.distance(ball, tf, part, at, request, coal.DistanceResult()) for part in parts)
        worst = max(worst, d + 1e-6)
    return worst


def probes(mesh: Mesh, rng: np.random.Generator) -> list[coal.Transform3s]:
    """Probe poses within 10 cm of the mesh's box."""
    lo, hi = mesh.local_box
    xyz = rng.uniform(lo - 0.1, hi + 0.1, (N_PROBES, 3))
    rot = Rotation.random(N_PROBES, random_state=int(rng.integers(1 << 31))).as_matrix()
    return [coal.Transform3s(r, p) for r, p in zip(rot, xyz)]


def main() -> None:
    rng = np.random.default_rng(0)
    solid = coal.Box(0.04, 0.04, 0.04)
    request, at = coal.DistanceRequest(), coal.Transform3s()
    print(f"date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC, "
          f"load {load_average()}, {os.cpu_count()} cores; {N_PROBES} probes a mesh")  # fmt: skip
    print("| mesh | triangles | coacd time, parts | vertex outside the parts | "
          "probes over-reported (largest excess) | per distance: exact / parts |")  # fmt: skip
    print("|---|---|---|---|---|---|")
    for name, mesh in meshes().items():
        parts, t_dec = convex_parts(mesh)
        out = outside(mesh, parts)
        exact = MeshDistance(solid, mesh.to_coal(), mesh)
        functors = [coal.ComputeDistance(solid, p) for p in parts]
        poses = probes(mesh, rng)
        d_exact, d_parts = np.empty(len(poses)), np.empty(len(poses))
        t0 = time.perf_counter()
        for i, tf in enumerate(poses):
            d_exact[i] = exact(tf, at, request, coal.DistanceResult())
        t_exact = (time.perf_counter() - t0) / len(poses)
        t0 = time.perf_counter()
        for i, tf in enumerate(poses):
            d_parts[i] = min(f(tf, at, request, coal.DistanceResult()) for f in functors)
        t_parts = (time.perf_counter() - t0) / len(poses)
        clear_wrong = (d_exact <= 0.0) & (d_parts > 1e-6)
        larger = (d_exact > 0.0) & (d_parts > d_exact + 1e-6)
        bad = clear_wrong | larger
        excess = float(np.max(np.where(bad, d_parts - d_exact, 0.0)))
        print(f"| {name} | {mesh.n_triangles} | {t_dec:.1f} s, {len(parts)} | "
              f"{1e6 * out:.1f} µm | {bad.sum()} of {len(poses)} ({clear_wrong.sum()} "
              f"collisions called clear; up to {1e6 * excess:.1f} µm) | "
              f"{1e6 * t_exact:.0f} / {1e6 * t_parts:.0f} µs |")  # fmt: skip


if __name__ == "__main__":
    main()
