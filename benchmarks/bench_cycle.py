"""Cycles on Dask: one worker against two, a scheduler + workers over TCP, and (issue 25)
the phase-optimised plan of a cycle with a moving obstacle against the naive one.

Run: ``python benchmarks/bench_cycle.py [--cycle detour|pick6|bench12 ...] [--pop P]
[--gens G] [--phases 8] [--repeat R] [--out DIR]`` (takes minutes to an hour).

The cycles (every scene here has the pendulum, so every cycle runs on the scene clock and
is planned on a phase grid of ``--phases`` start phases plus the arrivals' phases:
``adept-traj cycle --phase-grid N``, docs/cycles.md):

- ``detour``: the shipped detour scene, a → b, b → a (a, b its start and goal),
  ``repeat = 5``, seed 3, NSGA-II 100 × 60 (issue 25's cycle);
- ``pick6``: a closed 6-move pick-and-place on the paper scene, ``repeat = 10``, seed 1,
  NSGA-II 30 × 20 by default (48 grid tasks and up to 5 rounds of arrivals);
- ``bench12``: the 12-move cycle of issue 16 on the paper scene (``repeat = 1``).

Each configuration is timed as a user types it, whole process included, ``--repeat``
times (medians quoted), with the CPU time [s] of the command and every process it
started (``RUSAGE_CHILDREN``: user + system) and the load average before each run:

1. ``adept-traj cycle FILE --out DIR --workers 1 --phase-grid N``;
2. the same with ``--workers 2`` (target: ≥ 1.8× faster than 1 on two free cores);
3. ``dask scheduler`` and two ``dask worker … --nthreads 1`` processes on 127.0.0.1
   (real TCP), then ``adept-traj cycle … --scheduler tcp://127.0.0.1:P``; each worker's
   CPU time is read from it before it stops.

On a shared machine the wall times are distorted by the other load; the **CPU-time
scaling** is then the better figure: the 1-worker run's CPU time over the TCP run's
critical path (the command's own CPU time, serial, plus the busier worker's CPU time):
the speed-up two free cores would give with that division of the work.

Then checks that every run gives identical results (every task's front and best
trade-off bit for bit, and the same chosen schedule) and prints the cycle time of the
phase-optimised plan against the naive back-to-back plan that only adds the dwells it
needs, both certified at their real start times.
"""

from __future__ import annotations

import argparse
import json
import re
import resource
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _results import figure, recorded  # benchmarks/_results.py
from _timing import load_average  # benchmarks/_timing.py

from adept_traj.cycle import MOVES_FOLDER, read_cycle_file
from adept_traj.results import PlanningResult
from adept_traj.testing.cycle_files import HOME, PLACE, cycle_text, write_cycle

#: Speed-up of two local workers over one (issue #16).
TARGET_SPEEDUP = 1.8

LOCATIONS = {
    "home": {"joints": HOME},
    "place": {"joints": PLACE},
    "pick": {"pose": [0.3, 0.5, 0.55, 0.0]},
    "feeder": {"pose": [0.0, 0.6, 0.6, 0.5]},
    "tray": {"pose": [0.7, 0.1, 0.5, 0.0]},
}

SEQUENCE = [
    ("home", "pick"),
    ("pick", "place"),
    ("place", "feeder"),
    ("feeder", "tray"),
    ("tray", "home"),
    ("home", "place"),
    ("place", "pick"),
    ("pick", "tray"),
    ("tray", "feeder"),
    ("feeder", "home"),
    ("home", "tray"),
    ("tray", "place"),
]

#: Six moves between locations where the robot may wait at rest (at "place", the paper
#: scene's goal, the pendulum hits the resting robot at some phases: −12.7 mm).
PICK6 = [
    ("home", "pick"),
    ("pick", "feeder"),
    ("feeder", "tray"),
    ("tray", "pick"),
    ("pick", "tray"),
    ("tray", "home"),
]

#: name -> (scene, repeat, seed, locations, sequence, (pop, gens) by default)
CYCLES = {
    "detour": (
        "detour",
        5,
        3,
        {"a": {"joints": HOME}, "b": {"joints": PLACE}},
        [("a", "b"), ("b", "a")],
        (100, 60),
    ),
    "pick6": ("paper", 10, 1, LOCATIONS, PICK6, (30, 20)),
    "bench12": ("paper", 1, 1, LOCATIONS, SEQUENCE, (30, 20)),
}


def cycle_file_text(name: str, pop: int, gens: int) -> str:
    """The benchmark's cycle file."""
    scene, repeat, seed, locations, sequence, _ = CYCLES[name]
    plan = {"pop_size": pop, "n_gen": gens, "seed": seed}
    return cycle_text(
        name, scene=scene, repeat=repeat, plan=plan, locations=locations, moves=sequence
    )


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def timed(argv: list[str]) -> tuple[float, float, str]:
    """Wall time [s], CPU time [s] (the command and the processes it started) and stderr
    of the command ``argv`` (checked: exit 0, or 1 = not all certified)."""
    cpu0, t0 = _children_cpu(), time.perf_counter()
    run = subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall, cpu = time.perf_counter() - t0, _children_cpu() - cpu0
    if run.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(argv)} exited with {run.returncode}: {run.stderr[-800:]}")
    return wall, cpu, run.stderr


def pass_times(stderr: str) -> tuple[float, float | None, int]:
    """(optimised, naive) pass times [s] and the number of plans, from the command's
    phase-grid line."""
    found = re.search(
        r"\((\d+) plans\): pass time ([0-9.]+) s, naive back-to-back ([0-9.]+|–) s", stderr
    )
    if found is None:
        raise SystemExit(f"no phase-grid line in: {stderr[-800:]}")
    naive = found.group(3)
    return float(found.group(2)), None if naive == "–" else float(naive), int(found.group(1))


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _worker_cpu(address: str) -> list[float]:
    """Each worker's process CPU time [s] (user + system), read from it."""
    from distributed import Client

    with Client(address, timeout=30) as client:
        found = client.run(time.process_time)
    return sorted(found.values())


def run_on_tcp(file: Path, out: Path, extra: list[str]) -> tuple[float, float, str, list[float]]:
    """The cycle on a ``dask scheduler`` and two ``dask worker`` processes over TCP: wall
    [s], the command's CPU [s], its stderr and each worker's CPU [s]."""
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    scheduler = subprocess.Popen(
        ["dask", "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
        **quiet,
    )
    workers = []
    try:
        time.sleep(3.0)
        for _ in range(2):
            workers.append(
                subprocess.Popen(
                    ["dask", "worker", address, "--nthreads", "1", "--no-dashboard"], **quiet
                )
            )
        time.sleep(8.0)  # both workers registered
        command = ["adept-traj", "cycle", str(file), "--out", str(out), "--quiet", "--no-plots"]
        wall, cpu, err = timed([*command, "--no-playback", "--scheduler", address, *extra])
        return wall, cpu, err, _worker_cpu(address)
    finally:  # the workers first: a worker outliving its scheduler logs heartbeat errors
        for p in workers:
            p.terminate()
        for p in workers:
            p.wait(timeout=60)
        scheduler.terminate()
        scheduler.wait(timeout=60)


def same_results(outs: list[Path]) -> bool:
    """Whether every task's front and best trade-off, and the chosen schedule, are
    identical in all ``outs``."""
    names = sorted(p.name for p in (outs[0] / MOVES_FOLDER).iterdir())
    for o in outs[1:]:
        if sorted(p.name for p in (o / MOVES_FOLDER).iterdir()) != names:
            print(f"{o}: other tasks than {outs[0]}")
            return False
    for name in names:
        loaded = [PlanningResult.load(o / MOVES_FOLDER / name) for o in outs]
        for r in loaded[1:]:
            if not (
                np.array_equal(r.front.x, loaded[0].front.x)
                and np.array_equal(r.best_x, loaded[0].best_x)
            ):
                print(f"task {name}: results differ")
                return False
    clocks = [json.loads((o / "cycle.json").read_text())["clock"]["passes"] for o in outs]
    if any(c != clocks[0] for c in clocks[1:]):
        print("the chosen schedules differ")
        return False
    return True


def bench(name: str, args: argparse.Namespace, root: Path) -> bool:
    """Time one cycle (module doc) and print its figures; whether the runs agree."""
    pop, gens = args.pop or CYCLES[name][5][0], args.gens or CYCLES[name][5][1]
    folder = root / name
    folder.mkdir(parents=True, exist_ok=True)
    file = write_cycle(folder, cycle_file_text(name, pop, gens), file=f"{name}.toml", scenes={})
    repeat = read_cycle_file(file).repeat
    grid = ["--phase-grid", str(args.phases)]
    base = ["adept-traj", "cycle", str(file), "--quiet", "--no-plots", "--no-playback", "--out"]
    rows: dict[str, list[tuple[float, float, str]]] = {"1 worker": [], "2 workers": [], "tcp": []}
    outs, workers_cpu, err = [], [], ""
    for r in range(args.repeat):
        for label, n in (("1 worker", 1), ("2 workers", 2)):
            out = folder / f"{label.replace(' ', '')}.{r}"
            load = load_average()
            wall, cpu, err = timed([*base, str(out), "--workers", str(n), *grid])
            rows[label].append((wall, cpu, load))
            outs.append(out)
        out, load = folder / f"tcp.{r}", load_average()
        wall, cpu, _, per_worker = run_on_tcp(file, out, grid)
        rows["tcp"].append((wall, cpu, load))
        workers_cpu.append(per_worker)
        outs.append(out)
    same = same_results(outs)
    best, naive, plans = pass_times(err)
    print(f"{name} cycle, NSGA-II {pop} × {gens}, {args.phases} phases ({plans} tasks: "
          f"{len(read_cycle_file(file).moves)} moves × {args.phases} phases and the arrivals), "
          f"results in {folder}")  # fmt: skip
    print(
        f"  cycle time, phase-optimised: {repeat * best:8.3f} s ({best:.3f} s per pass × {repeat})"
    )
    if naive is None:
        print("  cycle time, naive back-to-back: no certified schedule")
    else:
        print(f"  cycle time, naive back-to-back: {repeat * naive:8.3f} s "
              f"(gain of the phase-optimised plan {100 * (1 - best / naive):.1f} %)")  # fmt: skip
    for label, runs in rows.items():
        walls = ", ".join(f"{w:.1f}" for w, _, _ in runs)
        cpus = ", ".join(f"{c:.1f}" for _, c, _ in runs)
        loads = "; ".join(ld for _, _, ld in runs)
        print(f"  {label:9}: wall {statistics.median(w for w, _, _ in runs):7.1f} s "
              f"(runs {walls}), CPU {statistics.median(c for _, c, _ in runs):7.1f} s "
              f"(runs {cpus}); load before: {loads}")  # fmt: skip
    t1 = statistics.median(w for w, _, _ in rows["1 worker"])
    t2 = statistics.median(w for w, _, _ in rows["2 workers"])
    speedup = t1 / t2
    print(f"  wall-time speed-up 1 → 2 local workers: {speedup:.2f}× (target ≥ "
          f"{TARGET_SPEEDUP}×) {'OK' if speedup >= TARGET_SPEEDUP else 'MISSED'}")  # fmt: skip
    cpu1 = statistics.median(c for _, c, _ in rows["1 worker"])
    paths = [c + max(w) for (_, c, _), w in zip(rows["tcp"], workers_cpu)]
    print(f"  TCP workers' CPU [s]: {workers_cpu}; command's CPU [s]: "
          f"{[round(c, 1) for _, c, _ in rows['tcp']]}")  # fmt: skip
    scaling = cpu1 / statistics.median(paths)
    print(f"  CPU-time scaling (1-worker CPU / TCP critical path): {scaling:.2f}× "
          f"{'OK' if scaling >= TARGET_SPEEDUP else 'MISSED'}")  # fmt: skip
    print(f"  identical results (every run): {'yes' if same else 'NO'}")
    figure(f"{name}_one_worker", f"{name} cycle on 1 local Dask worker", round(t1, 1), "s")
    figure(f"{name}_speedup", f"{name} cycle: 2 local workers vs 1 (wall)", round(speedup, 2),
           "×", target=f"≥ {TARGET_SPEEDUP}×", met=speedup >= TARGET_SPEEDUP,
           note=f"{t2:.1f} s on 2 workers")  # fmt: skip
    figure(f"{name}_cpu_scaling", f"{name} cycle: CPU-time scaling 1 → 2 workers",
           round(scaling, 2), "×", target=f"≥ {TARGET_SPEEDUP}×",
           met=scaling >= TARGET_SPEEDUP)  # fmt: skip
    return same


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycle", choices=sorted(CYCLES), nargs="+", default=["detour", "pick6"])
    parser.add_argument("--pop", type=int, help="population (default: the cycle's)")
    parser.add_argument("--gens", type=int, help="generations (default: the cycle's)")
    parser.add_argument("--phases", type=int, default=8, help="start phases per period")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each configuration")
    parser.add_argument("--out", type=Path, help="output folder (default: a temporary one)")
    args = parser.parse_args()
    root = args.out or Path(tempfile.mkdtemp(prefix="bench_cycle_"))
    root.mkdir(parents=True, exist_ok=True)
    same = [bench(name, args, root) for name in args.cycle]
    sys.exit(0 if all(same) else 1)


if __name__ == "__main__":
    with recorded(__file__, "work cycles on Dask: one worker, two, a scheduler over TCP"):
        main()
