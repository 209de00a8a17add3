"""The start of ``adept-traj plan`` (issue #15): its import, its ``--help`` and a tiny run, each
a fresh process, and which heavy modules it loads.

Run: ``python benchmarks/bench_imports.py [--repeat 5] [--baseline DIR]``.

- ``import adept_traj.cli.plan`` in a fresh process: wall time and CPU time (the process'
  own, ``resource.getrusage`` of the child), and the modules of :data:`WATCHED` it loaded;
- ``python -m adept_traj.cli plan --help`` (wall);
- a tiny run, ``plan --pop 20 --gens 2 --no-polish --no-plots --no-html --workers 1`` (wall
  and CPU): the whole process from its start to its first generations and out;
- ``--baseline DIR``: the same for another copy of the code (e.g. ``git archive`` of an
  earlier commit unpacked in DIR), run by run alternately (paired on a shared machine), and
  the medians of the ratios this/baseline.

Target (issue #15): nothing heavy that the run does not use on the path of the command —
no ``scipy`` (``scipy.spatial`` was pulled by pymoo's NSGA-II module, ``numpy.f2py`` by
scipy's array API) and no ``urllib``/``http``/``email``/``ssl`` through
``xml.sax.saxutils``. (moocore, which the loop uses every generation, imports
``urllib.request`` itself.)
"""

from __future__ import annotations

import argparse
import ast
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _results import recorded  # benchmarks/_results.py
from _timing import compared_codes, load_average  # benchmarks/_timing.py

HERE = Path(__file__).resolve().parent.parent

#: Modules whose presence after the import is reported.
WATCHED = ("scipy", "scipy.spatial", "scipy.sparse", "numpy.f2py", "xml.sax.saxutils")

_IMPORT = (
    f"import sys, adept_traj.cli.plan\nprint(sorted(m for m in {WATCHED!r} if m in sys.modules))"
)


def _run(code: Path, args: list[str]) -> tuple[float, float, str]:
    """Wall [s], CPU [s] (user + system) and stdout of ``python ARGS`` run in ``code``."""
    env = {**os.environ, "PYTHONPATH": str(code)}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    out = subprocess.run(
        [sys.executable, *args], cwd=code, env=env, capture_output=True, text=True, check=True
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, out.stdout


def measure(code: Path) -> dict[str, float | str]:
    """One round of the three measurements of ``code``."""
    wall, cpu, out = _run(code, ["-c", _IMPORT])
    row: dict[str, float | str] = {"import_wall": wall, "import_cpu": cpu}
    row["loaded"] = ", ".join(ast.literal_eval(out.strip().splitlines()[-1])) or "none"
    row["help_wall"] = _run(code, ["-m", "adept_traj.cli", "plan", "--help"])[0]
    with tempfile.TemporaryDirectory() as folder:
        tiny = ["-m", "adept_traj.cli", "plan", "--pop", "20", "--gens", "2", "--no-polish"]
        tiny += ["--no-plots", "--no-html", "--workers", "1", "--out", folder]
        row["tiny_wall"], row["tiny_cpu"], _ = _run(code, tiny)
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="rounds (fresh processes)")
    parser.add_argument("--baseline", type=Path, help="another copy of the code to compare")
    args = parser.parse_args()
    codes = compared_codes(HERE, args.baseline)
    print(f"load average at start {load_average()}; {args.repeat} rounds, medians [s]")
    rows: dict[str, list[dict[str, float | str]]] = {label: [] for label in codes}
    for _ in range(args.repeat):
        for label, code in codes.items():  # alternated: paired runs
            rows[label].append(measure(code))
    keys = ("import_wall", "import_cpu", "help_wall", "tiny_wall", "tiny_cpu")
    for label, runs in rows.items():
        figures = ", ".join(f"{k} {statistics.median(r[k] for r in runs):.3f}" for k in keys)
        print(f"{label:8s} {figures}; loaded by the import: {runs[-1]['loaded']}")
    if len(rows) == 2:
        pairs = list(zip(rows["baseline"], rows["this"], strict=True))
        ratios = ", ".join(
            f"{k} {statistics.median(b[k] / a[k] for a, b in pairs):.2f}" for k in keys
        )
        print(f"ratios this/baseline (medians of the pairs): {ratios}")


if __name__ == "__main__":
    with recorded(__file__, "the start of `adept-traj plan`: its import, `--help` and a tiny run"):
        main()
