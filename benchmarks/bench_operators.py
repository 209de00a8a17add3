"""The optimiser's own time (issue #15): pymoo's ask and tell, per generation, and the whole
``adept-traj plan`` on one worker, in process CPU time.

Run: ``python benchmarks/bench_operators.py [--seeds 1,2,3] [--algorithms nsga2,mode]
[--plan] [--repeat 3] [--baseline DIR]``.

- For each algorithm and seed, one process runs :func:`adept_traj.optimise.optimise` on the
  paper problem (one worker, the paper's budget) and measures the CPU time of every
  ``ask`` (mating: operators, repair, duplicate elimination), every ``tell`` (survival,
  bookkeeping) and every evaluation; it prints the medians per generation (the first,
  the initial population, left out), the totals, and a SHA-256 of the final population
  and the per-generation fronts (the same seed must give the same hash, bit for bit).
- ``--checkpoint``: the runs keep a checkpoint folder as ``plan`` does (one write a
  second; the per-generation bookkeeping of the checkpoint is the optimiser's).
- ``--plan``: the whole command ``python -m adept_traj.cli plan --workers 1 --out DIR``
  (``--algorithm mode`` for MODE) as a separate process, its CPU time with its children's
  (``resource.getrusage``), ``--repeat`` runs, medians.
- ``--baseline DIR``: the same measurements of another copy of the code (e.g. ``git
  archive`` of an earlier commit unpacked in DIR), alternated run by run with this one
  (paired A/B on a shared machine), and the ratios new/baseline.

With ``--baseline``, the optimiser's ratio (all but the evaluations, per run) is printed
against issue #15's target for this pass on the time between generations,
:data:`TARGET_RATIO` (−30 %);
the whole job's targets are in ``benchmarks/bench_job.py``.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from _results import recorded  # benchmarks/_results.py
from _timing import compared_codes, load_average  # benchmarks/_timing.py

HERE = Path(__file__).resolve().parent.parent

#: Issue #15 (fourth pass): the main process' CPU between generations (all but the
#: evaluations) −30 % or more.
TARGET_RATIO = 0.7

_LOOP = r"""
import hashlib, sys, time
import numpy as np
from adept_traj import Robot, Scene
from adept_traj.optimise import make_algorithm, optimise
from adept_traj.problem import TrajectoryProblem

name, seed, folder = sys.argv[1], int(sys.argv[2]), sys.argv[3] or None
scene = Scene.paper()
problem = TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal, workers=1)
algorithm, settings = make_algorithm(name)
cpu = time.process_time
spent = {"ask": [], "tell": [], "eval": []}

def timed(key, fn):
    def call(*args, **kwargs):
        t0 = cpu()
        out = fn(*args, **kwargs)
        spent[key].append(cpu() - t0)
        return out
    return call

algorithm.ask, algorithm.tell = timed("ask", algorithm.ask), timed("tell", algorithm.tell)
setup = algorithm.setup

def timed_setup(*args, **kwargs):
    out = setup(*args, **kwargs)
    algorithm.evaluator.eval = timed("eval", algorithm.evaluator.eval)
    return out

algorithm.setup = timed_setup
t0 = cpu()
state = optimise(problem, algorithm, settings.n_gen, seed, checkpoint=folder)
total = cpu() - t0
digest = hashlib.sha256()
for a in (state.X, state.F, state.G, state.CV, *state.fronts):
    digest.update(np.ascontiguousarray(a).tobytes())
ask, tell, ev = (np.array(spent[k]) for k in ("ask", "tell", "eval"))
print(digest.hexdigest()[:16], np.median(ask[1:]), np.median(tell[1:]), ask.sum(), tell.sum(),
      total - ev.sum(), ev.sum(), total)
"""


def loop_run(code: Path, name: str, seed: int, checkpoint: bool) -> dict[str, float | str]:
    """One optimiser run in a fresh process with ``code`` first on the path (checkpointed
    as ``plan`` does, into a temporary folder, if ``checkpoint``)."""
    env = {**os.environ, "PYTHONPATH": str(code)}
    with tempfile.TemporaryDirectory() as folder:
        out = subprocess.run(  # in ``code``: ``-c`` puts the working directory first
            [sys.executable, "-c", _LOOP, name, str(seed), folder if checkpoint else ""],
            cwd=code,
            env=env,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split()
    keys = ("ask_ms", "tell_ms", "ask_s", "tell_s", "optimiser_s", "eval_s", "total_s")
    values = [float(v) for v in out[1:]]
    values[0] *= 1e3
    values[1] *= 1e3
    return {"hash": out[0], **dict(zip(keys, values, strict=True))}


def plan_run(code: Path, name: str) -> float:
    """CPU time [s] of ``adept-traj plan --workers 1`` (with its children), run in ``code``
    (``-m`` puts the working directory first on the path)."""
    env = {**os.environ, "PYTHONPATH": str(code)}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    with tempfile.TemporaryDirectory() as out:
        command = [sys.executable, "-m", "adept_traj.cli", "plan", "--workers", "1"]
        command += ["--algorithm", name, "--out", out]
        subprocess.run(command, cwd=code, env=env, capture_output=True, check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="1,2,3")
    parser.add_argument("--algorithms", default="nsga2,mode")
    parser.add_argument("--plan", action="store_true", help="also time the whole command")
    parser.add_argument(
        "--checkpoint", action="store_true", help="checkpoint the runs as plan does"
    )
    parser.add_argument("--repeat", type=int, default=3, help="runs of each command")
    parser.add_argument("--baseline", type=Path, help="another copy of the code to compare")
    args = parser.parse_args()
    codes = compared_codes(HERE, args.baseline)
    print(f"load average at start {load_average()}; CPU times (process_time), medians")
    for name in args.algorithms.split(","):
        for seed in (int(s) for s in args.seeds.split(",")):
            rows = {
                label: loop_run(code, name, seed, args.checkpoint) for label, code in codes.items()
            }
            for label, r in rows.items():
                print(
                    f"{name} seed {seed} {label:8s} hash {r['hash']}  per generation: ask "
                    f"{r['ask_ms']:.2f} ms, tell {r['tell_ms']:.2f} ms; whole run: ask "
                    f"{r['ask_s']:.2f} s, tell {r['tell_s']:.2f} s, optimiser (all but the "
                    f"evaluations) {r['optimiser_s']:.2f} s, evaluations {r['eval_s']:.2f} s"
                )
            if len(rows) == 2:
                a, b = rows["baseline"], rows["this"]
                same = "identical" if a["hash"] == b["hash"] else "DIFFERENT"
                ratio = b["optimiser_s"] / a["optimiser_s"]
                verdict = "met" if ratio <= TARGET_RATIO else "NOT met"
                print(
                    f"{name} seed {seed} ratios this/baseline: ask {b['ask_ms'] / a['ask_ms']:.2f}"
                    f", tell {b['tell_ms'] / a['tell_ms']:.2f}, optimiser {ratio:.2f} (target "
                    f"≤ {TARGET_RATIO}: {verdict}); runs {same}"
                )
        if args.plan:
            times: dict[str, list[float]] = {label: [] for label in codes}
            for _ in range(args.repeat):
                for label, code in codes.items():  # alternated: paired runs
                    times[label].append(plan_run(code, name))
            for label, t in times.items():
                runs = ", ".join(f"{x:.2f}" for x in t)
                median = statistics.median(t)
                print(f"plan --algorithm {name} --workers 1, {label}: CPU {median:.2f} s ({runs})")
            if len(times) == 2:
                ratios = [b / a for a, b in zip(times["baseline"], times["this"], strict=True)]
                ratio = statistics.median(ratios)
                print(f"plan {name} ratio this/baseline (paired runs): median {ratio:.3f}")


if __name__ == "__main__":
    with recorded(__file__, "the optimiser's own time between generations (issue #15)"):
        main()
