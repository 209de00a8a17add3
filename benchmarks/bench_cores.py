"""What two cores of this machine give: one CPU-bound job against two copies side by side.

Run: ``python benchmarks/bench_cores.py [--repeat 5] [--seconds 2]``.

Issue #25's scaling target (≥ 1.8× from one Dask worker to two) presumes two cores that
each run a job as fast as one core alone does. This script measures that presumption,
independently of the planner's division of work: the same fixed amount of work is timed
in one process alone, then in two processes started together (forked, each the same
work), and the **side-by-side ratio** is ``2 × t_alone / t_together`` (2.0: two full
cores; 1.0: one core shared). The runs alternate (alone, together, alone, …) and the
median of ``--repeat`` pairs is quoted, with the load average before each.

The jobs:

- ``python loop``: an integer loop in pure Python (no memory traffic: registers and the
  first-level cache);
- ``evaluator``: the planner's own hot path, :meth:`TrajectoryProblem.evaluate_batch` of a
  fixed batch of 100 ramps on the paper scene in one process (``workers=1``), what each
  worker of a cycle spends its time on.

A ratio well below 2 for the loop says the machine's two cores are not two independent
cores (e.g. two hardware threads of one core, or a shared time quota): no division of the
work then reaches a 1 → 2 scaling above that ratio.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np
from _results import figure, recorded  # benchmarks/_results.py


def python_loop(units: int) -> None:
    """``units`` × 10⁵ integer additions and multiplications in pure Python."""
    total = 0
    for _ in range(units):
        for i in range(100_000):
            total = (total + i * 7) & 0xFFFF


def evaluator_job():
    """The evaluator job: ``run(units)`` evaluates a fixed batch of 100 ramps ``units``
    times (the problem and batch made before any timing)."""
    import adept_traj as at
    from adept_traj.optimise import RampSampling

    scene = at.Scene.paper()
    problem = at.TrajectoryProblem(
        at.Robot.adept_one_xl(), scene, scene.start, scene.goal, workers=1
    )
    batch = RampSampling().ramps(problem, 100, np.random.default_rng(1))
    problem.evaluate_batch(batch)  # warm: tables and caches made

    def run(units: int) -> None:
        for _ in range(units):
            problem.evaluate_batch(batch)

    return run


def timed_alone(job, units: int) -> float:
    """Wall time [s] of ``job(units)`` in one forked process."""
    tic = time.perf_counter()
    pid = os.fork()
    if pid == 0:  # the child: the work, then out without the interpreter's teardown
        try:
            job(units)
        finally:
            os._exit(0)
    os.waitpid(pid, 0)
    return time.perf_counter() - tic


def timed_together(job, units: int) -> float:
    """Wall time [s] of two forked processes each running ``job(units)``, started
    together."""
    tic = time.perf_counter()
    pids = []
    for _ in range(2):
        pid = os.fork()
        if pid == 0:
            try:
                job(units)
            finally:
                os._exit(0)
        pids.append(pid)
    for pid in pids:
        os.waitpid(pid, 0)
    return time.perf_counter() - tic


def calibrated_units(job, seconds: float) -> int:
    """How many units of ``job`` take about ``seconds`` in one process (≥ 1)."""
    one = timed_alone(job, 1)
    return max(1, round(seconds / max(one, 1e-6)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=5, help="pairs of runs (≥ 1)")
    parser.add_argument("--seconds", type=float, default=2.0, help="length of one job [s]")
    args = parser.parse_args()
    if args.repeat < 1 or not args.seconds > 0:
        parser.error(f"--repeat must be ≥ 1 and --seconds > 0; got {args.repeat}, {args.seconds}")
    jobs = {"python loop": python_loop, "evaluator": evaluator_job()}
    print(f"{'job':<12} {'units':>6} {'alone [s]':>10} {'together [s]':>13} {'ratio':>6}  load")
    for name, job in jobs.items():
        units = calibrated_units(job, args.seconds)
        ratios, alone_runs = [], []
        for _ in range(args.repeat):
            load = os.getloadavg()[0]
            alone = timed_alone(job, units)
            together = timed_together(job, units)
            ratios.append(2.0 * alone / together)
            alone_runs.append(alone)
            print(f"{name:<12} {units:>6} {alone:>10.3f} {together:>13.3f} "
                  f"{ratios[-1]:>6.3f}  {load:.2f}")  # fmt: skip
        ratio = statistics.median(ratios)
        print(f"{name}: median side-by-side ratio {ratio:.3f} (2.0: two full cores)")
        figure(
            name.replace(" ", "_"),
            f"{name}: two copies side by side vs one alone (throughput; 2.0: two full cores)",
            ratio,
            "×",
            runs=[round(r, 3) for r in ratios],
            digits=2,
            note=f"{units} units, one alone {statistics.median(alone_runs):.2f} s",
        )


if __name__ == "__main__":
    title = "what two cores of this machine give (the ceiling of issue #25's scaling)"
    with recorded(__file__, title):
        main()
