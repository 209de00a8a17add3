"""The detour scene (docs/detour-scene.md): evolutionary search alone, time-optimal mode
alone, and the search with its polish (issue #12).

Run: ``python benchmarks/bench_detour.py [--seeds 1,2,3] [--workers 1]``.

On the shipped detour scene (a post on the straight move's path, the pendulum across the
arm's way on fast moves), per seed: NSGA-II at the paper's budget (100 × 100) without the
polish (``plan(..., polish=False)``) and with it (the default), and the time-optimal
mode (``plan(problem, "time-optimal")``, no evolutionary search; on this scene its straight
and ramp starts end in the post, and it falls back to feasible detour starts). Prints the
fastest certified travel time, its ratio to the kinematic lower bound T_lb, the run's
T_best (``result.metrics.t_best``: the best T its local solver reached; ``-``: not
computed), the certified members and the wall time of each run. The paper scene's fastest
moves reach 1.0036 × T_lb with the polish (``benchmarks/bench_polish.py``); here the
obstacles bind, and the table shows how far each method gets. Takes a few minutes
(≈ 2 × 20 s + 5–20 s per seed on one core).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _results import recorded  # benchmarks/_results.py

from adept_traj import Robot, Scene, TrajectoryProblem, plan


def fastest(result) -> tuple[float, int, int]:
    """(fastest certified T [s] or NaN, certified members, front size)."""
    ok = result.front.feasible
    T = result.front.x[ok, 0]
    return (float(T.min()) if len(T) else float("nan"), int(ok.sum()), len(ok))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", default="1,2,3", help="comma-separated random seeds")
    parser.add_argument("--workers", type=int, default=1, help="evaluation processes")
    args = parser.parse_args()
    scene = Scene.shipped("detour")
    problem = TrajectoryProblem(
        Robot.adept_one_xl(), scene, scene.start, scene.goal, workers=args.workers
    )
    bound = problem.lower_bound.T_min
    print(f"detour scene, T_lb = {bound:.4f} s, {args.workers} worker(s)")
    print(
        f"{'run':<28}{'seed':>5}{'fastest T [s]':>15}{'/ T_lb':>8}{'T_best [s]':>12}"
        f"{'certified':>12}{'wall s':>8}"
    )
    seeds = [int(s) for s in args.seeds.split(",")]
    runs = [("time-optimal mode", "time-optimal", {}, seeds)]
    runs += [("NSGA-II, no polish", "nsga2", {"polish": False}, seeds)]
    runs += [("NSGA-II + polish", "nsga2", {"polish": True}, seeds)]
    for label, algorithm, options, run_seeds in runs:
        for seed in run_seeds:
            tic = time.perf_counter()
            result = plan(problem, algorithm, seed=seed, **options)
            wall = time.perf_counter() - tic
            T, n_ok, n = fastest(result)
            ratio = T / bound if np.isfinite(T) else float("nan")
            t_best = result.metrics.t_best
            best = "-" if t_best is None else f"{t_best:.4f}"
            print(
                f"{label:<28}{seed:>5}{T:>15.4f}{ratio:>8.3f}{best:>12}{f'{n_ok}/{n}':>12}"
                f"{wall:>8.1f}"
            )
    problem.close()


if __name__ == "__main__":
    with recorded(
        __file__,
        "the detour scene: the search alone, the time-optimal mode, the search with its polish",
    ):
        main()
