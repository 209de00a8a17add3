"""A plain check of the unseen benchmark scenes (issue #24): the straight move collides,
and a certified move exists.

Run: ``python benchmarks/check_scenes.py [benchmarks/scenes/*.toml]``.

For each scene file: the straight joint-space move at five travel times, certified
(``adept_traj.certify``) against the whole scene and against its fixed obstacles alone (the
wall or the post must block it without the pendulums); then the scene's stored reference
move (``benchmarks/reference/reference_vectors.json``, by the file's stem) certified at
1 kHz with the continuous bound and its distances re-checked at 4 kHz by a plain loop —
Pinocchio placements and one ``coal.distance`` per (robot solid, obstacle) pair and
sample, the pendulums at their pose at that instant, sharing no code with the checker but
the libraries. Exit status 1 if a check fails.
"""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin

import adept_traj as at

VECTORS = Path(__file__).parent / "reference" / "reference_vectors.json"
SCENES = sorted((Path(__file__).parent / "scenes").glob("*.toml"))


def coal_min_distance(
    problem: at.TrajectoryProblem, x: np.ndarray, rate_hz: float, start_time: float = 0.0
):
    """(smallest distance [m], time [s] from the move's start, pair) of move x by coal
    called pair by pair; the obstacles at the scene's clock ``start_time + t`` [s]."""
    T = float(x[0])
    t = np.linspace(0.0, T, int(np.ceil(T * rate_hz)) + 1)
    q = problem.trajectory.sample(x, t / T, orders=(0,)).q
    robot, scene = problem.robot, problem.scene
    model, gm = robot.model, robot.collision_model
    data, gdata = model.createData(), gm.createData()
    shapes = [ob.shape.to_coal() for ob in scene.obstacles]
    poses = scene.obstacle_poses(start_time + t, in_base_frame=True)  # (n_obstacles, n, 4, 4)
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    request.gjk_tolerance = 1e-9
    best = (np.inf, 0.0, ("", ""))
    for k in range(t.size):
        pin.updateGeometryPlacements(model, data, gm, gdata, q[k])
        for o, shape in enumerate(shapes):
            tf_o = coal.Transform3s(poses[o, k, :3, :3], poses[o, k, :3, 3])
            for g, obj in enumerate(gm.geometryObjects):
                placement = gdata.oMg[g]
                tf_g = coal.Transform3s(placement.rotation, placement.translation)
                result.clear()
                d = coal.distance(obj.geometry, tf_g, shape, tf_o, request, result)
                if d < best[0]:
                    best = (d, t[k], (obj.name, scene.obstacles[o].name))
    return best


def check(path: Path, vectors: dict) -> bool:
    """Print the checks of one scene file; True if all pass."""
    scene = at.Scene.from_file(path)
    robot = at.Robot.adept_one_xl()
    problem = at.TrajectoryProblem(robot, scene, scene.start, scene.goal)
    fixed_scene = dataclasses.replace(scene, obstacles=scene.fixed)
    fixed = at.TrajectoryProblem(robot, fixed_scene, scene.start, scene.goal)
    ok = True
    print(f"{path}:")
    t_lo, t_hi = float(problem.xl[0]), float(problem.xu[0])
    for T in np.linspace(t_lo * 1.05, t_hi, 5):
        x = problem.trajectory.straight_line(T)
        for label, prob in (("whole scene", problem), ("fixed obstacles", fixed)):
            c = at.certify(prob, x)
            print(
                f"  straight T = {T:.3f} s, {label:<15}: "
                f"{'CERTIFIED (unexpected)' if c.feasible else 'not certified'}, "
                f"d_min {c.min_distance:+.4f} m at {c.t_min_distance:.3f} s {c.closest_pair}"
            )
            ok &= not c.feasible
    stored = vectors.get(path.stem)
    if stored is None:
        print("  no stored reference move")
        return False
    x = np.array(stored["x"], dtype=float)
    c = at.certify(problem, x)
    d, t, pair = coal_min_distance(problem, x, 4000.0)
    print(
        f"  reference move T = {x[0]:.5f} s: certified {c.feasible} ({c.guarantee}), "
        f"d_min {c.min_distance:+.5f} m; coal pair by pair at 4 kHz: {d:+.5f} m at "
        f"{t:.4f} s {pair} (margin {problem.settings.margin} m)"
    )
    return ok and c.feasible and d >= problem.settings.margin


def main() -> None:
    paths = [Path(p) for p in sys.argv[1:]] or SCENES
    vectors = json.loads(VECTORS.read_text()) if VECTORS.exists() else {}
    results = [check(path, vectors) for path in paths]
    print("all checks passed" if all(results) else "A CHECK FAILED")
    raise SystemExit(0 if all(results) else 1)


if __name__ == "__main__":
    main()
