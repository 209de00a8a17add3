"""A wider multi-start of adept_traj's own certified local solver: a best known move made
without Drake (issue #24, ``docs/reference-moves.md``).

Run: ``python benchmarks/reference_adept.py SCENE [--processes 2] [--refined 8]
[--out FILE.json]``; ``SCENE`` a shipped name or a scene file.

The default runs (``plan``'s polish, the time-optimal mode) screen a few starts of the global
stage and stop once one is near the floor; this script screens many more, from more seeds,
and refines the best of them to the end — a reference for ``benchmarks/bench_hard.py``, not
a default:

- the problem's fixed-obstacle optimum (:func:`~adept_traj.optimise.relaxed_optimum`)
  stretched by 1, 1.05, …, 2 × its T;
- the timed trees' starts (:func:`~adept_traj.optimise.timed_roadmap_starts`, guided by that
  optimum) of seeds 0–3, six each;
- the via-point starts (:func:`~adept_traj.optimise.via_point_starts`) of seeds 0–2, six
  basins each from two batches;

every start screened (:func:`~adept_traj.optimise.screen_starts`), then the ``--refined``
screened moves that reached a point inside the sampled constraints (certified first, then
fastest) refined to the end (:func:`~adept_traj.optimise.refine_minimum_time`). The fastest
certified move is printed and written to ``--out`` as ``{"T": ..., "x": [...], "start":
...}``; ``benchmarks/check_scenes.py`` and ``tests/scene/test_unseen_scenes.py`` re-check
a stored one by coal called pair by pair.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import adept_traj as at
from adept_traj.optimise import (
    refine_minimum_time,
    relaxed_optimum,
    screen_starts,
    timed_roadmap_starts,
    via_point_starts,
)
from adept_traj.optimise.local.refinement import NO_MOVE_INSIDE


def problem_of(scene: str) -> at.TrajectoryProblem:
    """The problem of a shipped scene name or a scene file, the robot's defaults."""
    s = at.Scene.from_file(scene) if scene.endswith(".toml") else at.Scene.shipped(scene)
    return at.TrajectoryProblem(at.Robot.adept_one_xl(), s, s.start, s.goal)


def starts_of(problem: at.TrajectoryProblem, processes: int) -> dict[str, np.ndarray]:
    """The starts by family (module docstring)."""
    relaxed, floor = relaxed_optimum(problem, n_starts=3, rate_hz=1000.0, processes=processes)
    print(f"fixed-obstacle optimum: {floor:.6f} s", flush=True)
    starts = {}
    if len(relaxed):
        factors = np.arange(1.0, 2.01, 0.05)
        stretched = np.repeat(relaxed[:1], len(factors), axis=0)
        stretched[:, 0] = np.minimum(floor * factors, problem.xu[0])
        starts["stretch"] = stretched
    for seed in range(4):
        guide = relaxed[:1] if len(relaxed) else None
        starts[f"timed{seed}"] = timed_roadmap_starts(problem, seed, guides=guide, n_starts=6)
    for seed in range(3):
        starts[f"via{seed}"] = via_point_starts(
            problem, seed, n_starts=6, n_batches=2, processes=processes
        )
    return starts


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", help="a shipped scene name or a scene TOML file")
    parser.add_argument("--processes", type=int, default=2)
    parser.add_argument("--refined", type=int, default=8, help="screened moves refined")
    parser.add_argument("--out", type=Path, default=None, help="write the best move here")
    args = parser.parse_args()
    tic = time.perf_counter()
    problem = problem_of(args.scene)
    print(f"T_lb {problem.lower_bound.T_min:.6f} s", flush=True)
    screened = []
    for family, xs in starts_of(problem, args.processes).items():
        for i, o in enumerate(screen_starts(problem, xs, processes=args.processes)):
            screened.append((f"{family}[{i}]", o))
            print(f"{family}[{i}]: {xs[i, 0]:.4f} -> {o.x[0]:.4f} s, certified {o.certified}, "
                  f"{o.message}", flush=True)  # fmt: skip
    inside = [(name, o) for name, o in screened if o.message != NO_MOVE_INSIDE]
    inside.sort(key=lambda item: (not item[1].certified, float(item[1].x[0])))
    best = None
    for name, o in inside[: args.refined]:
        r = refine_minimum_time(
            problem, o.x, start_certificate=o.certificate, extra_samples=o.extra_samples
        )
        print(f"refined {name}: {o.x[0]:.4f} -> {r.x[0]:.6f} s, certified {r.certified}",
              flush=True)  # fmt: skip
        if r.certified and (best is None or r.x[0] < best[1].x[0]):
            best = (name, r)
    print(f"{len(screened)} starts, {len(inside[: args.refined])} refined, "
          f"{time.perf_counter() - tic:.0f} s")  # fmt: skip
    if best is None:
        print("no certified move")
        return
    name, r = best
    print(f"best: {r.x[0]!r} s, from {name}")
    if args.out is not None:
        record = {"T": float(r.x[0]), "start": name, "x": r.x.tolist()}
        args.out.write_text(json.dumps(record, indent=1) + "\n")


if __name__ == "__main__":
    main()
