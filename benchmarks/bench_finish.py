"""The finish of ``adept-traj plan``: everything after the optimiser returns (issue #15).

Run: ``python benchmarks/bench_finish.py RESULT_DIR [--repeat 3] [--compare OTHER_CHECKOUT]``.

``RESULT_DIR`` is the folder of a finished ``adept-traj plan`` run (e.g. ``adept-traj plan
--out out``). Each repeat starts a fresh process (matplotlib and meshcat not yet imported,
as in a real run), loads the result and calls ``adept_traj.cli.plan._finish`` on a new
folder: ``result.json`` and the CSV files, ``playback.html``, the five figures, the summary
and the completion mark. It prints the wall time and the CPU time of ``_finish`` alone,
medians over the repeats: in all, in the process itself, and in the processes it forked
(and waited for). On a loaded machine the wall time follows the CPU time; the split tells
how much of it the main process waits for on an idle one.

``--helper``: also time this checkout's ``_finish`` with the helper process of
:mod:`adept_traj.viz.finisher` (started before the timing, as ``plan`` starts it with the
run, and waited for until its imports are done, as on an idle machine): the main process
then saves ``result.json`` while the helper, whose imports are done, draws and writes the
page. Its CPU columns count the helper's imports too (done during a real run, at nice 19; the
helper is reaped, and its CPU time counted, inside ``_finish``).

``--compare OTHER_CHECKOUT`` runs the same measurement with ``PYTHONPATH=OTHER_CHECKOUT``
(e.g. an older version of the code) alternately with this checkout, so that both see the
same load: the figures to compare are the ratios of the two medians.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from _results import recorded  # benchmarks/_results.py
from _timing import load_average  # benchmarks/_timing.py

_FINISH = """
import argparse, json, resource, sys, time
from pathlib import Path
from adept_traj.results import PlanningResult, Replay
from adept_traj.cli import plan as cli_plan

result = PlanningResult.load(sys.argv[1])
replay = Replay.of(result)
problem = argparse.Namespace(robot=replay.robot, scene=replay.scene)
opts = argparse.Namespace(
    no_html=False, no_plots=False, ros=None, allow_infeasible=False, algorithm=result.algorithm
)
folder = Path(sys.argv[2])
folder.mkdir()
finisher = None
if sys.argv[3] == "helper":
    from adept_traj.viz.finisher import start_finisher

    finisher = start_finisher(replay.robot, replay.scene, figures=True, html=True)
    assert finisher.ready(120.0), "the helper did not get ready"

def cpu(who):
    use = resource.getrusage(who)
    return use.ru_utime + use.ru_stime

own0, kids0, t0 = cpu(resource.RUSAGE_SELF), cpu(resource.RUSAGE_CHILDREN), time.perf_counter()
code = cli_plan._finish(result, problem, folder, opts, *([finisher] if finisher else []))
wall = time.perf_counter() - t0
own, kids = cpu(resource.RUSAGE_SELF) - own0, cpu(resource.RUSAGE_CHILDREN) - kids0
import adept_traj
print(json.dumps({"code": code, "wall": wall, "cpu": own + kids, "own": own, "kids": kids,
                  "code_path": adept_traj.__file__}))
"""


def finish_once(pythonpath: str, result_dir: str, out: Path, helper: bool = False) -> dict:
    """Wall and CPU time [s] of one ``_finish`` in a fresh process with ``pythonpath``
    (``helper``: with a ready helper process)."""
    env = {**os.environ, "PYTHONPATH": pythonpath}
    # run in the output's folder: ``python -c`` puts its working folder first on sys.path
    done = subprocess.run(
        [sys.executable, "-c", _FINISH, str(Path(result_dir).resolve()), str(out),
         "helper" if helper else "plain"],
        env=env, cwd=out.parent, check=True, capture_output=True, text=True,
    )  # fmt: skip
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("result_dir", help="folder of a finished adept-traj plan run")
    parser.add_argument("--repeat", type=int, default=3, help="runs of each version (default 3)")
    parser.add_argument("--compare", help="another checkout, timed alternately with this one")
    parser.add_argument("--helper", action="store_true", help="also with a ready helper")
    args = parser.parse_args()
    here = str(Path(__file__).resolve().parent.parent)
    versions = {"this checkout": here}
    if args.helper:
        versions["this checkout, helper"] = here
    if args.compare:
        versions["--compare"] = str(Path(args.compare).resolve())
    print(f"load average at start: {load_average()}")
    runs: dict[str, list[dict]] = {name: [] for name in versions}
    with tempfile.TemporaryDirectory(prefix="bench_finish_") as tmp:
        for _ in range(args.repeat):
            for name, path in versions.items():
                label = name.strip("-").replace(" ", "_").replace(",", "")
                out = Path(tmp) / f"{len(runs[name])}_{label}"
                helper = name.endswith("helper")
                runs[name].append(finish_once(path, args.result_dir, out, helper))
    print(f"load average at end: {load_average()}")
    print("| version | wall [s] | CPU [s] | CPU of the process [s] | CPU forked [s] | wall runs |")
    print("|---|---|---|---|---|---|")
    medians = {}
    for name, rows in runs.items():
        wall, cpu, own, kids = (
            statistics.median(r[key] for r in rows) for key in ("wall", "cpu", "own", "kids")
        )
        medians[name] = (wall, cpu)
        assert all(r["code_path"].startswith(versions[name]) for r in rows), rows
        walls = ", ".join(f"{r['wall']:.2f}" for r in rows)
        print(f"| {name} | {wall:.2f} | {cpu:.2f} | {own:.2f} | {kids:.2f} | {walls} |")
    if args.compare:
        (w1, c1), (w0, c0) = medians["this checkout"], medians["--compare"]
        print(f"this checkout / --compare: wall {w1 / w0:.2f}x, CPU {c1 / c0:.2f}x")
    if args.helper:
        (w1, c1), (w0, c0) = medians["this checkout, helper"], medians["this checkout"]
        print(f"with the helper / without: wall {w1 / w0:.2f}x, CPU {c1 / c0:.2f}x")


if __name__ == "__main__":
    with recorded(
        __file__,
        "the finish of `adept-traj plan` (after the optimiser), two checkouts alternately",
    ):
        main()
