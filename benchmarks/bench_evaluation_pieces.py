"""CPU time per sample of each piece of one evaluation block of the full problem.

Run: ``python benchmarks/bench_evaluation_pieces.py [--pop 500] [--repeat 7]``.

Evaluates the paper problem's populations (``random``: uniform in the decision bounds;
``near feasible``: small perturbations of a collision-free move) block by block, as
:meth:`TrajectoryProblem.evaluate_batch` does (blocks of about 4 096 samples), and times
each piece of a block separately: spline sampling, RNEA, forward kinematics with the
manipulability, the spline integrals and exact bounds, the obstacle pruning, the obstacle
poses, the broad phase, the whole :meth:`CollisionChecker.min_distances` (pruning, poses,
broad phase, coal and the branch and bound) and the whole block. Figures are **process CPU
time** (:func:`time.process_time`) in µs per sample (a sample = one configuration of one
trajectory; 116 per trajectory), the median over ``--repeat`` runs: on a machine shared
with other jobs, wall time mostly measures the others. The pieces overlap (min_distances
holds pruning, poses and broad phase), so they do not add up to the block.

``--against DIR`` compares this tree's code with the code of another checkout ``DIR``
(e.g. ``git worktree add /tmp/base main``) in **paired runs**: each pair evaluates the
populations whole (:meth:`TrajectoryProblem.evaluate_batch`, one core) in one process
of this code and one of ``DIR``'s, alternately, and prints the process CPU time per
sample of each and the median over pairs of the ratio (this / other): the pairs see the
same load, so the ratio is what moves least.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable

import numpy as np
from _results import recorded  # benchmarks/_results.py
from _timing import pair_order  # benchmarks/_timing.py

from adept_traj import Robot, Scene
from adept_traj.problem import TrajectoryProblem
from adept_traj.testing.paper_moves import lift_then_lower  # a hand-made collision-free move

#: Samples per block, as in :meth:`TrajectoryProblem.evaluate_batch`.
BLOCK_SAMPLES = 4096


def pieces(problem: TrajectoryProblem, x: np.ndarray) -> dict[str, float]:
    """CPU seconds per piece over the blocks of population ``x`` (pop, n_var)."""
    robot, traj, checker = problem.robot, problem.trajectory, problem.checker
    broad = checker.broad_phase  # the profile reads the checker's parts
    spent: dict[str, float] = {}

    def timed(name: str, fn: Callable[[], object]) -> object:
        start = time.process_time()
        out = fn()
        spent[name] = spent.get(name, 0.0) + time.process_time() - start
        return out

    step = max(1, BLOCK_SAMPLES // len(problem.s))
    for i in range(0, len(x), step):
        b = x[i : i + step]
        smp = timed("spline sampling", lambda b=b: traj.sample(b, problem.s, orders=(0, 1, 2)))
        timed("RNEA", lambda smp=smp: robot.inverse_dynamics(smp.q, smp.qd, smp.qdd))
        fk = timed("kinematics + manipulability", lambda smp=smp: robot.forward_kinematics(smp.q))
        timed("spline integrals", lambda b=b: traj.integrals(b))
        timed("spline exact bounds", lambda b=b: traj.bounds(b))
        frames, q = fk.joint_frames, smp.q.reshape(-1, robot.nq)
        timed(
            "pruning (ball centres too)",
            lambda b=b, f=frames: checker._pruning.lower_bounds(
                broad.ball_centres(f), broad.ball_radius, len(b)
            ),
        )
        poses = timed("obstacle poses", lambda smp=smp: checker.obstacle_poses(smp.t))
        timed("broad phase", lambda f=frames, p=poses, q=q: broad.bounds(f, p, q))
        timed(
            "min_distances (all of it)",
            lambda smp=smp, f=frames: checker.min_distances(smp.q, smp.t, joint_frames=f),
        )
        timed("block (all of it)", lambda b=b: problem._evaluate_block(b))
    return spent


def _problem_and_populations(pop: int) -> tuple[TrajectoryProblem, dict[str, np.ndarray]]:
    """The paper problem and its seeded ``random``, ``near straight`` (collides) and
    ``near feasible`` populations of ``pop`` trajectories."""
    robot, scene = Robot.adept_one_xl(), Scene.paper()
    problem = TrajectoryProblem(robot, scene, scene.start, scene.goal)
    rng = np.random.default_rng(0)
    span = problem.xu - problem.xl
    noise = rng.normal(scale=0.01, size=(pop, problem.n_var)) * span
    populations = {
        "random": problem.xl + span * rng.uniform(size=(pop, problem.n_var)),
        "near straight": np.clip(
            problem.trajectory.straight_line(1.6) + noise, problem.xl, problem.xu
        ),
        "near feasible": np.clip(lift_then_lower(problem) + noise, problem.xl, problem.xu),
    }
    return problem, populations


def _keep_heap() -> None:
    """:func:`adept_traj.problem.keep_heap`, as the ``adept-traj`` command does in its own
    process (the code of an older checkout may not have it: then nothing)."""
    try:
        from adept_traj.problem import keep_heap
    except ImportError:
        return
    keep_heap()


def _whole(pop: int, repeat: int) -> None:
    """Child of ``--against``: print, as JSON, the median CPU seconds per sample of
    ``evaluate_batch`` on each population (``repeat`` runs)."""
    _keep_heap()
    problem, populations = _problem_and_populations(pop)
    problem.evaluate_batch(populations["random"][:5])  # warm-up
    out = {}
    for name, x in populations.items():
        runs = []
        for _ in range(repeat):
            start = time.process_time()
            problem.evaluate_batch(x)
            runs.append(time.process_time() - start)
        out[name] = float(np.median(runs)) / (pop * len(problem.s))
    print(json.dumps(out))


def _paired(other: str, pairs: int, pop: int, repeat: int) -> None:
    """Alternate processes of this code and of ``other``'s; print both and the ratios.

    Each pair runs with an environment padded by a random number of bytes (the same for
    both of the pair): the size of the environment moves the process' memory layout, and
    with it the CPU time of the same code by up to ± 15 % here (measured, 2026-12-01), in
    a way that differs between two versions; varying it over the pairs averages that out.
    """
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    trees = {"this": here, "other": os.path.abspath(other)}
    runs: dict[str, list[dict[str, float]]] = {"this": [], "other": []}
    pads = np.random.default_rng(0).integers(0, 4096, size=pairs)
    for i in range(pairs):
        for label in pair_order(("this", "other"), i):
            env = {**os.environ, "PYTHONPATH": trees[label], "BENCH_PAD": "x" * int(pads[i])}
            cmd = [sys.executable, __file__, "--whole", "--pop", str(pop), "--repeat", str(repeat)]
            done = subprocess.run(cmd, env=env, capture_output=True, text=True, check=True)
            runs[label].append(json.loads(done.stdout.strip().splitlines()[-1]))
    print(f"paired runs: {pairs} pairs, population {pop}, CPU µs/sample (median), this vs {other}")
    print(f"{'population':<15}{'this':>8}{'other':>8}{'this/other':>12}  (pair ratios)")
    for name in runs["this"][0]:
        mine = [r[name] * 1e6 for r in runs["this"]]
        theirs = [r[name] * 1e6 for r in runs["other"]]
        ratios = [a / b for a, b in zip(mine, theirs)]
        shown = ", ".join(f"{r:.2f}" for r in ratios)
        print(
            f"{name:<15}{np.median(mine):8.2f}{np.median(theirs):8.2f}"
            f"{np.median(ratios):12.3f}  ({shown})"
        )


def main() -> None:
    _keep_heap()
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pop", type=int, default=500, help="population size")
    parser.add_argument("--repeat", type=int, default=7, help="runs (the median is printed)")
    parser.add_argument("--against", metavar="DIR", help="paired runs against DIR's code")
    parser.add_argument("--pairs", type=int, default=12, help="pairs of runs for --against")
    parser.add_argument("--whole", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.whole:
        return _whole(args.pop, args.repeat)
    if args.against:
        return _paired(args.against, args.pairs, args.pop, args.repeat)
    problem, populations = _problem_and_populations(args.pop)
    del populations["near straight"]  # the per-piece table: two populations
    n_samples = args.pop * len(problem.s)
    print(
        f"{problem.robot.name}, paper scene, {len(problem.s)} samples per trajectory, CPU µs/sample"
    )
    for name, x in populations.items():
        problem.evaluate_batch(x[:5])  # warm-up
        runs = [pieces(problem, x) for _ in range(args.repeat)]
        print(name)
        for piece in runs[0]:
            median = float(np.median([r[piece] for r in runs]))
            print(f"  {piece:<30}{median / n_samples * 1e6:7.2f}")
        block = float(np.median([r["block (all of it)"] for r in runs]))
        print(f"  {'= evaluations/s on one core':<30}{args.pop / block:7.0f}")


if __name__ == "__main__":
    with recorded(
        __file__,
        "CPU time per sample of each piece of an evaluation block",
        child_flags=("--whole",),
    ):
        main()
