"""Cycles on Dask: one worker against two, a scheduler + workers over TCP, and (issue 25)
the phase-optimised plan of a cycle with a moving obstacle against the naive one.

Run: ``python benchmarks/bench_cycle.py [--cycle detour|pick6|bench12] [--pop 100]
[--gens 60] [--phases 8] [--out DIR]`` (takes minutes at the default budgets).

The cycles (every scene here has the pendulum, so every cycle runs on the scene clock and
is planned on a phase grid of ``--phases`` start phases: one Dask task per move × phase,
``adept-traj cycle --phase-grid N``, docs/cycles.md):

- ``detour``: the shipped detour scene, a → b, b → a (a, b its start and goal),
  ``repeat = 5``, seed 3 (issue 25's cycle);
- ``pick6``: a closed 6-move pick-and-place on the paper scene, ``repeat = 10``;
- ``bench12``: the 12-move cycle of issue 16 on the paper scene.

Each is timed as a user types it, whole process included:

1. ``adept-traj cycle FILE --out DIR/one --workers 1 --phase-grid N``;
2. the same with ``--workers 2`` (target: ≥ 1.8× faster than 1 on two free cores);
3. ``dask scheduler`` and two ``dask worker … --nthreads 1`` processes on 127.0.0.1
   (real TCP), then ``adept-traj cycle … --scheduler tcp://127.0.0.1:P``.

Then checks that the three runs give identical results (every task's front and best
trade-off bit for bit) and prints the cycle time of the phase-optimised plan (dynamic
programming over the grid) against the naive back-to-back plan that only adds the dwells
it needs, both certified at their start times.
"""

from __future__ import annotations

import argparse
import re
import socket
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

#: Speed-up of two local workers over one (issue #16).
TARGET_SPEEDUP = 1.8

LOCATIONS = """\
[[location]]
name = "home"
joints = [0.1682, 1.3849, 0.08, -0.7555]

[[location]]
name = "place"
joints = [-0.761, 0.245, 0.2, 1.0095]

[[location]]
name = "pick"
pose = [0.3, 0.5, 0.55, 0.0]

[[location]]
name = "feeder"
pose = [0.0, 0.6, 0.6, 0.5]

[[location]]
name = "tray"
pose = [0.7, 0.1, 0.5, 0.0]
"""

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

DETOUR_LOCATIONS = """\
[[location]]
name = "a"
joints = [0.1682, 1.3849, 0.08, -0.7555]

[[location]]
name = "b"
joints = [-0.7610, 0.2450, 0.20, 1.0095]
"""

#: name -> (scene, repeat, seed, locations, sequence)
CYCLES = {
    "detour": ("detour", 5, 3, DETOUR_LOCATIONS, [("a", "b"), ("b", "a")]),
    "pick6": ("paper", 10, 1, LOCATIONS, PICK6),
    "bench12": ("paper", 1, 1, LOCATIONS, SEQUENCE),
}


def cycle_text(name: str, pop: int, gens: int) -> str:
    """The benchmark's cycle file."""
    scene, repeat, seed, locations, sequence = CYCLES[name]
    moves = "".join(f'\n[[move]]\nfrom = "{a}"\nto = "{b}"\n' for a, b in sequence)
    head = (
        f'name = "{name}"\nscene = "{scene}"\nrepeat = {repeat}\n\n'
        f"[plan]\npop_size = {pop}\nn_gen = {gens}\nseed = {seed}\n\n"
    )
    return head + locations + moves


def timed(argv: list[str]) -> tuple[float, str]:
    """Wall time [s] and stderr of the command ``argv`` (checked: exit 0 or 1 = not all
    certified)."""
    t0 = time.perf_counter()
    run = subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if run.returncode not in (0, 1):
        raise SystemExit(f"{' '.join(argv)} exited with {run.returncode}: {run.stderr[-500:]}")
    return time.perf_counter() - t0, run.stderr


def pass_times(stderr: str) -> tuple[float, float | None]:
    """(optimised, naive) pass times [s] from the command's phase-grid line."""
    found = re.search(r"pass time ([0-9.]+) s, naive back-to-back ([0-9.]+|–) s", stderr)
    if found is None:
        raise SystemExit(f"no phase-grid line in: {stderr[-500:]}")
    naive = found.group(2)
    return float(found.group(1)), None if naive == "–" else float(naive)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_on_tcp(file: Path, out: Path, extra: list[str]) -> tuple[float, str]:
    """The cycle on a ``dask scheduler`` and two ``dask worker`` processes over TCP."""
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
        time.sleep(5.0)  # both workers registered
        return timed(["adept-traj", "cycle", str(file), "--out", str(out), "--quiet",
                      "--no-plots", "--no-playback", "--scheduler", address, *extra])  # fmt: skip
    finally:  # the workers first: a worker outliving its scheduler logs heartbeat errors
        for p in workers:
            p.terminate()
        for p in workers:
            p.wait(timeout=30)
        scheduler.terminate()
        scheduler.wait(timeout=30)


def same_results(outs: list[Path]) -> bool:
    """Whether every task's front and best trade-off are identical in all ``outs``."""
    names = sorted(p.name for p in (outs[0] / MOVES_FOLDER).iterdir())
    for name in names:
        loaded = [PlanningResult.load(o / MOVES_FOLDER / name) for o in outs]
        for r in loaded[1:]:
            if not (
                np.array_equal(r.front.x, loaded[0].front.x)
                and np.array_equal(r.best_x, loaded[0].best_x)
            ):
                print(f"task {name}: results differ")
                return False
    return True


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycle", choices=sorted(CYCLES), default="detour")
    parser.add_argument("--pop", type=int, default=100, help="population (default 100)")
    parser.add_argument("--gens", type=int, default=60, help="generations (default 60)")
    parser.add_argument("--phases", type=int, default=8, help="start phases per period")
    parser.add_argument("--out", type=Path, help="output folder (default: a temporary one)")
    args = parser.parse_args()
    root = args.out or Path(tempfile.mkdtemp(prefix="bench_cycle_"))
    root.mkdir(parents=True, exist_ok=True)
    file = root / f"{args.cycle}.toml"
    file.write_text(cycle_text(args.cycle, args.pop, args.gens))
    repeat = read_cycle_file(file).repeat
    grid = ["--phase-grid", str(args.phases)]
    base = ["adept-traj", "cycle", str(file), "--quiet", "--no-plots", "--no-playback", "--out"]
    t1, err1 = timed([*base, str(root / "one"), "--workers", "1", *grid])
    t2, _ = timed([*base, str(root / "two"), "--workers", "2", *grid])
    t_tcp, _ = run_on_tcp(file, root / "tcp", grid)
    same = same_results([root / "one", root / "two", root / "tcp"])
    best, naive = pass_times(err1)
    speedup = t1 / t2
    tasks = len(read_cycle_file(file).moves) * args.phases
    print(f"{args.cycle} cycle, NSGA-II {args.pop} × {args.gens}, {args.phases} phases "
          f"({tasks} tasks), load {load_average()}, results in {root}")  # fmt: skip
    print(
        f"  cycle time, phase-optimised: {repeat * best:8.3f} s ({best:.3f} s per pass × {repeat})"
    )
    if naive is None:
        print("  cycle time, naive back-to-back: no certified schedule")
    else:
        print(f"  cycle time, naive back-to-back: {repeat * naive:8.3f} s "
              f"(gain {100 * (1 - best / naive):.1f} %)")  # fmt: skip
    print(f"  1 local worker : {t1:7.1f} s")
    print(f"  2 local workers: {t2:7.1f} s   speed-up {speedup:.2f}× (target ≥ {TARGET_SPEEDUP}×)"
          f"  {'OK' if speedup >= TARGET_SPEEDUP else 'MISSED'}")  # fmt: skip
    print(f"  scheduler + 2 dask workers over TCP: {t_tcp:7.1f} s")
    print(f"  identical results (1, 2 workers, TCP): {'yes' if same else 'NO'}")
    budget = f"NSGA-II {args.pop} × {args.gens}, {args.phases} phases, {tasks} tasks"
    figure(f"{args.cycle}_one_worker", f"{args.cycle} cycle on 1 local Dask worker", round(t1, 1),
           "s", note=budget)  # fmt: skip
    figure(f"{args.cycle}_speedup", f"{args.cycle} cycle: 2 local workers vs 1", round(speedup, 2),
           "×", target=f"≥ {TARGET_SPEEDUP}×", met=speedup >= TARGET_SPEEDUP,
           note=f"{t2:.1f} s on 2 workers")  # fmt: skip
    figure(f"{args.cycle}_tcp", f"{args.cycle} cycle on a scheduler + 2 dask workers over TCP",
           round(t_tcp, 1), "s", note=f"identical results: {'yes' if same else 'NO'}")  # fmt: skip
    sys.exit(0 if same else 1)


if __name__ == "__main__":
    with recorded(__file__, "work cycles on Dask: one worker, two, a scheduler over TCP"):
        main()
