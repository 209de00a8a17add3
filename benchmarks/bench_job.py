"""Whole-job speed of the commands as a user runs them, against the targets of issue #15.

Run: ``python benchmarks/bench_job.py [--quick] [--repeat 3]``.

Every command runs as a separate process (the console script ``adept-traj`` when it is on
the PATH, else ``python -m adept_traj.cli``), timed from start to exit, ``--repeat`` times;
the figures are medians. ``--quick``: one run of each command, fewer evaluations.

Figures, each printed beside its target:

- ``adept-traj plan --out DIR`` (paper NSGA-II budget, figures, playback.html, every front
  member certified) — target ≤ 5 s;
- ``adept-traj plan --algorithm mode --out DIR`` (5 × 10⁴ evaluations) — ≤ 20 s;
- ``adept-traj --help`` — ≤ 0.3 s;
- saving a result (``PlanningResult.save`` of the paper run's result) — ≤ 0.2 s;
- full problem evaluations per second, population 500 of the paper problem (a random
  initial population), on 1 worker and on the default workers (the cores available) —
  ≥ 5 000/s with the default workers, and ≥ 20× the per-sample reference
  (:func:`adept_traj.testing.reference.evaluate_reference`) on one core;
- the five figures of a run (``adept_traj.viz.plots.save_all``, in a fresh process,
  matplotlib's import included) — ≤ 1 s;
- a 200-box work cell (``benchmarks/cell_scene.py``: the paper's obstacles near the path,
  198 boxes beyond reach) evaluated on one core, as a share of the paper scene's rate —
  ≥ 0.3×.
"""

from __future__ import annotations

import argparse
import datetime
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _results import figure, recorded  # benchmarks/_results.py
from _results import machine as results_machine
from _timing import compile_package, load_average  # benchmarks/_timing.py
from cell_scene import cell_scene  # benchmarks/cell_scene.py

from adept_traj import PlanningResult, Robot, Scene
from adept_traj.problem import TrajectoryProblem, available_cores, keep_heap
from adept_traj.testing.reference import evaluate_reference

_FIGURES = """
import sys, time
t0 = time.perf_counter()
from adept_traj.results import PlanningResult
result = PlanningResult.load(sys.argv[1])
t1 = time.perf_counter()
from adept_traj.viz import plots
paths = plots.save_all(result, sys.argv[2])
print(len(paths), time.perf_counter() - t1)
"""


def machine() -> str:
    """CPU model, cores available / in the machine, Python and OS (:func:`_results.machine`)."""
    m = results_machine()
    return (
        f"{m['cpu']}; {m['cores_available']} cores available of {m['cores']}; "
        f"Python {m['python']}; {m['os']}; "
        f"load average at start {load_average()} (other jobs on the machine slow every figure)"
    )


def command() -> list[str]:
    """How a user starts ``adept-traj``: the console script beside this Python (a pyenv
    shim on the PATH would add its own start-up), else ``python -m adept_traj.cli``."""
    script = Path(sys.executable).parent / "adept-traj"
    return [str(script)] if script.is_file() else [sys.executable, "-m", "adept_traj.cli"]


def wall(argv: list[str]) -> float:
    """Wall time [s] of one process running ``argv`` (fails loudly on a non-zero exit)."""
    t0 = time.perf_counter()
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
    return time.perf_counter() - t0


def median_wall(argv_of, repeat: int) -> tuple[float, list[float]]:
    """Median and all of ``repeat`` wall times of ``argv_of(k)``, k = 0 … repeat − 1."""
    times = [wall(argv_of(k)) for k in range(repeat)]
    return statistics.median(times), times


def rate(problem: TrajectoryProblem, x: np.ndarray, repeat: int) -> float:
    """Median evaluations per second of ``problem.evaluate_batch(x)``."""
    problem.evaluate_batch(x[:20])  # warm-up (and the workers' start)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        problem.evaluate_batch(x)
        times.append(time.perf_counter() - t0)
    return len(x) / statistics.median(times)


def row(
    fid: str,
    name: str,
    value: float,
    unit: str,
    digits: int,
    target: str,
    met: bool,
    extra: str = "",
    runs: list[float] | None = None,
) -> None:
    """Print one row of the table and record it (``benchmarks/results/bench_job.json``)."""
    shown = f"{value:.{digits}f}{' ' if unit == 's' else ''}{unit}"
    print(f"| {name} | {shown} | {target} | {'met' if met else 'NOT met'} | {extra} |")
    rounded = None if runs is None else [round(t, digits) for t in runs]
    note = "" if runs is not None else extra  # the runs are recorded as such
    figure(fid, name, value, unit, target=target, met=met, runs=rounded, note=note, digits=digits)


def main() -> None:
    keep_heap()  # as the adept-traj command does in its own process
    compile_package()  # the bytecode pip writes at install: not timed as compile
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="one run each, fewer evaluations")
    parser.add_argument("--repeat", type=int, default=3, help="runs of each command (default 3)")
    args = parser.parse_args()
    repeat = 1 if args.quick else args.repeat
    cmd = command()
    tmp = Path(tempfile.mkdtemp(prefix="bench_job_"))
    print(f"machine: {machine()}")
    print(f"date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC")
    print(f"command: {' '.join(cmd)}; {repeat} run(s) each, medians\n")
    print("| figure | measured | target | | runs |")
    print("|---|---|---|---|---|")
    try:
        _bench(cmd, tmp, repeat, args.quick)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _bench(cmd: list[str], tmp: Path, repeat: int, quick: bool) -> None:
    runs = ", ".join

    med, times = median_wall(
        lambda k: [*cmd, "plan", "--quiet", "--out", str(tmp / f"n{k}")], repeat
    )
    row(
        "plan",
        "`adept-traj plan --out DIR`",
        med, "s", 2,
        "≤ 5 s",
        med <= 5.0,
        runs(f"{t:.2f}" for t in times),
        times,
    )  # fmt: skip
    med, times = median_wall(
        lambda k: [*cmd, "plan", "--algorithm", "mode", "--quiet", "--out", str(tmp / f"m{k}")],
        repeat,
    )
    row(
        "mode",
        "`adept-traj plan --algorithm mode --out DIR`",
        med, "s", 2,
        "≤ 20 s",
        med <= 20.0,
        runs(f"{t:.2f}" for t in times),
        times,
    )  # fmt: skip
    med, times = median_wall(lambda k: [*cmd, "--help"], max(5, repeat))
    row(
        "help",
        "`adept-traj --help`",
        med, "s", 3,
        "≤ 0.3 s",
        med <= 0.3,
        runs(f"{t:.3f}" for t in times),
        times,
    )  # fmt: skip

    result = PlanningResult.load(tmp / "n0")
    saves = []
    for k in range(max(5, repeat)):
        t0 = time.perf_counter()
        result.save(tmp / f"save{k}")
        saves.append(time.perf_counter() - t0)
    med = statistics.median(saves)
    row(
        "save", "saving a result", med, "s", 3, "≤ 0.2 s", med <= 0.2,
        runs(f"{t:.3f}" for t in saves), saves,
    )  # fmt: skip

    figs = []
    for k in range(repeat):
        out = subprocess.run(
            [sys.executable, "-c", _FIGURES, str(tmp / "n0"), str(tmp / f"fig{k}")],
            check=True, capture_output=True, text=True,
        )  # fmt: skip
        n, seconds = out.stdout.split()
        figs.append(float(seconds))
    med = statistics.median(figs)
    row(
        "figures",
        f"the {n} figures of a run",
        med, "s", 2,
        "≤ 1 s",
        med <= 1.0,
        runs(f"{t:.2f}" for t in figs),
        figs,
    )  # fmt: skip

    robot, paper = Robot.adept_one_xl(), Scene.paper()
    pop = 100 if quick else 500
    serial = TrajectoryProblem(robot, paper, paper.start, paper.goal, workers=1)
    rng = np.random.default_rng(0)
    x = serial.xl + (serial.xu - serial.xl) * rng.uniform(size=(pop, serial.n_var))
    one = rate(serial, x, max(3, repeat))
    cores = available_cores()
    with TrajectoryProblem(robot, paper, paper.start, paper.goal, workers=cores) as parallel:
        many = rate(parallel, x, max(3, repeat))
    t0 = time.perf_counter()
    evaluate_reference(serial, x[:5])
    reference = 5 / (time.perf_counter() - t0)
    row(
        "rate",
        f"evaluations/s, population {pop}, {cores} workers (default)",
        many, "/s", 0,
        "≥ 5 000/s",
        many >= 5000,
        f"1 worker: {one:.0f}/s",
    )  # fmt: skip
    row(
        "reference_ratio",
        "1 worker vs the per-sample reference",
        one / reference, "×", 0,
        "≥ 20×",
        one / reference >= 20,
        f"reference {reference:.1f}/s",
    )  # fmt: skip

    t0 = time.perf_counter()
    cell = cell_scene(200)
    big = TrajectoryProblem(robot, cell, cell.start, cell.goal, workers=1)
    built = time.perf_counter() - t0
    crowded = rate(big, x[:100] if not quick else x[:50], max(3, repeat))
    share = crowded / one
    row(
        "cell_share", "200-box cell vs paper scene, 1 worker", share, "×", 2, "≥ 0.3×",
        share >= 0.3, f"{crowded:.0f}/s vs {one:.0f}/s; problem built in {built:.1f} s",
    )  # fmt: skip


if __name__ == "__main__":
    with recorded(__file__, "the whole job: the commands as a user runs them (issue #15)"):
        main()
