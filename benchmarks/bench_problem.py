"""Evaluations per second of the full trajectory problem (paper scene), batched vs reference.

Run: ``python benchmarks/bench_problem.py [--pop 500] [--reference 10]``.

Three populations of the 65-variable problem at the default sampling (6 Gauss–Legendre
nodes on each of the 19 spline segments plus both ends: 116 samples per trajectory):

- ``random``: uniform in the decision bounds (a typical initial population; wild motions,
  many collisions);
- ``near straight``: small perturbations of the straight joint-space move (it hits cube 1);
- ``near feasible``: small perturbations of a collision-free move (a late-run population,
  close to the obstacles: the hardest case for the distance computation).

Prints evaluations per second of :meth:`TrajectoryProblem.evaluate_batch` and of the plain
per-sample :func:`adept_traj.testing.reference.evaluate_reference` (on a few individuals),
their ratio measured in the same run, the coal calls per evaluation and the peak memory of
one batched evaluation of the population (tracemalloc: numpy allocations).
"""

from __future__ import annotations

import argparse
import tracemalloc

import numpy as np
from _results import figure, recorded  # benchmarks/_results.py
from _timing import best_of  # benchmarks/_timing.py

from adept_traj import Robot, Scene
from adept_traj.problem import TrajectoryProblem, keep_heap
from adept_traj.testing.paper_moves import lift_then_lower  # a hand-made collision-free move
from adept_traj.testing.reference import evaluate_reference


def main() -> None:
    keep_heap()  # as the adept-traj command does in its own process
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pop", type=int, default=500, help="population size")
    parser.add_argument("--reference", type=int, default=10, help="individuals for reference")
    parser.add_argument("--repeat", type=int, default=3, help="repetitions (best is kept)")
    parser.add_argument("--workers", type=int, default=2, help="processes for the parallel row")
    args = parser.parse_args()

    robot, scene = Robot.adept_one_xl(), Scene.paper()
    problem = TrajectoryProblem(robot, scene, scene.start, scene.goal)
    rng = np.random.default_rng(0)
    span = problem.xu - problem.xl

    def around(x0: np.ndarray, scale: float) -> np.ndarray:
        pop = x0 + rng.normal(scale=scale, size=(args.pop, problem.n_var)) * span
        return np.clip(pop, problem.xl, problem.xu)

    populations = {
        "random": problem.xl + span * rng.uniform(size=(args.pop, problem.n_var)),
        "near straight": around(problem.trajectory.straight_line(1.6), 0.01),
        "near feasible": around(lift_then_lower(problem), 0.01),
    }
    print(
        f"{robot.name}, paper scene, {len(problem.s)} samples per trajectory, population {args.pop}"
    )
    print(
        f"{'population':<15}{'batched ev/s':>13}{'reference ev/s':>16}{'ratio':>8}"
        f"{'coal calls/ev':>15}{'feasible':>10}"
    )
    for name, pop in populations.items():
        problem.evaluate_batch(pop[:5])  # warm-up
        ev = problem.evaluate_batch(pop)
        batched = args.pop / best_of(lambda pop=pop: problem.evaluate_batch(pop), args.repeat)
        few = pop[: args.reference]
        reference = len(few) / best_of(lambda few=few: evaluate_reference(problem, few), 1)
        print(
            f"{name:<15}{batched:>13.0f}{reference:>16.1f}{batched / reference:>7.0f}×"
            f"{ev.n_narrow / args.pop:>15.1f}{int(ev.feasible.sum()):>10}"
        )
        key = name.replace(" ", "_")
        figure(f"{key}_rate", f"{name}: evaluations/s, one core", round(batched), "/s")
        figure(
            f"{key}_ratio", f"{name}: one core vs the per-sample reference",
            round(batched / reference), "×", target="≥ 20×", met=batched / reference >= 20,
            note=f"reference {reference:.1f}/s",
        )  # fmt: skip
    parallel = TrajectoryProblem(robot, scene, scene.start, scene.goal, workers=args.workers)
    parallel.evaluate_batch(populations["random"][:40])  # start the workers
    for name, pop in populations.items():
        serial = args.pop / best_of(lambda pop=pop: problem.evaluate_batch(pop), args.repeat)
        both = args.pop / best_of(lambda pop=pop: parallel.evaluate_batch(pop), args.repeat)
        print(
            f"{name:<15} {args.workers} workers: {both:.0f} ev/s, serial {serial:.0f} ev/s "
            f"({both / serial:.2f}×)"
        )
        figure(
            f"{name.replace(' ', '_')}_rate_workers",
            f"{name}: evaluations/s, {args.workers} workers", round(both), "/s",
            target="≥ 2 000/s", met=both >= 2000, note=f"serial {serial:.0f}/s in the same run",
        )  # fmt: skip
    parallel.close()
    pop = populations["near feasible"]
    tracemalloc.start()
    problem.evaluate_batch(pop)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    print(f"peak memory of one batched evaluation of {args.pop}: {peak / 2**20:.0f} MiB")
    figure("peak_memory", f"peak memory of one batched evaluation of {args.pop}",
           round(peak / 2**20), "MiB")  # fmt: skip


if __name__ == "__main__":
    with recorded(
        __file__, "evaluations per second of the full problem, batched vs the per-sample reference"
    ):
        main()
