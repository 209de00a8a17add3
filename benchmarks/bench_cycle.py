"""Cycles on Dask: one worker against two, a scheduler + workers over TCP, and (issue 25)
the phase-optimised plan of a cycle with a moving obstacle against the naive one.

Run: ``python benchmarks/bench_cycle.py [--cycle detour|pick6|bench12 ...] [--pop P]
[--gens G] [--phases 8] [--repeat R] [--configs 1 2 tcp] [--out DIR]`` (takes minutes to
an hour).

The cycles (every scene here has the pendulum, so every cycle runs on the scene clock and
is planned on a phase grid of ``--phases`` start phases plus the arrivals' phases:
``adept-traj cycle --phase-grid N``, docs/cycles.md):

- ``detour``: the shipped detour scene, a → b, b → a (a, b its start and goal),
  ``repeat = 5``, seed 3, NSGA-II 100 × 60 (issue 25's cycle);
- ``pick6``: a closed 6-move pick-and-place on the paper scene, ``repeat = 10``, seed 1,
  NSGA-II 30 × 20 by default (48 grid tasks and up to 5 rounds of arrivals);
- ``bench12``: the 12-move cycle of issue 16 on the paper scene (``repeat = 1``).

Each configuration of ``--configs`` is timed as a user types it, whole process included,
``--repeat`` times (medians quoted), with the CPU time [s] of the command and every
process it started (``RUSAGE_CHILDREN``: user + system), each local Dask worker's CPU time
(polled) and the load average before each run; the 1- and 2-worker runs are paired and
alternate (1, 2 / 2, 1 / …), the speed-up being the median of the pairs' ratios:

1. ``adept-traj cycle FILE --out DIR --workers 1 --phase-grid N``;
2. the same with ``--workers 2`` (target: ≥ 1.8× faster than 1 on two free cores);
3. ``dask scheduler`` and two ``dask worker … --nthreads 1`` processes on 127.0.0.1
   (real TCP), then ``adept-traj cycle … --scheduler tcp://127.0.0.1:P``; each worker's
   CPU time is read from it before it stops.

On a shared machine the wall times are distorted by the other load; the **CPU-time
scaling** is then the better figure: the 1-worker run's CPU time over the 2-worker (or
TCP) run's critical path (the command's own CPU time, serial, plus the busier worker's
CPU time): the speed-up two free cores would give with that division of the work, an
upper bound since a worker waiting for the next round of arrivals is not counted.

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
import threading
import time
from pathlib import Path

import numpy as np
import psutil
from _results import figure, recorded  # benchmarks/_results.py
from _timing import load_average, pair_order  # benchmarks/_timing.py

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


def _process_cpu(process: psutil.Process) -> float:
    times = process.cpu_times()
    return times.user + times.system


def timed(argv: list[str]) -> tuple[float, float, str, list[float]]:
    """Wall time [s], CPU time [s] (the command and the processes it started), stderr of
    the command ``argv`` (checked: exit 0, or 1 = not all certified) and the CPU time [s]
    of each Dask worker process it started (its last reading, polled every 0.2 s: the
    local cluster's spawned processes; a few 0.1 s short of the whole)."""
    cpu0, t0 = _children_cpu(), time.perf_counter()
    run = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    seen: dict[int, float] = {}
    err: list[str] = []
    reader = threading.Thread(target=lambda: err.append(run.stderr.read()), daemon=True)
    reader.start()
    main = psutil.Process(run.pid)
    while run.poll() is None:
        try:
            for child in main.children(recursive=True):
                if "spawn_main" in " ".join(child.cmdline()):
                    seen[child.pid] = _process_cpu(child)
        except psutil.Error:
            pass
        time.sleep(0.2)
    reader.join()
    wall, cpu = time.perf_counter() - t0, _children_cpu() - cpu0
    stderr = "".join(err)
    if run.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(argv)} exited with {run.returncode}: {stderr[-800:]}")
    return wall, cpu, stderr, sorted(seen.values())


def cycle_times(stderr: str) -> tuple[float, float | None, int, str]:
    """(optimised, naive back-to-back) cycle times [s], the number of plans and the kind
    of the optimised schedule, from the command's phase-grid line."""
    found = re.search(
        r"\((\d+) plans\): cycle time ([0-9.]+) s \(([^)]*)\), naive back-to-back "
        r"([0-9.]+|–) s",
        stderr,
    )
    if found is None:
        raise SystemExit(f"no phase-grid line in: {stderr[-800:]}")
    naive = found.group(4)
    best, plans, kind = float(found.group(2)), int(found.group(1)), found.group(3)
    return best, None if naive == "–" else float(naive), plans, kind


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
        wall, cpu, err, _ = timed([*command, "--no-playback", "--scheduler", address, *extra])
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


def _median(values: list[float]) -> float:
    return statistics.median(values)


def _runs(values: list[float]) -> str:
    return ", ".join(f"{v:.1f}" for v in values)


def bench(name: str, args: argparse.Namespace, root: Path) -> bool:
    """Time one cycle (module doc) and print its figures; whether the runs agree."""
    pop, gens = args.pop or CYCLES[name][5][0], args.gens or CYCLES[name][5][1]
    folder = root / name
    folder.mkdir(parents=True, exist_ok=True)
    file = write_cycle(folder, cycle_file_text(name, pop, gens), file=f"{name}.toml", scenes={})
    grid = ["--phase-grid", str(args.phases)]
    base = ["adept-traj", "cycle", str(file), "--quiet", "--no-plots", "--no-playback", "--out"]
    configs = ["2"] if name in args.once else args.configs
    repeats = 1 if name in args.once else args.repeat
    local = [c for c in ("1", "2") if c in configs]
    # per configuration: (wall [s], CPU [s], load before, workers' CPU [s]) of each run
    rows: dict[str, list[tuple[float, float, str, list[float]]]] = {c: [] for c in configs}
    outs, err = [], ""
    for r in range(repeats):
        for c in pair_order(local, r):  # paired, alternating: 1, 2 / 2, 1 / …
            out, load = folder / f"{c}workers.{r}", load_average()
            wall, cpu, err, per_worker = timed([*base, str(out), "--workers", c, *grid])
            rows[c].append((wall, cpu, load, per_worker))
            outs.append(out)
            print(f"  run {r} on {c} worker(s): wall {wall:.1f} s, CPU {cpu:.1f} s "
                  f"(workers {_runs(per_worker)}), load before {load}", flush=True)  # fmt: skip
        if "tcp" in configs and r == 0:  # once: the same results bit for bit over TCP
            out, load = folder / f"tcp.{r}", load_average()
            wall, cpu, err, per_worker = run_on_tcp(file, out, grid)
            rows["tcp"].append((wall, cpu, load, per_worker))
            outs.append(out)
    same = same_results(outs)
    best, naive, plans, kind = cycle_times(err)
    print(f"{name} cycle, NSGA-II {pop} × {gens}, {args.phases} phases ({plans} tasks: "
          f"{len(read_cycle_file(file).moves)} moves × {args.phases} phases and the arrivals), "
          f"results in {folder}")  # fmt: skip
    print(f"  cycle time, phase-optimised: {best:8.3f} s ({kind})")
    if naive is None:
        print("  cycle time, naive back-to-back: no certified schedule")
    else:
        print(f"  cycle time, naive back-to-back: {naive:8.3f} s "
              f"(gain of the phase-optimised plan {100 * (1 - best / naive):.1f} %)")  # fmt: skip
    figure(f"{name}_cycle_time", f"{name} cycle: phase-optimised cycle time ({kind})",
           round(best, 3), "s", note=f"naive back-to-back {naive} s")  # fmt: skip
    for label, runs in rows.items():
        print(f"  {label:>3} worker(s): wall {_median([w for w, _, _, _ in runs]):7.1f} s "
              f"(runs {_runs([w for w, _, _, _ in runs])}), CPU "
              f"{_median([c for _, c, _, _ in runs]):7.1f} s (runs "
              f"{_runs([c for _, c, _, _ in runs])}); load before: "
              f"{'; '.join(ld for _, _, ld, _ in runs)}")  # fmt: skip
    if len(local) == 2:
        pairs = [a[0] / b[0] for a, b in zip(rows["1"], rows["2"])]
        speedup = _median(pairs)
        cpu1 = _median([c for _, c, _, _ in rows["1"]])
        # the 2-worker runs' critical path by CPU time: the command's own (its CPU less
        # the workers') plus the busier worker's (an upper bound of the scaling: the
        # waits between rounds of arrivals are not in it)
        paths = [c - sum(w) + max(w) for _, c, _, w in rows["2"] if w]
        scaling = cpu1 / _median(paths) if paths else float("nan")
        print(f"  wall-time speed-up 1 → 2 local workers, median of {len(pairs)} pairs: "
              f"{speedup:.2f}× (pairs {', '.join(f'{p:.2f}' for p in pairs)}; target ≥ "
              f"{TARGET_SPEEDUP}×) {'OK' if speedup >= TARGET_SPEEDUP else 'MISSED'}")  # fmt: skip
        print(f"  CPU-time scaling (1-worker CPU / 2-worker critical path): {scaling:.2f}× "
              f"{'OK' if scaling >= TARGET_SPEEDUP else 'MISSED'}")  # fmt: skip
        t1 = _median([w for w, _, _, _ in rows["1"]])
        t2 = _median([w for w, _, _, _ in rows["2"]])
        figure(f"{name}_one_worker", f"{name} cycle on 1 local Dask worker (wall)", round(t1, 1),
               "s", runs=[round(w, 1) for w, _, _, _ in rows["1"]],
               note=f"CPU {cpu1:.1f} s")  # fmt: skip
        figure(f"{name}_speedup", f"{name} cycle: 2 local workers vs 1 (wall, paired)",
               round(speedup, 2), "×", target=f"≥ {TARGET_SPEEDUP}×",
               met=speedup >= TARGET_SPEEDUP, runs=[round(p, 2) for p in pairs],
               note=f"{t2:.1f} s on 2 workers; load before the runs "
               f"{'; '.join(ld for _, _, ld, _ in rows['1'] + rows['2'])}")  # fmt: skip
        figure(f"{name}_cpu_scaling", f"{name} cycle: CPU-time scaling 1 → 2 local workers",
               round(scaling, 2), "×", target=f"≥ {TARGET_SPEEDUP}×",
               met=scaling >= TARGET_SPEEDUP,
               note="1-worker CPU / (command CPU + busier worker's CPU) of the 2-worker "
               "runs: an upper bound (waits between rounds not counted)")  # fmt: skip
    if rows.get("tcp"):
        paths = [c + max(w) for _, c, _, w in rows["tcp"]]
        print(f"  TCP workers' CPU [s]: {[w for _, _, _, w in rows['tcp']]}; command's CPU "
              f"[s]: {[round(c, 1) for _, c, _, _ in rows['tcp']]}")  # fmt: skip
        if "1" in rows:
            scaling = _median([c for _, c, _, _ in rows["1"]]) / _median(paths)
            print(f"  CPU-time scaling (1-worker CPU / TCP critical path): {scaling:.2f}× "
                  f"{'OK' if scaling >= TARGET_SPEEDUP else 'MISSED'}")  # fmt: skip
        tcp = _median([w for w, _, _, _ in rows["tcp"]])
        same_text = "yes" if same else "NO"
        figure(f"{name}_tcp", f"{name} cycle on a scheduler + 2 dask workers over TCP (wall)",
               round(tcp, 1), "s", note=f"identical results: {same_text}")  # fmt: skip
    print(f"  identical results (every run): {'yes' if same else 'NO'}")
    return same


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycle", choices=sorted(CYCLES), nargs="+", default=["detour", "pick6"])
    parser.add_argument("--pop", type=int, help="population (default: the cycle's)")
    parser.add_argument("--gens", type=int, help="generations (default: the cycle's)")
    parser.add_argument("--phases", type=int, default=8, help="start phases per period")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each configuration")
    parser.add_argument(
        "--configs",
        nargs="+",
        choices=["1", "2", "tcp"],
        default=["1", "2", "tcp"],
        help="1 / 2 local workers, a scheduler + 2 workers over TCP (its first repeat only)",
    )
    parser.add_argument(
        "--once",
        nargs="*",
        default=[],
        help="cycles run once on 2 local workers only (their cycle times; no scaling)",
    )
    parser.add_argument("--out", type=Path, help="output folder (default: a temporary one)")
    args = parser.parse_args()
    root = args.out or Path(tempfile.mkdtemp(prefix="bench_cycle_"))
    root.mkdir(parents=True, exist_ok=True)
    same = [bench(name, args, root) for name in args.cycle]
    sys.exit(0 if all(same) else 1)


if __name__ == "__main__":
    with recorded(__file__, "work cycles on Dask: one worker, two, a scheduler over TCP"):
        main()
