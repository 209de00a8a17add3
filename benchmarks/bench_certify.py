"""Certification of whole fronts: the paper NSGA-II front (100 members) and MODE (500).

Run: ``python benchmarks/bench_certify.py [--seed 1] [--workers 2] [--repeat 3]``.

Plans the paper scenario with NSGA-II (100 × 100) and MODE (500 × 100) at the given seed
(``--workers`` evaluation processes; the planning is not timed), then times the front's
certification as :func:`~adept_traj.plan` does it, in this process (one core):
:func:`~adept_traj.analysis.certify_members` (``certify(problem, x, exact=False)`` with the
continuous guarantee at 1 kHz, on the same problem with the influence distance lowered to
``margin + 0.01 m``: pairs whose broad-phase bound lies beyond it need no coal call, and
each certificate summarised), for every member the optimiser marked feasible. Prints the
median of ``--repeat`` timings against the targets of issue #11: ≤ 1 s for the 100-member
front and ≤ 5 s for the 500-member front, with the number of members certified, their
guarantee and the size of the saved ``result.json`` (every member's certificate in it).
Also the process CPU time of the same calls (median; the machine is shared, so CPU time
says more than wall time) and the CPU time per member (issue #15). The first timed call
of a front includes making the certifying problem (≈ 0.1 s, once per problem).
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
from _results import figure, recorded  # benchmarks/_results.py

from adept_traj import Robot, Scene, TrajectoryProblem, plan
from adept_traj.certification import certify_members

#: Target wall time [s] of one front's certification (issue #11), per algorithm.
TARGETS = {"nsga2": 1.0, "mode": 5.0}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=1, help="random seed of the runs")
    parser.add_argument("--workers", type=int, default=2, help="processes for the planning")
    parser.add_argument("--repeat", type=int, default=3, help="timings per front (median)")
    args = parser.parse_args()
    scene = Scene.paper()
    robot = Robot.adept_one_xl()
    problem = TrajectoryProblem(robot, scene, scene.start, scene.goal, workers=args.workers)
    print(f"paper scenario, seed {args.seed}, certification on one core, {args.repeat} repeats")
    print(
        f"{'algorithm':<10}{'front':>7}{'checked':>9}{'certified':>11}{'continuous':>12}"
        f"{'median s':>10}{'min s':>8}{'per member ms':>15}{'target s':>10}{'met':>5}"
        f"{'result.json kB':>16}{'CPU s':>8}{'CPU ms/member':>15}"
    )
    for name, target in TARGETS.items():
        result = plan(problem, name, seed=args.seed)
        front = result.front
        # plan certifies the members the optimiser marked feasible (all constraints ≤ 0).
        rows = np.flatnonzero(np.all(front.constraints <= 0.0, axis=1))
        times, cpu, certificates = [], [], []
        for _ in range(args.repeat):
            t0, c0 = time.perf_counter(), time.process_time()
            certificates = certify_members(problem, front.x, rows)
            times.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        median, cpu_median = statistics.median(times), statistics.median(cpu)
        checked = [certificates[k] for k in rows]
        n_cert = sum(c.feasible for c in checked)
        n_cont = sum(c.guarantee == "continuous" for c in checked)
        per_member = 1e3 * median / max(len(rows), 1)
        with tempfile.TemporaryDirectory() as tmp:
            size = (result.save(Path(tmp) / "run") / "result.json").stat().st_size / 1e3
        print(
            f"{name:<10}{len(front.x):>7}{len(rows):>9}{n_cert:>11}{n_cont:>12}"
            f"{median:>10.2f}{min(times):>8.2f}{per_member:>15.1f}{target:>10.1f}"
            f"{'yes' if median <= target else 'no':>5}{size:>16.0f}{cpu_median:>8.2f}"
            f"{1e3 * cpu_median / max(len(rows), 1):>15.2f}"
        )
        figure(
            f"{name}_front", f"certifying the {name} front ({len(rows)} members), one core",
            round(median, 2), "s", target=f"≤ {target:g} s", met=median <= target,
            runs=[round(t, 3) for t in times],
            note=f"{n_cert} certified, {n_cont} continuous; CPU {cpu_median:.2f} s",
        )  # fmt: skip
    problem.close()


if __name__ == "__main__":
    with recorded(
        __file__, "certifying whole fronts: the NSGA-II (100) and MODE (500) paper fronts"
    ):
        main()
