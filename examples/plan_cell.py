"""Plan the example work cell (``docs/example-cell.md``): the paper's robot and task among
CAD meshes (a table fixture, a guard, a conveyor's belt), three parts riding the belt, a
jig on a turntable and a second robot swinging its arm away (its 7 solids moving
obstacles ``robotA.*``); certify the best move in continuous time and re-verify the saved result.

Run: ``python examples/plan_cell.py [--pop 40] [--gens 30] [--out out/cell]``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import adept_traj as at
from adept_traj.cli.app import main as adept_traj_main


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pop", type=int, default=40, help="population (default 40)")
    parser.add_argument("--gens", type=int, default=30, help="generations (default 30)")
    parser.add_argument("--out", type=Path, default=Path("out/cell"), help="output folder")
    args = parser.parse_args()
    scene = at.Scene.shipped("cell")
    for ob in scene.obstacles:
        kind = type(ob.shape).__name__
        moves = type(ob.motion).__name__ if ob.is_moving else "fixed"
        size = f", {ob.shape.n_triangles} triangles" if isinstance(ob.shape, at.Mesh) else ""
        print(f"  {ob.name:8s} {kind}{size}, {moves}")
    problem = at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal)
    result = at.plan(problem, "nsga2", seed=1, pop_size=args.pop, n_gen=args.gens)
    result.save(args.out)
    cert = result.certificate
    print(
        f"best trade-off T = {result.best_objectives[0]:.3f} s: "
        f"{'FEASIBLE' if cert.feasible else 'NOT feasible'}, distance {cert.guarantee} "
        f"(bound {cert.distance_bound:.4f} m, margin {cert.margin} m); saved to {args.out}"
    )
    # the saved result re-verified from its files, as a user would: exit code 0 = certified
    code = adept_traj_main(["verify", str(args.out)])
    raise SystemExit(code)


if __name__ == "__main__":
    main()
