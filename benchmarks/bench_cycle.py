"""A 12-move cycle on Dask: one worker against two, and a scheduler + workers over TCP.

Run: ``python benchmarks/bench_cycle.py [--pop 100] [--gens 100] [--out DIR]``
(the defaults are the paper's NSGA-II budget; takes several minutes).

Writes a 12-move cycle file of the paper scene (five locations, poses and joints) and
times the command as a user types it, whole process included:

1. ``adept-traj cycle FILE --out DIR/one --workers 1``;
2. ``adept-traj cycle FILE --out DIR/two --workers 2`` (target: ≥ 1.8× faster than 1,
   issue #16; on a machine with two free cores);
3. ``dask scheduler`` and two ``dask worker … --nthreads 1`` processes on 127.0.0.1
   (real TCP), then ``adept-traj cycle FILE --out DIR/tcp --scheduler tcp://127.0.0.1:P``.

Then checks that the three runs give identical results (every move's front and best
trade-off bit for bit) and prints the figures against the target.
"""

from __future__ import annotations

import argparse
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

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


def cycle_text(pop: int, gens: int) -> str:
    """The benchmark's cycle file."""
    moves = "".join(f'\n[[move]]\nfrom = "{a}"\nto = "{b}"\n' for a, b in SEQUENCE)
    head = f'name = "bench12"\nscene = "paper"\n\n[plan]\npop_size = {pop}\nn_gen = {gens}\n\n'
    return head + LOCATIONS + moves


def timed(argv: list[str]) -> float:
    """Wall time [s] of the command ``argv`` (checked: exit 0 or 1 = not all certified)."""
    t0 = time.perf_counter()
    code = subprocess.run(argv, stdout=subprocess.DEVNULL, check=False).returncode
    if code not in (0, 1):
        raise SystemExit(f"{' '.join(argv)} exited with {code}")
    return time.perf_counter() - t0


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run_on_tcp(file: Path, out: Path) -> float:
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
                      "--no-plots", "--scheduler", address])  # fmt: skip
    finally:  # the workers first: a worker outliving its scheduler logs heartbeat errors
        for p in workers:
            p.terminate()
        for p in workers:
            p.wait(timeout=30)
        scheduler.terminate()
        scheduler.wait(timeout=30)


def same_results(file: Path, outs: list[Path]) -> bool:
    """Whether every move's front and best trade-off are identical in all ``outs``."""
    for move in read_cycle_file(file).moves:
        loaded = [PlanningResult.load(o / MOVES_FOLDER / move.name) for o in outs]
        for r in loaded[1:]:
            if not (
                np.array_equal(r.front.x, loaded[0].front.x)
                and np.array_equal(r.best_x, loaded[0].best_x)
            ):
                print(f"move {move.name}: results differ")
                return False
    return True


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pop", type=int, default=100, help="population (paper NSGA-II: 100)")
    parser.add_argument("--gens", type=int, default=100, help="generations (paper: 100)")
    parser.add_argument("--out", type=Path, help="output folder (default: a temporary one)")
    args = parser.parse_args()
    root = args.out or Path(tempfile.mkdtemp(prefix="bench_cycle_"))
    root.mkdir(parents=True, exist_ok=True)
    file = root / "bench12.toml"
    file.write_text(cycle_text(args.pop, args.gens))
    base = ["adept-traj", "cycle", str(file), "--quiet", "--no-plots", "--out"]
    t1 = timed([*base, str(root / "one"), "--workers", "1"])
    t2 = timed([*base, str(root / "two"), "--workers", "2"])
    t_tcp = run_on_tcp(file, root / "tcp")
    same = same_results(file, [root / "one", root / "two", root / "tcp"])
    speedup = t1 / t2
    print(f"12-move cycle, NSGA-II {args.pop} × {args.gens}, results in {root}")
    print(f"  1 local worker : {t1:7.1f} s")
    print(f"  2 local workers: {t2:7.1f} s   speed-up {speedup:.2f}× (target ≥ {TARGET_SPEEDUP}×)"
          f"  {'OK' if speedup >= TARGET_SPEEDUP else 'MISSED'}")  # fmt: skip
    print(f"  scheduler + 2 dask workers over TCP: {t_tcp:7.1f} s")
    print(f"  identical results (1, 2 workers, TCP): {'yes' if same else 'NO'}")
    sys.exit(0 if same else 1)


if __name__ == "__main__":
    main()
