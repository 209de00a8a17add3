"""Gradient-based polish and the time-optimal mode on the paper scenario (issue #12).

Run: ``python benchmarks/bench_polish.py [--seeds 1,2,3,4,5] [--algorithms nsga2,mode]
[--skip-runs]``.

1. **Time-optimal mode**, the command as a user types it, whole process:
   ``adept-traj plan --algorithm time-optimal --out DIR --no-html --no-plots`` (wall time,
   median of 3), and ``plan(problem, algorithm="time-optimal")`` in process (its own
   figures: T, T / T_lb, solve time, certificate). Target: T ≤ 1.001 × 1.0766 s (Drake's,
   SNOPT) in ≤ 1 s wall on one core. Also the straight start alone
   (``time_optimal(problem, n_starts=1)``) and one evaluation of the smooth constraints
   and their Jacobian (``local_constraints``, what SLSQP calls each iteration).
2. **Polish inside plan** at the paper budgets (one evaluation process), per seed: the
   fastest certified T / T_lb with and without polish, the hypervolume of both fronts on
   common bounds, and the polish's share of the run's time (the polish timed alone:
   SLSQP from the unpolished run's fastest feasible member, as ``plan`` does it, plus its
   certificate; the two runs' totals differ by machine noise as much as by the polish).
   Targets: fastest certified T ≤ 1.005 × T_lb, HV(polished) ≥ HV(unpolished) on every
   seed, polish ≤ 25 % of the run. This part takes minutes (≈ 2 × 16 s per NSGA-II seed,
   ≈ 2 × 60 s per MODE).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from adept_traj import Robot, Scene, TrajectoryProblem, certify, plan
from adept_traj.analysis import normalised_hypervolume, objective_bounds
from adept_traj.optimise import minimum_time, time_optimal
from adept_traj.problem import local_constraints

#: Drake's KinematicTrajectoryOptimization with SNOPT on the paper scene (issue #12) [s].
DRAKE_T = 1.0766


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", default="1,2,3,4,5", help="comma-separated random seeds")
    parser.add_argument("--algorithms", default="nsga2", help="comma-separated, e.g. nsga2,mode")
    parser.add_argument("--skip-runs", action="store_true", help="only the time-optimal part")
    args = parser.parse_args()
    scene = Scene.paper()
    problem = TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)
    time_optimal_part(problem)
    if not args.skip_runs:
        for name in args.algorithms.split(","):
            polish_part(problem, name, [int(s) for s in args.seeds.split(",")])


def time_optimal_part(problem: TrajectoryProblem) -> None:
    bound = problem.lower_bound.T_min
    walls = []
    for _ in range(3):
        with tempfile.TemporaryDirectory() as tmp:
            cmd = ["adept-traj", "plan", "--algorithm", "time-optimal", "--out", str(Path(tmp))]
            t0 = time.perf_counter()
            subprocess.run([*cmd, "--no-html", "--no-plots"], check=True, capture_output=True)
            walls.append(time.perf_counter() - t0)
    print("time-optimal mode, paper scene (pendulum included)")
    shown = ", ".join(f"{w:.2f}" for w in walls)
    print(
        f"  adept-traj plan --algorithm time-optimal: median wall {statistics.median(walls):.2f}"
        f" s (whole process, 3 runs: {shown})"
    )
    t0 = time.perf_counter()
    result = plan(problem, algorithm="time-optimal")
    wall = time.perf_counter() - t0
    T = float(result.best_x[0])
    print(
        f"  plan(..., 'time-optimal'): T = {T:.5f} s = {T / bound:.4f} × T_lb = "
        f"{T / DRAKE_T:.5f} × Drake's; solve {result.timing.total_s:.2f} s, plan {wall:.2f} s "
        f"(with certificates), {result.timing.n_evaluations} evaluations, certified: "
        f"{result.feasible}  [target T ≤ {1.001 * DRAKE_T:.4f} s in ≤ 1 s]"
    )
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        (out,) = time_optimal(problem, n_starts=1)
        times.append(time.perf_counter() - t0)
    ok = certify(problem, out.x).certified
    print(
        f"  straight start only: T = {out.x[0]:.5f} s in {statistics.median(times):.2f} s "
        f"(median of 3), {out.n_iterations} SLSQP iterations, certified: {ok}"
    )
    calls = []
    for x in (out.start, out.x) * 10:
        t0 = time.perf_counter()
        local_constraints(problem, x)
        calls.append(time.perf_counter() - t0)
    print(
        f"  local_constraints (values and Jacobian, {problem.n_var} variables): "
        f"{1000 * statistics.median(calls):.1f} ms a call (median of 20)"
    )


def polish_part(problem: TrajectoryProblem, name: str, seeds: list[int]) -> None:
    bound = problem.lower_bound.T_min
    print(f"\n{name} at the paper budget, one process; T_lb = {bound:.4f} s")
    print(
        f"{'seed':>4}{'T/T_lb raw':>12}{'T/T_lb pol':>12}{'HV raw':>9}{'HV pol':>9}"
        f"{'total raw s':>12}{'total pol s':>12}{'polish s':>9}{'polish %':>9}{'+evals':>7}"
    )
    for seed in seeds:
        raw = plan(problem, name, seed=seed, polish=False)
        pol = plan(problem, name, seed=seed, polish=True)
        fronts = [r.feasible_front.objectives for r in (raw, pol)]
        lo, hi = objective_bounds(*fronts)
        hv = [normalised_hypervolume(f, lo, hi) for f in fronts]
        fastest = [float(r.feasible_front.objectives[:, 0].min()) / bound for r in (raw, pol)]
        # The polish alone, as plan runs it (same start: same seed, same population).
        ok = np.flatnonzero(np.all(raw.front.constraints <= 0.0, axis=1))
        start = raw.front.x[ok[np.argmin(raw.front.x[ok, 0])]]
        t0 = time.perf_counter()
        out = minimum_time(problem, start, max_iter=30)
        certify(problem, out.x, exact=False)
        polish_s = time.perf_counter() - t0
        share = 100.0 * polish_s / (raw.timing.total_s + polish_s)
        extra = pol.timing.n_evaluations - raw.timing.n_evaluations
        print(
            f"{seed:>4}{fastest[0]:>12.4f}{fastest[1]:>12.4f}{hv[0]:>9.4f}{hv[1]:>9.4f}"
            f"{raw.timing.total_s:>12.2f}{pol.timing.total_s:>12.2f}{polish_s:>9.2f}{share:>9.1f}"
            f"{extra:>7}"
        )
        sys.stdout.flush()
    print("targets: T/T_lb pol ≤ 1.005, HV pol ≥ HV raw, polish ≤ 25 %")


if __name__ == "__main__":
    np.set_printoptions(precision=4)
    main()
