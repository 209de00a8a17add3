"""``adept-traj robot``: the robot-model demo.

Peak joint speeds, accelerations and torques, the torques' ratio to their limits (the
paper's UC), the integral of the squared torques (z2) and the manipulability range (z4)
along a rest-to-rest quintic move of the paper's task or of the one given; with ``--srdf``,
the smallest self-collision distance along it (:class:`~adept_traj.collision.SelfCollision`).

``--collision-matrix OUT.srdf`` instead writes the robot's self-collision matrix
(:func:`~adept_traj.collision.collision_matrix`: adjacent pairs and pairs in contact at
every one of 1 000 poses sampled within the limits left out, every other pair checked) as
an SRDF, reusable with ``--srdf``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from adept_traj.cli import status
from adept_traj.cli.arguments import floats
from adept_traj.cli.robot_options import add_robot_arguments, check_task, robot_from_arguments
from adept_traj.collision import SelfCollision, collision_matrix
from adept_traj.errors import InvalidInputError
from adept_traj.files import write_text_atomic
from adept_traj.memory import check_memory
from adept_traj.robot import Robot
from adept_traj.scene import Scene

__all__ = ["add_parser", "run", "samples_bytes"]


def samples_bytes(n_samples: int, nq: int) -> int:
    r"""Estimated peak memory [B] of the demo with ``n_samples`` samples of ``nq`` joints:

    .. math::
        M = 300\,n_q\,n + 1\ \text{MiB}

    (the move, the torques, the manipulability and their temporaries: 1 110 B per sample
    measured with :mod:`tracemalloc` for the AdeptOne XL, :math:`n_q = 4`, at
    n = 10⁴–8·10⁴, rounded up; ``benchmarks/bench_memory.py``)."""
    return 300 * nq * n_samples + 2**20


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``robot`` and its options."""
    p = sub.add_parser("robot", help="robot-model demo: torques and manipulability")
    add_robot_arguments(p)
    p.add_argument("--urdf", dest="robot", help="the same as --robot (older name)")
    p.add_argument("--start", type=floats, help="q1,...,qn [rad|m] (default: paper's)")
    p.add_argument("--goal", type=floats, help="q1,...,qn [rad|m] (default: paper's)")
    p.add_argument("--duration", type=float, default=1.1, help="move time T [s]")
    p.add_argument("--samples", type=int, default=1001, help="samples along the move")
    p.add_argument(
        "--collision-matrix",
        metavar="OUT.srdf",
        help="write the robot's self-collision matrix (made by sampling poses within the "
        "limits) as an SRDF instead of the demo",
    )
    return p


def _write_matrix(robot: Robot, path: Path) -> int:
    """Write ``robot``'s collision matrix as the SRDF ``path``; print what it holds."""
    if path.is_dir():
        raise InvalidInputError(f"--collision-matrix {path} is a folder; give a file")
    matrix = collision_matrix(robot)
    write_text_atomic(path, matrix.to_srdf())
    print(
        f"{robot.name}: {len(matrix.checked)} link pairs checked, {len(matrix.adjacent)} "
        f"adjacent and {len(matrix.always)} in contact at every one of {matrix.samples} "
        f"sampled poses left out; written to {path}"
    )
    return status.OK


def _quintic_move(
    start: np.ndarray, goal: np.ndarray, duration: float, n: int
) -> tuple[np.ndarray, ...]:
    """Rest-to-rest quintic move: t (n,), q, v, a (n, nq)."""
    tau = np.linspace(0.0, 1.0, n)
    s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
    sd = (30 * tau**2 - 60 * tau**3 + 30 * tau**4) / duration
    sdd = (60 * tau - 180 * tau**2 + 120 * tau**3) / duration**2
    delta = goal - start
    return tau * duration, start + s[:, None] * delta, sd[:, None] * delta, sdd[:, None] * delta


def run(args: argparse.Namespace) -> int:
    """Run ``robot``; return the exit status (0)."""
    robot = robot_from_arguments(args)
    if args.collision_matrix is not None:
        return _write_matrix(robot, Path(args.collision_matrix))
    paper = Scene.paper()  # its [task]: the paper's start and goal (docs/paper-scenario.md)
    start = check_task(robot, paper.start if args.start is None else args.start, "--start")
    goal = check_task(robot, paper.goal if args.goal is None else args.goal, "--goal")
    start = robot.limits.check_position(start, "--start")
    goal = robot.limits.check_position(goal, "--goal")
    if not (np.isfinite(args.duration) and args.duration > 0):
        raise InvalidInputError(f"--duration must be a positive number [s]; got {args.duration}")
    if args.samples < 2:
        raise InvalidInputError(f"--samples must be at least 2; got {args.samples}")
    check_memory(samples_bytes(args.samples, robot.nq), "--samples", args.samples)
    t, q, v, a = _quintic_move(start, goal, args.duration, args.samples)
    tau = robot.inverse_dynamics(q, v, a)
    lim = robot.limits
    print(f"{robot.name}: quintic rest-to-rest move in T = {args.duration:g} s")
    print(f"  start {np.array2string(start, precision=4)}")
    print(f"  goal  {np.array2string(goal, precision=4)}")
    print(f"  {'joint':<8}{'peak |q̇|':>16}{'peak |q̈|':>17}{'peak |τ|':>14}{'UC':>6}{'|τ|/UC':>8}")
    for k, name in enumerate(robot.joint_names):
        unit = lim.units[k]
        force = "N" if unit == "m" else "N·m"
        peak_tau = np.abs(tau[:, k]).max()
        print(
            f"  {name:<8}{np.abs(v[:, k]).max():>9.3f} {unit + '/s':<6}"
            f"{np.abs(a[:, k]).max():>9.3f} {unit + '/s²':<7}{peak_tau:>9.2f} {force:<4}"
            f"{lim.torque[k]:>6.0f}{peak_tau / lim.torque[k]:>8.3f}"
        )
    dt = np.diff(t)
    energy = np.sum(0.5 * ((tau[1:] ** 2).sum(1) + (tau[:-1] ** 2).sum(1)) * dt)
    print(f"  ∫ Σ τ² dt (paper z2) = {energy:.2f} [N²·m²·s]")
    if robot.task_rows is not None:
        w = robot.manipulability(q)
        print(f"  manipulability (paper z4): min {w.min():.5f}, max {w.max():.5f} [m²]")
    check = SelfCollision(robot)
    if robot.srdf_path is not None and len(check.pairs):  # --srdf: self-collision wanted
        d = check.distances(q)  # (n, n_pairs)
        k, p = np.unravel_index(int(np.argmin(d)), d.shape)
        a, b = check.pair_names[p]
        print(f"  self-collision: min distance {d[k, p]:.4f} m ({a}, {b}) at t = {t[k]:.3f} s")
    return status.OK
