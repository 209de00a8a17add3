"""The critical path after the search of ``adept-traj plan --out DIR`` (issue #15, fourth
pass): the polish, the front's certificates and the finish, two checkouts alternately.

Run: ``python benchmarks/bench_post.py OTHER_CHECKOUT [--repeat 6] [-- PLAN OPTIONS]``.

Each repeat runs the whole command as typed (``python -m adept_traj.cli plan --quiet
--out DIR``, in a fresh process) once with ``PYTHONPATH`` set to this checkout and once to
``OTHER_CHECKOUT`` (e.g. the version before a change), in alternating order, so that both
see the same load. A small wrapper (``python -c``, the command's own ``main``) stamps the
wall time of the phases in the command's process: the end of the search (the optimiser
returns), the end of the certificates (the reported member's certificate made, i.e. the
polish and the front's certificates done), the start of the finish and the process' end.
Per run it records these, the process' wall time and the CPU time of the process and
everything it forked. It prints medians, the ratios of the medians, and the load average
before and after: the gain of a change is the ratio of the phases after the search (the
search itself is the same code in both, its time is noise).

Target of the fourth pass: −0.6 s of wall time after the search on an idle machine.
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

_WRAPPED = """
import json, sys, time
t0 = time.perf_counter()
marks = {}
import adept_traj.cli.plan as command
import adept_traj.optimise.planner as planner
from adept_traj.cli.app import main

def stamped(module, name, key, at_end):
    real = getattr(module, name)
    def wrapper(*args, **kwargs):
        if not at_end:
            marks[key] = time.perf_counter() - t0
        try:
            return real(*args, **kwargs)
        finally:
            if at_end:
                marks[key] = time.perf_counter() - t0
    setattr(module, name, wrapper)

stamped(planner, "optimise", "search", True)
stamped(planner, "_certified_choice", "certified", True)
stamped(command, "_finish", "finish", False)
code = main(sys.argv[2:])
marks["end"] = time.perf_counter() - t0
with open(sys.argv[1], "w") as f:
    json.dump(marks, f)
sys.exit(code)
"""

#: The columns printed (phase: how it is computed from the marks).
_PHASES = {
    "search ends": lambda m: m["search"],
    "polish + certificates": lambda m: m["certified"] - m["search"],
    "finish": lambda m: m["end"] - m["finish"],
    "after the search": lambda m: m["end"] - m["search"],
}


def plan_once(pythonpath: str, folder: Path, options: list[str]) -> dict[str, float]:
    """The phases [s] of one ``plan``, its wall [s] and CPU [s] (with its children)."""
    marks_file = folder.with_suffix(".json")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    command = [sys.executable, "-c", _WRAPPED, str(marks_file), "plan", "--quiet", *options]
    subprocess.run(
        [*command, "--out", str(folder)],
        cwd=folder.parent,  # not a checkout: ``python -c`` puts the working folder first
        env={**os.environ, "PYTHONPATH": pythonpath},
        check=True,
        stdout=subprocess.DEVNULL,
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    marks = json.loads(marks_file.read_text())
    out = {name: phase(marks) for name, phase in _PHASES.items()}
    out["wall"] = wall
    out["cpu"] = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("other", help="another checkout, timed alternately with this one")
    parser.add_argument("--repeat", type=int, default=6, help="runs of each (default 6)")
    args, options = parser.parse_known_args()
    args.options = [o for o in options if o != "--"]
    versions = {
        "other": str(Path(args.other).resolve()),
        "this checkout": str(Path(__file__).resolve().parent.parent),
    }
    print(f"load average at start: {load_average()}")
    runs: dict[str, list[dict[str, float]]] = {name: [] for name in versions}
    with tempfile.TemporaryDirectory(prefix="bench_post_") as tmp:
        for k in range(args.repeat):
            for name in pair_order(list(versions), k):
                folder = Path(tmp) / f"{k}_{name.replace(' ', '_')}"
                runs[name].append(plan_once(versions[name], folder, args.options))
    print(f"load average at end: {load_average()}")
    keys = [*_PHASES, "wall", "cpu"]
    print("| version | " + " | ".join(f"{k} [s]" for k in keys) + " |")
    print("|---|" + "---|" * len(keys))
    medians = {}
    for name, rows in runs.items():
        medians[name] = {k: statistics.median(r[k] for r in rows) for k in keys}
        print(f"| {name} | " + " | ".join(f"{medians[name][k]:.2f}" for k in keys) + " |")
    new, old = medians["this checkout"], medians["other"]
    print("| this / other | " + " | ".join(f"{new[k] / old[k]:.2f}" for k in keys) + " |")
    after = [r["after the search"] for r in runs["this checkout"]]
    before = [r["after the search"] for r in runs["other"]]
    pairs = ", ".join(f"{b:.2f}→{a:.2f}" for b, a in zip(before, after))
    print(f"after the search, pair by pair: {pairs}")
    gain = statistics.median(b - a for b, a in zip(before, after))
    print(f"median gain after the search: {gain:.2f} s (target ≥ 0.6 s on an idle machine)")


if __name__ == "__main__":
    with recorded(__file__, "the critical path after the search, two checkouts alternately"):
        main()
