"""Gradient-based polish and the time-optimal mode on the paper scenario (issue #12).

Run: ``python benchmarks/bench_polish.py [--seeds 1,2,3,4,5] [--algorithms nsga2,mode]
[--skip-runs] [--quick]`` (``--quick``: seed 1, 20 generations, no whole-process timing: a
check that everything runs, not the targets).

1. **Time-optimal mode**, the command as a user types it, whole process:
   ``adept-traj plan --algorithm time-optimal --out DIR --no-html --no-plots`` (wall time,
   median of 3), and ``plan(problem, algorithm="time-optimal")`` in process (its own
   figures: T, T / T_lb, solve time, certificate). Target: T ≤ 1.001 × 1.0766 s (Drake's,
   SNOPT) in ≤ 1 s wall on one core. Also the straight start alone
   (``time_optimal(problem, n_starts=1)``) and one evaluation of the smooth constraints
   and their Jacobian (``local_constraints``, what SLSQP calls each iteration).
2. **Polish inside plan** at the paper budgets (one evaluation process), NSGA-II and MODE,
   per seed: ``plan(..., polish="off")`` and ``plan(...)`` (the default ``"front"``): the
   fastest certified T / T_lb of both, the hypervolume of both certified fronts on common
   bounds, the front members the polish added, and the polish's share of the run's time
   (the polish timed alone: :func:`~adept_traj.optimise.polish_run` on the unpolished
   run's front, which holds every member ``plan`` polishes, with its certificates; the two
   runs' totals differ by machine noise as much as by the polish). Targets: fastest
   certified T ≤ 1.005 × T_lb, HV(polished) ≥ HV(unpolished) on every seed, polish ≤ 25 %
   of the run. This part takes minutes (≈ 2 × 12 s per NSGA-II seed, ≈ 2 × 30 s per MODE).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np
from _results import figure, recorded  # benchmarks/_results.py

from adept_traj import Robot, Scene, TrajectoryProblem, certify, plan
from adept_traj.analysis import PAPER_WEIGHTS, normalised_hypervolume, objective_bounds
from adept_traj.optimise import RunState, polish_run, time_optimal
from adept_traj.problem import local_constraints, to_pymoo

#: Drake's KinematicTrajectoryOptimization with SNOPT on the paper scene (issue #12) [s].
DRAKE_T = 1.0766


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", default="1,2,3,4,5", help="comma-separated random seeds")
    parser.add_argument("--algorithms", default="nsga2,mode", help="comma-separated")
    parser.add_argument("--skip-runs", action="store_true", help="only the time-optimal part")
    parser.add_argument("--quick", action="store_true", help="seed 1, 20 generations")
    args = parser.parse_args()
    scene = Scene.paper()
    problem = TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)
    if not args.quick:
        time_optimal_part(problem)
    if not args.skip_runs:
        seeds = [1] if args.quick else [int(s) for s in args.seeds.split(",")]
        for name in args.algorithms.split(","):
            polish_part(problem, name, seeds, 20 if args.quick else None)


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
    figure(
        "time_optimal_command", "`adept-traj plan --algorithm time-optimal` (whole process)",
        round(statistics.median(walls), 2), "s", runs=[round(w, 3) for w in walls],
    )  # fmt: skip
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
    figure(
        "time_optimal_T", "time-optimal mode: T over Drake's 1.0766 s", round(T / DRAKE_T, 5),
        "×", target="≤ 1.001×", met=bool(result.feasible) and T <= 1.001 * DRAKE_T,
        note=f"T = {T:.5f} s, certified: {result.feasible}",
    )  # fmt: skip
    figure(
        "time_optimal_solve", "time-optimal mode: solve, in process", round(wall, 2), "s",
        target="≤ 1 s", met=wall <= 1.0, note=f"without certificates {result.timing.total_s:.2f} s",
    )  # fmt: skip
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


def polish_part(problem: TrajectoryProblem, name: str, seeds: list[int], n_gen: int | None) -> None:
    bound = problem.lower_bound.T_min
    budget = "paper budget" if n_gen is None else f"{n_gen} generations"
    print(f"\n{name} at the {budget}, one process; T_lb = {bound:.4f} s")
    print(
        f"{'seed':>4}{'T/T_lb raw':>12}{'T/T_lb pol':>12}{'HV raw':>9}{'HV pol':>9}{'added':>7}"
        f"{'total raw s':>12}{'total pol s':>12}{'polish s':>9}{'polish %':>9}{'+evals':>7}"
    )
    worst_share, hv_ok, t_worst = 0.0, True, 0.0
    for seed in seeds:
        raw = plan(problem, name, seed=seed, n_gen=n_gen, polish="off")
        pol = plan(problem, name, seed=seed, n_gen=n_gen)
        fronts = [r.feasible_front.objectives for r in (raw, pol)]
        lo, hi = objective_bounds(*fronts)
        hv = [normalised_hypervolume(f, lo, hi) for f in fronts]
        fastest = [float(f[:, 0].min()) / bound for f in fronts]
        added = sum(not np.any(np.all(raw.front.x == x, axis=1)) for x in pol.front.x)
        polish_s = _polish_alone(problem, raw)
        share = 100.0 * polish_s / (raw.timing.total_s + polish_s)
        extra = pol.timing.n_evaluations - raw.timing.n_evaluations
        worst_share, hv_ok = max(worst_share, share), hv_ok and hv[1] >= hv[0]
        t_worst = max(t_worst, fastest[1])
        print(
            f"{seed:>4}{fastest[0]:>12.4f}{fastest[1]:>12.4f}{hv[0]:>9.4f}{hv[1]:>9.4f}"
            f"{added:>7}{raw.timing.total_s:>12.2f}{pol.timing.total_s:>12.2f}{polish_s:>9.2f}"
            f"{share:>9.1f}{extra:>7}"
        )
        sys.stdout.flush()
    print(
        f"worst: T/T_lb pol {t_worst:.4f} [target ≤ 1.005], HV pol ≥ HV raw on every seed: "
        f"{hv_ok}, polish {worst_share:.1f} % [target ≤ 25 %]"
    )
    figure(
        f"{name}_fastest", f"{name}: worst fastest certified T / T_lb with the polish",
        round(t_worst, 4), "×", target="≤ 1.005×", met=t_worst <= 1.005,
        note=f"seeds {','.join(map(str, seeds))}; HV with polish ≥ without on every seed: {hv_ok}",
    )  # fmt: skip
    figure(
        f"{name}_polish_share", f"{name}: the polish's worst share of the run",
        round(worst_share, 1), "%", target="≤ 25 %", met=worst_share <= 25.0,
    )  # fmt: skip


def _polish_alone(problem: TrajectoryProblem, raw: Any) -> float:
    """Wall time [s] of the default polish on the unpolished run's front, with its
    certificates (the front holds the fastest feasible member and every member the polish
    chooses: they are chosen among the feasible non-dominated ones)."""
    f = raw.front
    state = RunState(
        X=f.x,
        F=to_pymoo(f.objectives),
        G=f.constraints,
        CV=np.maximum(f.constraints, 0.0).sum(axis=1),
        n_generations=raw.timing.n_generations,
        n_evaluations=raw.timing.n_evaluations,
        total_s=0.0,
        evaluation_s=0.0,
    )
    t0 = time.perf_counter()
    polish_run(problem, state, 1000.0, "front", PAPER_WEIGHTS)
    return time.perf_counter() - t0


if __name__ == "__main__":
    np.set_printoptions(precision=4)
    with recorded(__file__, "the polish and the time-optimal mode on the paper scene (issue #12)"):
        main()
