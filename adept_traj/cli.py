"""The ``adept-traj`` command.

Sub-commands:

- ``adept-traj robot`` — the robot-model demo: torques, their ratio to the limits and the
  manipulability along a rest-to-rest move (default: the paper's start → goal).
- ``adept-traj build-urdf PARAMS --output URDF`` — regenerate a URDF from a parameter file.

Bad input never prints a traceback: the command exits with status 2 and a one-line reason.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .errors import AdeptTrajError, InvalidInputError
from .robot import Robot
from .urdf_builder import build_urdf

__all__ = ["main"]

#: The paper's start and goal (θ1, θ2, θ4 as printed) with d3 inside its stroke [rad, rad, m, rad].
PAPER_START = (0.1682, 1.3849, 0.05, -0.7555)
PAPER_GOAL = (-0.7610, 0.2450, 0.15, 1.0095)


def _floats(text: str) -> list[float]:
    try:
        return [float(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated numbers, got {text!r}"
        ) from None


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="adept-traj", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)

    robot = sub.add_parser("robot", help="robot-model demo: torques and manipulability")
    robot.add_argument("--urdf", type=Path, help="URDF file (default: the AdeptOne XL)")
    robot.add_argument("--params", type=Path, help="parameter file for --urdf")
    robot.add_argument("--start", type=_floats, default=PAPER_START, help="q1,...,qn [rad|m]")
    robot.add_argument("--goal", type=_floats, default=PAPER_GOAL, help="q1,...,qn [rad|m]")
    robot.add_argument("--duration", type=float, default=1.1, help="move time T [s]")
    robot.add_argument("--samples", type=int, default=1001, help="samples along the move")

    build = sub.add_parser("build-urdf", help="write a URDF from a robot parameter file")
    build.add_argument("params", type=Path, help="parameter file (TOML)")
    build.add_argument("--output", "-o", type=Path, help="URDF path (default: stdout)")
    return parser


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


def _robot_demo(args: argparse.Namespace) -> int:
    robot = Robot.adept_one_xl() if args.urdf is None else Robot.from_urdf(args.urdf, args.params)
    start = robot.limits.check_position(args.start, "--start")
    goal = robot.limits.check_position(args.goal, "--goal")
    if not (np.isfinite(args.duration) and args.duration > 0):
        raise InvalidInputError(f"--duration must be a positive number [s]; got {args.duration}")
    if args.samples < 2:
        raise InvalidInputError(f"--samples must be at least 2; got {args.samples}")
    t, q, v, a = _quintic_move(start, goal, args.duration, args.samples)
    u = robot.inverse_dynamics(q, v, a)
    lim = robot.limits
    print(f"{robot.name}: quintic rest-to-rest move in T = {args.duration:g} s")
    print(f"  start {np.array2string(start, precision=4)}")
    print(f"  goal  {np.array2string(goal, precision=4)}")
    print(f"  {'joint':<8}{'peak |q̇|':>16}{'peak |q̈|':>17}{'peak |u|':>14}{'UC':>6}{'|u|/UC':>8}")
    for k, name in enumerate(robot.joint_names):
        unit = lim.units[k]
        force = "N" if unit == "m" else "N·m"
        peak_u = np.abs(u[:, k]).max()
        print(
            f"  {name:<8}{np.abs(v[:, k]).max():>9.3f} {unit + '/s':<6}"
            f"{np.abs(a[:, k]).max():>9.3f} {unit + '/s²':<7}{peak_u:>9.2f} {force:<4}"
            f"{lim.effort[k]:>6.0f}{peak_u / lim.effort[k]:>8.3f}"
        )
    dt = np.diff(t)
    energy = np.sum(0.5 * ((u[1:] ** 2).sum(1) + (u[:-1] ** 2).sum(1)) * dt)
    print(f"  ∫ Σ u² dt (paper z2) = {energy:.2f} [N²·m²·s]")
    if robot.task_rows is not None:
        w = robot.manipulability(q)
        print(f"  manipulability (paper z4): min {w.min():.5f}, max {w.max():.5f} [m²]")
    return 0


def _build_urdf(args: argparse.Namespace) -> int:
    text = build_urdf(args.params)
    if args.output is None:
        sys.stdout.write(text)
    else:
        args.output.write_text(text)
        print(f"wrote {args.output}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``adept-traj``; returns the exit status."""
    args = _parser().parse_args(argv)
    try:
        if args.command == "robot":
            return _robot_demo(args)
        return _build_urdf(args)
    except AdeptTrajError as exc:
        print(f"adept-traj: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"adept-traj: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
