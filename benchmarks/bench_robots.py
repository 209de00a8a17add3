"""Real robots against the AdeptOne XL: evaluations per second and certificate time.

Run: ``python benchmarks/bench_robots.py [--pop 100] [--gens 10] [--repeat 3]``
(needs ``example-robot-data``: ``pip install "adept_traj[robots]"``).

In one run, on one core, for the AdeptOne XL paper problem as ``plan`` builds it
(no SRDF: self-collision off), the same with self-collision (its 10 pairs), a UR5 (its
collision meshes as convex hulls, a box obstacle: ``examples/data/ur5_box.toml``, the
SRDF of example-robot-data, self-collision on: 16 pairs) and a Kinova Jaco2 (its meshes
as shipped, 44 k triangles on one link, a box obstacle, self-collision off):

- **evaluations per second** of :func:`adept_traj.plan` (NSGA-II, ``--pop`` × ``--gens``):
  ``timing.n_evaluations / timing.evaluation_s`` of the result, median of ``--repeat`` runs
  with seeds 1, 2, …;
- **certificate**: wall time of :func:`adept_traj.certify` of the best trade-off at 1 kHz,
  continuous guarantee (self-distance included when on), median of ``--repeat``; also its
  CPU time (``cpu``: the process's, which the other processes of a shared machine do not
  inflate; the certificate runs in this one process), whose ratio is the steadier figure
  on a busy machine.

Prints the ratios to the AdeptOne XL paper problem against the targets of issue #14: the
UR5 with self-collision ≥ 0.5 × its evaluations per second and ≤ 2 × its certificate time;
Jaco2 ≥ 0.2 × both ways. The "+self" row of the AdeptOne XL shows what its self check
would cost.
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings
from pathlib import Path

import numpy as np
from _results import figure, recorded  # benchmarks/_results.py

from adept_traj import Obstacle, Robot, Scene, TrajectoryProblem, certify, plan
from adept_traj.robot import installed_data_dirs
from adept_traj.scene import Box, FixedPose

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "data"
#: (evaluations-per-second ratio ≥, certificate-time ratio ≤) per robot, issue #14.
TARGETS = {"ur5 +self": (0.5, 2.0), "jaco2": (0.2, 5.0)}


def problems() -> dict[str, TrajectoryProblem]:
    """The problems: paper (AdeptOne XL, without and with self-collision), UR5, Jaco2."""
    paper, scara = Scene.paper(), Robot.adept_one_xl()
    out = {
        "adept_one_xl": TrajectoryProblem(scara, paper, paper.start, paper.goal),
        "  +self": TrajectoryProblem(scara, paper, paper.start, paper.goal, self_collision=True),
    }
    share = next(d for d in installed_data_dirs() if (d / "example-robot-data").is_dir())
    robots = share / "example-robot-data" / "robots"
    ur5 = Robot.from_urdf(
        robots / "ur_description/urdf/ur5_robot.urdf",
        EXAMPLES / "ur5.toml",
        srdf=robots / "ur_description/srdf/ur5.srdf",
    )
    scene = Scene.from_file(EXAMPLES / "ur5_box.toml")
    out["ur5 +self"] = TrajectoryProblem(ur5, scene, scene.start, scene.goal)
    jaco = Robot.from_urdf(robots / "kinova_description/robots/kinova.urdf")
    box = Obstacle("box", Box((0.15, 0.15, 0.15)), FixedPose.from_xyz_rpy((0.0, 0.45, 0.3)))
    start = np.array([-1.2, 2.9, 1.3, 0.0, 2.0, 0.0])
    goal = np.array([1.2, 2.9, 1.3, 0.0, 2.0, 0.0])
    out["jaco2"] = TrajectoryProblem(
        jaco, Scene(obstacles=(box,)), start, goal, self_collision=False
    )
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
        rates, cert_times, cert_cpu = [], [], []
        for seed in range(1, args.repeat + 1):
            result = plan(problem, "nsga2", seed=seed, pop_size=args.pop, n_gen=args.gens)
            timing = result.timing
            rates.append(timing.n_evaluations / timing.evaluation_s)
            t0, c0 = time.perf_counter(), time.process_time()
            certify(problem, result.front.x[result.best.index])
            cert_times.append(time.perf_counter() - t0)
            cert_cpu.append(time.process_time() - c0)
        own = problem.self_check
        rows[name] = (
            statistics.median(rates),
            statistics.median(cert_times),
            statistics.median(cert_cpu),
            problem.robot.nq,
            len(problem.robot.mesh_hulls),
            0 if own is None else own.n_pairs,
        )
        problem.close()
    ref_rate, ref_cert, ref_cpu, *_ = rows["adept_one_xl"]
    print(f"NSGA-II {args.pop} x {args.gens}, medians of {args.repeat} seeds, one core")
    print(
        f"{'robot':<14}{'nq':>3}{'meshes':>7}{'self':>5}{'eval/s':>9}{'ratio':>7}"
        f"{'cert s':>8}{'ratio':>7}{'cpu s':>7}{'ratio':>7}{'targets':>16}{'met':>5}"
    )
    for name, (rate, cert, cpu, nq, meshes, pairs) in rows.items():
        r_eval, r_cert = rate / ref_rate, cert / ref_cert
        target = TARGETS.get(name)
        met = (
            ""
            if target is None
            else ("yes" if r_eval >= target[0] and r_cert <= target[1] else "NO")
        )
        shown = "" if target is None else f">= {target[0]}, <= {target[1]}"
        print(
            f"{name:<14}{nq:>3}{meshes:>7}{pairs:>5}{rate:>9.0f}{r_eval:>7.2f}"
            f"{cert:>8.3f}{r_cert:>7.2f}{cpu:>7.3f}{cpu / ref_cpu:>7.2f}{shown:>16}{met:>5}"
        )
        if name != "adept_one_xl":
            key = name.replace(" +", "_")
            figure(
                f"{key}_rate", f"{name}: evaluations/s vs the AdeptOne XL's", round(r_eval, 2),
                "×", target=None if target is None else f"≥ {target[0]}×",
                met=None if target is None else r_eval >= target[0], note=f"{rate:.0f}/s",
            )  # fmt: skip
            figure(
                f"{key}_certificate", f"{name}: certificate time vs the AdeptOne XL's",
                round(r_cert, 2), "×", target=None if target is None else f"≤ {target[1]}×",
                met=None if target is None else r_cert <= target[1], note=f"{cert:.3f} s",
            )  # fmt: skip


if __name__ == "__main__":
    with recorded(
        __file__,
        "real robots (UR5, Jaco2) against the AdeptOne XL: evaluations/s and certificate time",
    ):
        main()
