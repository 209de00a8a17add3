"""The parallel evaluation's own cost: one population on ``workers`` processes against one.

Run: ``python benchmarks/bench_pool.py [--pops 100,500] [--calls 40] [--against DIR]``.

A planning run evaluates one population per generation: 100 trajectories for the paper's
NSGA-II, 500 for MODE. With ``workers > 1`` every generation pays the pool's own cost
(handing the chunks to the worker processes, their evaluations back, waking them), which
matters most at small populations. For each population size this prints the **wall time
per call** of :meth:`TrajectoryProblem.evaluate_batch` on one process and on ``workers``
(medians of ``--calls`` calls of a near-feasible population of the paper problem, the
pool already started), their ratio (the speed-up), and the process CPU time per call of
the parallel calls, the workers' included (:func:`resource.getrusage` of the process and
of its children, read after the pool is closed). The rows ``pop, nothing`` time the pool
alone: a :class:`ParallelEvaluator` whose evaluation computes nothing (wall and
main-process CPU time per call, medians of 10 × ``--calls`` calls).

``--against DIR`` runs this measurement in fresh processes of this tree's code and of the
checkout ``DIR``'s alternately (``--pairs`` pairs) and prints both and the median of the
pair ratios (this / other): on a shared machine the pairs see the same load.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import time

import numpy as np
from _results import recorded  # benchmarks/_results.py
from _timing import pair_order  # benchmarks/_timing.py

from adept_traj import Robot, Scene
from adept_traj.problem import Evaluation, ParallelEvaluator, TrajectoryProblem
from adept_traj.testing.paper_moves import lift_then_lower  # a hand-made collision-free move


def _cpu(who: int) -> float:
    usage = resource.getrusage(who)
    return usage.ru_utime + usage.ru_stime


def _nothing(x: np.ndarray) -> Evaluation:
    """An evaluation that computes nothing (the paper problem's shapes): the pool's own cost."""
    k = len(x)
    return Evaluation(np.zeros((k, 6)), np.zeros((k, 21)), np.zeros((k, 4)))


def overhead(pop: int, calls: int, workers: int) -> dict[str, float]:
    """Median wall and main-process CPU seconds per call of a :class:`ParallelEvaluator`
    whose evaluation computes nothing, population ``pop`` (its own cost per generation)."""
    x = np.random.default_rng(0).uniform(size=(pop, 65))
    walls, cpus = [], []
    with ParallelEvaluator(_nothing, workers, 65) as evaluator:
        evaluator.evaluate(x)  # forks the workers
        for _ in range(calls):
            cpu0, start = _cpu(resource.RUSAGE_SELF), time.perf_counter()
            evaluator.evaluate(x)
            walls.append(time.perf_counter() - start)
            cpus.append(_cpu(resource.RUSAGE_SELF) - cpu0)
    return {"serial": 0.0, "parallel": statistics.median(walls), "cpu": statistics.median(cpus)}


def measure(pops: list[int], calls: int, workers: int) -> dict[str, dict[str, float]]:
    """Per population size: ``serial`` and ``parallel`` median wall seconds per call and
    ``cpu`` seconds per parallel call (every process)."""
    robot, scene = Robot.adept_one_xl(), Scene.paper()
    serial = TrajectoryProblem(robot, scene, scene.start, scene.goal)
    rng = np.random.default_rng(0)
    span = serial.xu - serial.xl
    x0 = lift_then_lower(serial)
    out = {}
    for pop in pops:
        x = np.clip(
            x0 + rng.normal(scale=0.01, size=(pop, serial.n_var)) * span, serial.xl, serial.xu
        )
        serial.evaluate_batch(x)  # warm-up
        parallel = TrajectoryProblem(robot, scene, scene.start, scene.goal, workers=workers)
        parallel.evaluate_batch(x)  # starts the workers
        one, both, cpu = [], [], 0.0
        for _ in range(calls):  # alternately: both see the same load
            start = time.perf_counter()
            serial.evaluate_batch(x)
            one.append(time.perf_counter() - start)
            cpu0 = _cpu(resource.RUSAGE_SELF)
            start = time.perf_counter()
            parallel.evaluate_batch(x)
            both.append(time.perf_counter() - start)
            cpu += _cpu(resource.RUSAGE_SELF) - cpu0
        children = _cpu(resource.RUSAGE_CHILDREN)
        parallel.close()  # the workers' CPU time counts once they have exited
        cpu += _cpu(resource.RUSAGE_CHILDREN) - children  # (their warm-up call included)
        out[str(pop)] = {
            "serial": statistics.median(one),
            "parallel": statistics.median(both),
            "cpu": cpu / calls,
        }
    for pop in pops:
        out[f"{pop}, nothing"] = overhead(pop, 10 * calls, workers)
    return out


def _show(label: str, runs: list[dict[str, dict[str, float]]]) -> None:
    for pop in runs[0]:
        s = statistics.median(r[pop]["serial"] for r in runs) * 1e3
        p = statistics.median(r[pop]["parallel"] for r in runs) * 1e3
        c = statistics.median(r[pop]["cpu"] for r in runs) * 1e3
        if s == 0.0:  # the pool alone: no serial call, the main process' CPU time
            print(f"{label:<7}{pop:>15}{'':>12}{p:>12.3f}{'':>11}{c:>14.3f}")
        else:
            print(f"{label:<7}{pop:>15}{s:>12.2f}{p:>12.2f}{s / p:>10.2f}×{c:>14.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pops", default="100,500", help="population sizes, comma-separated")
    parser.add_argument("--calls", type=int, default=40, help="calls per population size")
    parser.add_argument("--workers", type=int, default=2, help="processes of the parallel calls")
    parser.add_argument("--against", metavar="DIR", help="paired runs against DIR's code")
    parser.add_argument("--pairs", type=int, default=4, help="pairs of runs for --against")
    parser.add_argument("--json", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    pops = [int(p) for p in args.pops.split(",")]
    header = (
        f"{'code':<7}{'pop':>15}{'1 proc [ms]':>12}{'parallel':>12}{'speed-up':>11}"
        f"{'CPU/call [ms]':>14}"
    )
    what = f"{args.workers} workers, medians of {args.calls} calls"
    if args.json:
        print(json.dumps(measure(pops, args.calls, args.workers)))
        return
    if not args.against:
        print(f"paper problem, near-feasible populations, {what}")
        print(header)
        _show("this", [measure(pops, args.calls, args.workers)])
        return
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    trees = {"this": here, "other": os.path.abspath(args.against)}
    runs: dict[str, list] = {"this": [], "other": []}
    cmd = [sys.executable, __file__, "--json", "--pops", args.pops, "--calls", str(args.calls)]
    cmd += ["--workers", str(args.workers)]
    for i in range(args.pairs):
        for label in pair_order(("this", "other"), i):
            env = {**os.environ, "PYTHONPATH": trees[label]}
            done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
            runs[label].append(json.loads(done.stdout.strip().splitlines()[-1]))
    print(f"{args.pairs} pairs, {what}; other = {args.against}")
    print(header)
    _show("this", runs["this"])
    _show("other", runs["other"])
    for pop in runs["this"][0]:
        ratios = [
            a[pop]["parallel"] / b[pop]["parallel"] for a, b in zip(runs["this"], runs["other"])
        ]
        shown = ", ".join(f"{r:.2f}" for r in ratios)
        print(f"pop {pop}: parallel wall this/other {statistics.median(ratios):.3f} ({shown})")


if __name__ == "__main__":
    with recorded(
        __file__,
        "the parallel evaluation's own cost: a population on several processes vs one",
        child_flags=("--json",),
    ):
        main()
