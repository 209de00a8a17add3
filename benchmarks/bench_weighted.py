"""The weighted-sum mode on the paper scenario (issue #12): solve time, certified, f_w.

Run: ``python benchmarks/bench_weighted.py [--boxes 0.03,0.1,0.3,1] [--repeat 3]
[--skip-command]``.

1. ``plan(problem, algorithm="time-optimal", weights=w)`` in process for several weight
   vectors (one evaluation process): process CPU time [s] (median of ``--repeat``), its
   gradient and move evaluations, the certified front members, the best member's f_w
   against the least f_w of the certified minimum-T moves (the starts of the descents,
   T within 1e-6 of the fastest) and both travel times.
2. The choice of the step's box (``WEIGHTED_BOX``): the descent from the minimum-T move of
   the straight start for each box half-width β in ``--boxes`` (β = 1: one SLSQP solve on
   the whole bounds, the "direct" epigraph solve, with the same acceptance of feasible,
   lower iterates), with the evaluations, CPU time, f_w and whether the result passes
   its 1 kHz certificate.
3. The command as typed, whole process: ``adept-traj plan --algorithm time-optimal
   --weights 0,1,0,0,0,0 --out DIR --no-html --no-plots`` (CPU time of the child process,
   median of ``--repeat``), beside the same command without ``--weights``.

No target is set by the issue for this mode; the figures go to ``docs/engine.md``.
"""

from __future__ import annotations

import argparse
import resource
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
from _results import recorded  # benchmarks/_results.py

import adept_traj.optimise.local.weighted_move as weighted_move
from adept_traj import Robot, Scene, TrajectoryProblem, plan
from adept_traj.analysis import WeightedSum, weighted_sum
from adept_traj.certification import certify_members
from adept_traj.optimise import time_optimal, weighted_descent

#: Weight vectors measured: name → w1…w6.
WEIGHTS = {
    "z1 only": (1.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    "z2 only": (0.0, 1.0, 0.0, 0.0, 0.0, 0.0),
    "paper": (0.25, 0.25, 0.1, 0.1, 0.15, 0.15),
    "z1+z6": (0.5, 0.0, 0.0, 0.0, 0.0, 0.5),
    "z1+4 z5": (0.2, 0.0, 0.0, 0.0, 0.8, 0.0),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--boxes", default="0.03,0.1,0.3,1", help="box half-widths β")
    parser.add_argument("--repeat", type=int, default=3, help="runs per figure (median)")
    parser.add_argument("--skip-command", action="store_true", help="no whole-process part")
    args = parser.parse_args()
    scene = Scene.paper()
    problem = TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal, workers=1)
    plan_part(problem, args.repeat)
    box_part(problem, [float(b) for b in args.boxes.split(",")])
    if not args.skip_command:
        command_part(args.repeat)


def plan_part(problem: TrajectoryProblem, repeat: int) -> None:
    print("plan(problem, 'time-optimal', weights=w), paper scene, one process")
    print(
        f"{'weights':>9}{'CPU s':>8}{'evals':>7}{'cert':>6}{'f_w best':>10}{'f_w min-T':>10}"
        f"{'T best':>8}{'T min-T':>9}"
    )
    for name, w in WEIGHTS.items():
        cpu = []
        for _ in range(repeat):
            t0 = time.process_time()
            result = plan(problem, "time-optimal", seed=1, weights=w)
            cpu.append(time.process_time() - t0)
        ws = WeightedSum.from_settings(result.algorithm_settings)
        f = ws.values(result.front.objectives)
        ok = np.flatnonzero(result.front.feasible)
        t_min = result.front.objectives[ok, 0].min()
        min_t = ok[result.front.objectives[ok, 0] <= t_min * (1.0 + 1e-6)]  # the starts
        start = min_t[np.argmin(f[min_t])]  # the minimum-T move of least f_w
        best = result.best.index
        print(
            f"{name:>9}{statistics.median(cpu):>8.2f}{result.timing.n_evaluations:>7}"
            f"{f'{len(ok)}/{len(f)}':>6}{f[best]:>10.4f}{f[start]:>10.4f}"
            f"{result.front.objectives[best, 0]:>8.4f}{result.front.objectives[start, 0]:>9.4f}"
        )


def box_part(problem: TrajectoryProblem, boxes: list[float]) -> None:
    start = time_optimal(problem, seed=1, n_starts=1)[0]
    print("\nthe step's box, descent from the straight start's minimum-T move")
    print(f"{'weights':>9}{'box':>6}{'evals':>7}{'CPU s':>8}{'f_w':>9}{'f_w start':>10}{'cert':>6}")
    default = weighted_move.WEIGHTED_BOX
    try:
        for name in ("z2 only", "paper", "z1+4 z5"):
            ws = weighted_sum(problem, WEIGHTS[name])
            for box in boxes:
                weighted_move.WEIGHTED_BOX = box
                budget = 1000 if box >= 1.0 else weighted_move.MAX_EVALUATIONS_PER_START
                steps = budget if box >= 1.0 else weighted_move.STEP_EVALUATIONS
                t0 = time.process_time()
                out = _descent(problem, start.x, ws, budget, steps)
                cpu = time.process_time() - t0
                ok = certify_members(problem, out.x[None])[0].feasible
                print(
                    f"{name:>9}{box:>6g}{out.n_evaluations:>7}{cpu:>8.2f}"
                    f"{ws.values(out.objectives):>9.4f}{ws.values(start.objectives):>10.4f}"
                    f"{ok!s:>6}"
                )
    finally:
        weighted_move.WEIGHTED_BOX = default


def _descent(problem, x0, ws, budget, steps):
    """:func:`weighted_descent` with ``steps`` evaluations a step (β = 1: one long solve)."""
    default = weighted_move.STEP_EVALUATIONS
    weighted_move.STEP_EVALUATIONS = steps
    try:
        return weighted_descent(problem, x0, ws, max_evaluations=budget)
    finally:
        weighted_move.STEP_EVALUATIONS = default


def command_part(repeat: int) -> None:
    print("\nthe command as typed, whole process (CPU of the child, median)")
    for extra in ([], ["--weights", "0,1,0,0,0,0"]):
        cpu, wall = [], []
        for _ in range(repeat):
            with tempfile.TemporaryDirectory() as tmp:
                cmd = ["adept-traj", "plan", "--algorithm", "time-optimal", *extra]
                cmd += ["--out", str(Path(tmp) / "r"), "--no-html", "--no-plots", "--quiet"]
                before = resource.getrusage(resource.RUSAGE_CHILDREN)
                t0 = time.perf_counter()
                subprocess.run(cmd, check=True, capture_output=True)
                wall.append(time.perf_counter() - t0)
                after = resource.getrusage(resource.RUSAGE_CHILDREN)
                cpu.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
        print(
            f"  adept-traj plan --algorithm time-optimal {' '.join(extra)}: CPU "
            f"{statistics.median(cpu):.2f} s, wall {statistics.median(wall):.2f} s"
        )


if __name__ == "__main__":
    with recorded(__file__, "the weighted-sum mode: solve time, certified, f_w"):
        main()
