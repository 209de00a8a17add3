"""Plan the paper's scenario with NSGA-II and MODE and compare them.

Run: ``python examples/plan_paper.py [--gens 100] [--out out/paper]`` (the paper's budget is
100 generations; CI runs it with ``--gens 3 --small``).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import adept_traj as at


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--gens", type=int, default=100, help="generations")
    parser.add_argument("--small", action="store_true", help="small populations (CI)")
    parser.add_argument("--out", type=Path, default=Path("out/paper"), help="output folder")
    args = parser.parse_args()
    scene = at.Scene.paper()
    problem = at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal)
    print(f"kinematic lower bound on T: {problem.lower_bound.T_min:.3f} s")
    for name, paper_pop in (("nsga2", 100), ("mode", 500)):
        pop = 16 if args.small else paper_pop
        result = at.plan(problem, name, seed=1, pop_size=pop, n_gen=args.gens)
        result.save(args.out / name)
        z = result.best_objectives
        print(
            f"{name}: {result.timing.n_evaluations} evaluations in {result.timing.total_s:.1f} s;"
            f" best trade-off T = {z[0]:.3f} s, verified "
            f"{'feasible' if result.feasible else 'NOT feasible'}; saved to {args.out / name}"
        )


if __name__ == "__main__":
    main()
