"""Paper-scale runs of the engine on the paper scenario: wall time, quality, verification.

Run: ``python benchmarks/bench_engine.py [--workers 2] [--seeds 1,2,3]``.

NSGA-II at the paper's settings (100 × 100 = 10⁴ evaluations) and MODE (500 × 100 =
5 × 10⁴ evaluations) on the same problem and seed. Prints, per algorithm: wall time, time
spent evaluating, optimiser overhead, the hypervolume of each feasible front on common
bounds (reference point 1.1 in normalised space), the number of feasible front members, and
the best trade-off's travel time against the kinematic lower bound with its dense (1 kHz)
verification. Targets (issue): NSGA-II ≤ 10 s, MODE ≤ 40 s, best z1 ≤ 1.15 × the bound.
With several seeds, one block per seed (the fast end of the front varies from seed to seed).
"""

from __future__ import annotations

import argparse

import numpy as np
from _results import figure, recorded  # benchmarks/_results.py

from adept_traj import Robot, Scene, TrajectoryProblem, certify, plan
from adept_traj.analysis import normalised_hypervolume, objective_bounds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", type=int, default=2, help="evaluation processes")
    parser.add_argument("--seeds", default="1", help="comma-separated random seeds")
    parser.add_argument("--gens", type=int, default=None, help="generations (default 100)")
    args = parser.parse_args()
    scene = Scene.paper()
    problem = TrajectoryProblem(
        Robot.adept_one_xl(), scene, scene.start, scene.goal, workers=args.workers
    )
    for seed in (int(s) for s in args.seeds.split(",")):
        run_seed(problem, seed, args)
    problem.close()


def run_seed(problem: TrajectoryProblem, seed: int, args: argparse.Namespace) -> None:
    results = {}
    for name in ("nsga2", "mode"):
        results[name] = plan(problem, name, seed=seed, n_gen=args.gens)
    fronts = [r.feasible_front.objectives for r in results.values() if len(r.feasible_front)]
    lo, hi = objective_bounds(*fronts) if fronts else (None, None)
    bound = problem.lower_bound.T_min
    print(f"paper scenario, seed {seed}, {args.workers} evaluation workers")
    print(f"kinematic lower bound on T: {bound:.3f} s")
    print(
        f"{'algorithm':<10}{'evals':>8}{'wall s':>9}{'eval s':>9}{'OO':>7}{'HV':>9}"
        f"{'front':>7}{'feasible':>10}{'trade-off T':>12}{'fastest T':>11}{'T/bound':>9}"
        f"{'verified':>10}"
    )
    for name, r in results.items():
        front = r.feasible_front.objectives
        hv = normalised_hypervolume(front, lo, hi) if len(front) else float("nan")
        # The fastest member of the front, verified on its own 1 kHz grid.
        fastest = int(np.argmin(r.front.objectives[:, 0]))
        cert = certify(problem, r.front.x[fastest])
        t_fast = r.front.objectives[fastest, 0]
        print(
            f"{name:<10}{r.timing.n_evaluations:>8}{r.timing.total_s:>9.1f}"
            f"{r.timing.evaluation_s:>9.1f}{r.metrics.oo:>7.3f}{hv:>9.4f}{len(r.front):>7}"
            f"{len(front):>10}{r.best_objectives[0]:>12.3f}{t_fast:>11.3f}"
            f"{t_fast / bound:>9.2f}{'yes' if cert.feasible else 'NO':>10}"
        )
        target = 10.0 if name == "nsga2" else 40.0
        wall = r.timing.total_s
        figure(
            f"{name}_wall_seed{seed}", f"{name} wall time, seed {seed}", round(wall, 1), "s",
            target=f"≤ {target:.0f} s", met=wall <= target,
            note=f"{r.timing.n_evaluations} evaluations, {args.workers} workers",
        )  # fmt: skip
        figure(
            f"{name}_fastest_seed{seed}", f"{name} fastest verified T / T_lb, seed {seed}",
            round(t_fast / bound, 2), "×", target="≤ 1.15×",
            met=bool(cert.feasible) and t_fast / bound <= 1.15,
            note=f"T = {t_fast:.3f} s, T_lb = {bound:.3f} s",
        )  # fmt: skip


if __name__ == "__main__":
    with recorded(__file__, "the engine at paper scale: NSGA-II and MODE, wall time and quality"):
        main()
