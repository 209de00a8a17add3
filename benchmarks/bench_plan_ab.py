"""``adept-traj plan --out DIR`` as typed, two checkouts alternately (issue #15: the finish).

Run: ``python benchmarks/bench_plan_ab.py OTHER_CHECKOUT [--repeat 4] [-- PLAN OPTIONS]``.

``OTHER_CHECKOUT`` may be ``no-helper``: this checkout with the helper process of
:mod:`adept_traj.viz.finisher` left out (``python -c``, ``_finisher`` replaced by an empty
context: the files are then written as before the helper existed), to measure what the
helper costs the run (``timing.total_s``) and saves at its end.

Each repeat runs the whole command in a fresh process, once with ``PYTHONPATH`` set to
this checkout and once to ``OTHER_CHECKOUT`` (e.g. the version before a change), in
alternating order, so that both see the same load. Per run it records the process' wall
time, the CPU time of the process and everything it forked (``RUSAGE_CHILDREN``), and
the run's own wall time as ``result.json`` stores it (``timing.total_s``: the optimiser,
the polish and the certificates, from the problem built to the result: what a helper
process started with the run could slow down). It prints medians and the ratios of the
medians, with the load average before and after.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _results import recorded  # benchmarks/_results.py
from _timing import load_average, pair_order  # benchmarks/_timing.py


def command() -> list[str]:
    """The console script beside this Python, else ``python -m adept_traj.cli``."""
    script = Path(sys.executable).parent / "adept-traj"
    return [str(script)] if script.is_file() else [sys.executable, "-m", "adept_traj.cli"]


_NO_HELPER = """
import contextlib, sys
import adept_traj.cli.plan as plan_command
from adept_traj.cli.app import main
plan_command._finisher = lambda *_args: contextlib.nullcontext(None)
sys.exit(main(sys.argv[1:]))
"""


def plan_once(
    pythonpath: str, out: Path, options: list[str], helper: bool = True
) -> dict[str, float]:
    """Wall [s], CPU [s] (with its children) and the stored run time [s] of one ``plan``
    (``helper=False``: with the helper process left out)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    cmd = command() if helper else [sys.executable, "-c", _NO_HELPER]
    subprocess.run(
        [*cmd, "plan", "--quiet", *options, "--out", str(out)],
        env={**os.environ, "PYTHONPATH": pythonpath},
        check=True,
        stdout=subprocess.DEVNULL,
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    run = json.loads((out / "result.json").read_text())["timing"]["total_s"]
    return {"wall": wall, "cpu": cpu, "run": run}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("other", help="another checkout, timed alternately with this one")
    parser.add_argument("--repeat", type=int, default=4, help="runs of each (default 4)")
    parser.add_argument("options", nargs="*", help="more plan options (after --)")
    args = parser.parse_args()
    here = str(Path(__file__).resolve().parent.parent)
    versions = {
        "this checkout": here,
        "other": here if args.other == "no-helper" else str(Path(args.other).resolve()),
    }
    print(f"load average at start: {load_average()}")
    runs: dict[str, list[dict[str, float]]] = {name: [] for name in versions}
    with tempfile.TemporaryDirectory(prefix="bench_plan_ab_") as tmp:
        for k in range(args.repeat):
            for name in pair_order(list(versions), k):
                out = Path(tmp) / f"{k}_{name.replace(' ', '_')}"
                helper = name != "other" or args.other != "no-helper"
                runs[name].append(plan_once(versions[name], out, args.options, helper))
    print(f"load average at end: {load_average()}")
    print("| version | wall [s] | CPU [s] | run (timing.total_s) [s] | wall runs |")
    print("|---|---|---|---|---|")
    medians = {}
    for name, rows in runs.items():
        med = {key: statistics.median(r[key] for r in rows) for key in ("wall", "cpu", "run")}
        medians[name] = med
        walls = ", ".join(f"{r['wall']:.2f}" for r in rows)
        print(f"| {name} | {med['wall']:.2f} | {med['cpu']:.2f} | {med['run']:.2f} | {walls} |")
    new, old = medians["this checkout"], medians["other"]
    print(
        "this checkout / other: "
        + ", ".join(f"{key} {new[key] / old[key]:.2f}x" for key in ("wall", "cpu", "run"))
    )


if __name__ == "__main__":
    with recorded(__file__, "`adept-traj plan --out DIR` as typed, two checkouts alternately"):
        main()
