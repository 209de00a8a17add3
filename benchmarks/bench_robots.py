"""Real robots against the AdeptOne XL: evaluations per second and certificate time.

Run: ``python benchmarks/bench_robots.py [--pop 100] [--gens 10] [--repeat 3]``
(needs ``example-robot-data``: ``pip install "adept_traj[robots]"``).

In one run, on one core, for the AdeptOne XL paper problem, a UR5 (its collision meshes
as convex hulls, a box obstacle: ``examples/data/ur5_box.toml``) and a Kinova Jaco2 (its
meshes as shipped, 44 k triangles on one link, a box obstacle):

- **evaluations per second** of :func:`adept_traj.plan` (NSGA-II, ``--pop`` × ``--gens``):
  ``timing.n_evaluations / timing.evaluation_s`` of the result, median of ``--repeat`` runs
  with seeds 1, 2, …;
- **with self-collision**: the same, adding the time of
  :meth:`~adept_traj.collision.SelfCollision.min_distance` on the samples of as many
  trajectories (the planner does not check self-collision yet: this is its cost if it did);
- **certificate**: wall time of :func:`adept_traj.certify` of the best trade-off at 1 kHz,
  continuous guarantee, median of ``--repeat``; also its CPU time (``cert cpu``: the
  process's, which the other processes of a shared machine do not inflate; the certificate
  runs in this one process), whose ratio is the steadier figure on a busy machine.

Prints the ratios to the AdeptOne XL (planner evaluations, without self-collision) against
the targets of issue #14: UR5 ≥ 0.5 × its evaluations per second and ≤ 2 × its certificate
time; Jaco2 ≥ 0.2 × both ways. The "+self" columns (ratio to the AdeptOne XL's planner
rate) are shown, not judged: the planner does not include self-collision.
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings
from pathlib import Path

import numpy as np

from adept_traj import Obstacle, Robot, Scene, TrajectoryProblem, certify, plan
from adept_traj.collision import SelfCollision
from adept_traj.robot import installed_data_dirs
from adept_traj.scene import Box, FixedPose

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "data"
#: (evaluations-per-second ratio ≥, certificate-time ratio ≤) per robot, issue #14.
TARGETS = {"ur5": (0.5, 2.0), "jaco2": (0.2, 5.0)}


def problems() -> dict[str, TrajectoryProblem]:
    """The three problems: paper (AdeptOne XL), UR5, Jaco2."""
    paper = Scene.paper()
    out = {"adept_one_xl": TrajectoryProblem(Robot.adept_one_xl(), paper, paper.start, paper.goal)}
    share = next(d for d in installed_data_dirs() if (d / "example-robot-data").is_dir())
    robots = share / "example-robot-data" / "robots"
    ur5 = Robot.from_urdf(robots / "ur_description/urdf/ur5_robot.urdf", EXAMPLES / "ur5.toml")
    scene = Scene.from_file(EXAMPLES / "ur5_box.toml")
    out["ur5"] = TrajectoryProblem(ur5, scene, scene.start, scene.goal)
    jaco = Robot.from_urdf(robots / "kinova_description/robots/kinova.urdf")
    box = Obstacle("box", Box((0.15, 0.15, 0.15)), FixedPose.from_xyz_rpy((0.0, 0.45, 0.3)))
    start = np.array([-1.2, 2.9, 1.3, 0.0, 2.0, 0.0])
    goal = np.array([1.2, 2.9, 1.3, 0.0, 2.0, 0.0])
    out["jaco2"] = TrajectoryProblem(jaco, Scene(obstacles=(box,)), start, goal)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pop", type=int, default=100, help="population size")
    parser.add_argument("--gens", type=int, default=10, help="generations")
    parser.add_argument("--repeat", type=int, default=3, help="runs per robot (median)")
    args = parser.parse_args()
    warnings.simplefilter("ignore", UserWarning)  # the Jaco2 has no acceleration limits
    rows = {}
    for name, problem in problems().items():
        rates, self_rates, cert_times, cert_cpu = [], [], [], []
        self_check = SelfCollision(problem.robot)
        for seed in range(1, args.repeat + 1):
            result = plan(problem, "nsga2", seed=seed, pop_size=args.pop, n_gen=args.gens)
            timing = result.timing
            rates.append(timing.n_evaluations / timing.evaluation_s)
            x = np.random.default_rng(seed).uniform(
                problem.xl, problem.xu, (args.pop, problem.n_var)
            )
            q = problem.trajectory.sample(x, problem.s).q
            t0 = time.perf_counter()
            self_check.min_distance(q)
            per_eval = (time.perf_counter() - t0) / args.pop
            self_rates.append(1.0 / (1.0 / rates[-1] + per_eval))
            t0, c0 = time.perf_counter(), time.process_time()
            certify(problem, result.front.x[result.best.index])
            cert_times.append(time.perf_counter() - t0)
            cert_cpu.append(time.process_time() - c0)
        rows[name] = (
            statistics.median(rates),
            statistics.median(self_rates),
            statistics.median(cert_times),
            statistics.median(cert_cpu),
            problem.robot.nq,
            len(problem.robot.mesh_hulls),
        )
        problem.close()
    ref_rate, _, ref_cert, ref_cpu, *_ = rows["adept_one_xl"]
    print(f"NSGA-II {args.pop} x {args.gens}, medians of {args.repeat} seeds, one core")
    print(
        f"{'robot':<14}{'nq':>3}{'meshes':>7}{'eval/s':>9}{'ratio':>7}{'+self eval/s':>14}"
        f"{'ratio':>7}{'cert s':>8}{'ratio':>7}{'cert cpu':>9}{'ratio':>7}{'targets':>16}{'met':>5}"
    )
    for name, (rate, self_rate, cert, cpu, nq, meshes) in rows.items():
        r_eval, r_self, r_cert = rate / ref_rate, self_rate / ref_rate, cert / ref_cert
        target = TARGETS.get(name)
        met = (
            ""
            if target is None
            else ("yes" if r_eval >= target[0] and r_cert <= target[1] else "NO")
        )
        shown = "" if target is None else f">= {target[0]}, <= {target[1]}"
        print(
            f"{name:<14}{nq:>3}{meshes:>7}{rate:>9.0f}{r_eval:>7.2f}{self_rate:>14.0f}"
            f"{r_self:>7.2f}{cert:>8.3f}{r_cert:>7.2f}{cpu:>9.3f}{cpu / ref_cpu:>7.2f}"
            f"{shown:>16}{met:>5}"
        )


if __name__ == "__main__":
    main()
