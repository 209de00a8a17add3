"""The phases of ``plan`` after the search (the polish, the front's certificates and the
reported solution's certificate), timed alone, two versions of the code alternately.

Run: ``python benchmarks/bench_post_search.py [--baseline CHECKOUT] [--runs 5]
[--cases nsga2:1,mode:1,ur5:1] [--states DIR] [--workers 2]``.

1. Each case's final population (the search, unchanged by the polish: ``plan`` with its
   ``optimise`` replaced by one that stores the :class:`~adept_traj.optimise.RunState` it
   returns) is made once and kept in ``--states`` (default: a folder in the temporary
   directory), so that every timed run starts from the same population.
2. Every run is a fresh process (``PYTHONPATH`` = the version's checkout) that loads the
   state, builds the problem (``--workers`` processes, the command's default on this
   machine) and calls ``plan`` with ``optimise`` replaced by a function that returns the
   stored state: what is timed is everything ``plan`` does after the search (wall time,
   and process CPU time with its children, :func:`resource.getrusage`). The baseline and
   this checkout alternate run by run (paired), so that the machine's load drifts alike
   for both. The phases are timed too (wall and CPU): the polish, the front's
   certificates and the reported solution's certificate (``_polish_run``,
   ``_certify_front``, ``_certified_choice`` of the code before; ``PostSearch.polish`` and
   ``PostSearch.certificates``, which includes the choice, of this one).
3. Each run prints a SHA-256 of its result as ``result.json`` encodes it, without the
   timing (the measured times), OO and AE (computed from them) and the workers: the two
   versions must give the same hash (the same front, certificates, choice and T_best).

Cases: ``nsga2:SEED`` and ``mode:SEED`` are the paper problem at the paper budgets;
``ur5:SEED`` the UR5 around a box with self-collision (``examples/data/ur5_box.toml``,
60 × 30, as ``examples/ur5_around_a_box.py``).
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent

#: The code run in each timed process: ``argv`` = state file, case, workers.
CHILD = r"""
import hashlib, json, pickle, resource, sys, time
import adept_traj as at
from adept_traj.optimise import planner
from adept_traj.results.json_codec import _encode

sys.path.insert(0, sys.argv[4])
from bench_post_search import make_problem

state_file, case, workers = sys.argv[1], sys.argv[2], int(sys.argv[3])
with open(state_file, "rb") as f:
    state, kwargs = pickle.load(f)
problem = make_problem(case, workers)
planner.optimise = lambda *a, **k: state


def _cpu():
    s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime


phases = {}


def timed(owner, name, label):  # wrap owner.name: its wall and CPU time into phases[label]
    real = getattr(owner, name)

    def wrapper(*args, **kw):
        w, c = time.perf_counter(), _cpu()
        try:
            return real(*args, **kw)
        finally:
            old = phases.get(label, (0.0, 0.0))
            phases[label] = (old[0] + time.perf_counter() - w, old[1] + _cpu() - c)

    setattr(owner, name, wrapper)


if hasattr(planner, "_polish_run"):  # the code before issue #15's post-search
    timed(planner, "_polish_run", "polish")
    timed(planner, "_certify_front", "certificates")
    timed(planner, "_certified_choice", "choice")
else:
    from adept_traj.optimise import post_search

    timed(post_search.PostSearch, "polish", "polish")
    timed(post_search.PostSearch, "certificates", "certificates")
w0, c0 = time.perf_counter(), _cpu()
result = planner.plan(problem, **kwargs)
wall, cpu = time.perf_counter() - w0, _cpu() - c0
problem.close()
doc = _encode(result)
doc.pop("timing")
doc["metrics"].pop("OO")
doc["metrics"].pop("AE")
doc["problem_settings"].pop("workers")
digest = hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()[:16]
out = {"wall": wall, "cpu": cpu, "hash": digest, "front": len(result.front), "phases": phases}
print(json.dumps(out))
"""


def make_problem(case: str, workers: int):
    """The problem of ``case`` (``nsga2:SEED``, ``mode:SEED`` or ``ur5:SEED``)."""
    import adept_traj as at

    kind = case.split(":")[0]
    if kind == "ur5":
        from adept_traj.robot import installed_data_dirs

        share = next(d for d in installed_data_dirs() if (d / "example-robot-data").is_dir())
        robots = share / "example-robot-data/robots/ur_description"
        robot = at.Robot.from_urdf(
            robots / "urdf/ur5_robot.urdf",
            HERE / "examples/data/ur5.toml",
            srdf=robots / "srdf/ur5.srdf",
        )
        scene = at.Scene.from_file(HERE / "examples/data/ur5_box.toml")
    else:
        robot, scene = at.Robot.adept_one_xl(), at.Scene.paper()
    return at.TrajectoryProblem(robot, scene, scene.start, scene.goal, workers=workers)


def _plan_kwargs(case: str) -> dict:
    kind, seed = case.split(":")
    if kind == "ur5":
        return {"algorithm": "nsga2", "seed": int(seed), "pop_size": 60, "n_gen": 30}
    return {"algorithm": kind, "seed": int(seed)}


def make_state(case: str, path: Path, workers: int) -> None:
    """Run the search of ``case`` once and store its final population in ``path``."""
    from adept_traj.optimise import planner

    kwargs = _plan_kwargs(case)
    problem = make_problem(case, workers)
    real, kept = planner.optimise, []

    def storing(*args, **kw):
        kept.append(real(*args, **kw))
        return kept[-1]

    planner.optimise = storing
    try:
        planner.plan(problem, **kwargs, polish="off", max_certify=1)
    finally:
        planner.optimise = real
        problem.close()
    with open(path, "wb") as f:
        pickle.dump((kept[0], kwargs), f)


def timed(checkout: Path, state: Path, case: str, workers: int) -> dict:
    """One fresh process of ``checkout``'s code: the post-search phases of ``case``."""
    env = {**os.environ, "PYTHONPATH": str(checkout)}
    args = [str(state), case, str(workers), str(HERE / "benchmarks")]
    # -P: the current folder (maybe another checkout) must not come before PYTHONPATH
    out = subprocess.run(
        [sys.executable, "-P", "-c", CHILD, *args],
        env=env,
        check=True,
        capture_output=True,
        text=True,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--baseline", type=Path, help="another checkout, run alternately")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--cases", default="nsga2:1,nsga2:2,mode:1,ur5:1")
    parser.add_argument("--states", type=Path, default=Path(tempfile.gettempdir()) / "post_search")
    parser.add_argument("--workers", type=int, default=len(os.sched_getaffinity(0)))
    args = parser.parse_args()
    args.states.mkdir(parents=True, exist_ok=True)
    print(f"load average at start: {', '.join(f'{v:.1f}' for v in os.getloadavg())}")
    versions = {"this": HERE}
    if args.baseline is not None:
        versions = {"baseline": args.baseline.resolve(), "this": HERE}
    for case in args.cases.split(","):
        state = args.states / f"{case.replace(':', '_')}.pkl"
        if not state.exists():
            make_state(case, state, args.workers)
        runs: dict[str, list[dict]] = {name: [] for name in versions}
        for _ in range(args.runs):
            for name, checkout in versions.items():
                runs[name].append(timed(checkout, state, case, args.workers))
        print(f"{case} ({args.workers} workers; front of {runs['this'][0]['front']} members)")
        for name, rs in runs.items():
            walls, cpus = [r["wall"] for r in rs], [r["cpu"] for r in rs]
            labels = sorted({k for r in rs for k in r["phases"]})
            shown = "; ".join(
                f"{k} {statistics.median(r['phases'][k][0] for r in rs):.3f} s wall, "
                f"{statistics.median(r['phases'][k][1] for r in rs):.3f} s CPU"
                for k in labels
            )
            print(f"  {name:8s} phases (medians): {shown}")
            print(
                f"  {name:8s} wall median {statistics.median(walls):.3f} s "
                f"({', '.join(f'{w:.3f}' for w in walls)}); CPU median "
                f"{statistics.median(cpus):.3f} s ({', '.join(f'{c:.3f}' for c in cpus)}); "
                f"hashes {sorted({r['hash'] for r in rs})}"
            )
        if "baseline" in runs:
            ratios = [t["wall"] / b["wall"] for t, b in zip(runs["this"], runs["baseline"])]
            same = {r["hash"] for r in runs["this"]} == {r["hash"] for r in runs["baseline"]}
            print(
                f"  this / baseline wall, paired: median {statistics.median(ratios):.2f} "
                f"({', '.join(f'{r:.2f}' for r in ratios)}); results identical: {same}"
            )


if __name__ == "__main__":
    main()
