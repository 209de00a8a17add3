"""Options shared by the planning commands (``plan``, ``compare``) and the problem they
describe.

:func:`add_problem_arguments` declares the options; :func:`problem_from_arguments` checks
them and builds the :class:`~adept_traj.problem.TrajectoryProblem` (on ``--robot`` or the
scene file's robot, else the AdeptOne XL) in two steps a caller may take apart
(:func:`task_from_arguments`: the checked :class:`Task` with its robot and scene;
:func:`problem_from_task`: the problem); :func:`check_rate` checks a verification rate [Hz].
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.analysis import PAPER_WEIGHTS, unit_warnings
from adept_traj.certification import check_rest_poses
from adept_traj.cli.robot_options import add_robot_arguments, check_task, robot_from_arguments
from adept_traj.errors import (
    CollidingConfigurationError,
    ConfigurationError,
    InvalidInputError,
    RobotModelError,
    SceneError,
)
from adept_traj.files import read_toml
from adept_traj.problem import TrajectoryProblem, available_cores, keep_heap
from adept_traj.robot import ELBOWS, Robot, ScaraGeometry, solve_location
from adept_traj.scene import SHIPPED_SCENES, Scene
from adept_traj.transforms import transform_from_xyz_rpy
from adept_traj.validation import as_scalar

__all__ = [
    "MIN_RATE_HZ",
    "Task",
    "add_problem_arguments",
    "check_rate",
    "floats",
    "problem_from_arguments",
    "problem_from_task",
    "task_from_arguments",
]

#: Lowest dense-verification rate the commands accept [Hz].
MIN_RATE_HZ = 100.0


def floats(text: str) -> list[float]:
    """``argparse`` type of a comma-separated list of numbers, e.g. ``"0.1,1.2,0.08,0"``."""
    try:
        return [float(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated numbers, got {text!r}"
        ) from None


def add_problem_arguments(parser: argparse.ArgumentParser, *, start_time: bool = False) -> None:
    """Declare the options of a planning problem: scene, start, goal, seed, weights, rate,
    workers (default ``None``: :func:`~adept_traj.problem.available_cores`), ``--quiet``
    and, with ``start_time``, ``--start-time T0`` (scene time [s] of the move's start)."""
    if start_time:
        parser.add_argument(
            "--start-time",
            type=float,
            metavar="T0",
            help="scene time [s] at which the move starts (default 0): moving obstacles are "
            "checked, certified and shown at scene time T0 + t",
        )
    parser.add_argument(
        "--scene",
        default="paper",
        help="a shipped scene (paper, detour) or a scene TOML file (default: paper)",
    )
    parser.add_argument("--start", type=floats, help="q1,...,qn [rad|m] (default: the scene's)")
    parser.add_argument("--goal", type=floats, help="q1,...,qn [rad|m] (default: the scene's)")
    for end in ("start", "goal"):
        parser.add_argument(
            f"--{end}-pose",
            type=floats,
            metavar="POSE",
            help=f"the {end} as a tool pose in the robot base frame, solved by inverse "
            "kinematics as a cycle file's location: x,y,z [m],yaw [rad] for a SCARA, "
            "x,y,z [m],roll,pitch,yaw [rad] for another robot (instead of --" + end + ")",
        )
    parser.add_argument(
        "--elbow",
        choices=ELBOWS,
        help="SCARA: the elbow of --start-pose/--goal-pose (default: righty if it reaches "
        "the pose, else lefty)",
    )
    parser.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
    parser.add_argument(
        "--weights",
        type=floats,
        default=list(PAPER_WEIGHTS),
        help="w1,...,w6 for f_c (default: the paper's); with plan --algorithm time-optimal, "
        "the weights of the weighted sum it minimises",
    )
    parser.add_argument("--rate", type=float, default=1000.0, help="verification rate [Hz]")
    parser.add_argument("--quiet", action="store_true", help="no progress output")
    add_robot_arguments(parser)
    parser.add_argument(
        "--workers",
        type=int,
        help="processes evaluating in parallel (default: the cores available to the process; "
        "1 evaluates in the main process; the results are the same)",
    )


def _pose_joints(
    robot: Robot,
    pose: list[float] | None,
    end: str,
    joints: np.ndarray | None,
    hint: np.ndarray | None,
    args: argparse.Namespace,
) -> np.ndarray:
    """``joints`` (nq,), or those of ``--{end}-pose`` ``pose`` solved as a cycle file's
    location (:func:`~adept_traj.robot.solve_location`: SCARA closed form with
    ``--elbow``, else numeric IK from ``hint``, the start's joints for the goal)."""
    if pose is None:
        return joints
    try:
        ScaraGeometry.of(robot)
        size, text = 4, "x,y,z [m],yaw [rad]"
    except RobotModelError:
        size, text = 6, "x,y,z [m],roll,pitch,yaw [rad]"
    values = np.asarray(pose, dtype=float)
    if values.shape != (size,) or not np.all(np.isfinite(values)):
        raise InvalidInputError(
            f"--{end}-pose must be {size} finite numbers ({text}) for robot '{robot.name}'; "
            f"got {','.join(map(str, pose))}"
        )
    if size == 6 and args.elbow is not None:
        raise ConfigurationError(
            f"--elbow is only for SCARA robots; robot '{robot.name}' is not one"
        )
    target = values if size == 4 else transform_from_xyz_rpy(values[:3], values[3:])
    joints, _ = solve_location(robot, target, elbow=args.elbow, name=f"--{end}-pose", hint=hint)
    return joints


def check_rate(rate: float) -> float:
    """``rate`` [Hz] if it is a finite number ≥ :data:`MIN_RATE_HZ`, else
    :class:`~adept_traj.errors.InvalidInputError`."""
    return as_scalar(rate, "--rate", "[Hz]", minimum=MIN_RATE_HZ)


def scene_from_argument(value: str) -> Scene:
    """The scene named by ``--scene``: a shipped scene's name (``SHIPPED_SCENES``, which
    takes precedence over a file of that name) or a scene TOML file's path."""
    return Scene.shipped(value) if value in SHIPPED_SCENES else Scene.from_file(value)


@dataclass(frozen=True)
class Task:
    """What a problem is made of, checked (:func:`task_from_arguments`).

    Attributes
    ----------
    robot : Robot
        The robot (``--robot``, the scene file's, else the AdeptOne XL).
    scene : Scene
        The scene (``--scene``).
    start, goal : numpy.ndarray or None
        (nq,) start and goal joint positions [rad | m] (``None``: from the given pose).
    workers : int
        The problem's evaluation processes (``--workers``, else the free cores).
    start_time : float or None
        The move's start on the scene clock [s] (``--start-time``; ``None``: not given, 0).
    """

    robot: Robot
    scene: Scene
    start: Any
    goal: Any
    workers: int
    start_time: float | None


def problem_from_arguments(args: argparse.Namespace) -> TrajectoryProblem:
    """The problem the options describe: :func:`problem_from_task` of
    :func:`task_from_arguments` (whose errors it raises)."""
    return problem_from_task(args, task_from_arguments(args))


def task_from_arguments(args: argparse.Namespace) -> Task:
    """The checked :class:`Task` the options describe, on the robot of
    :func:`~adept_traj.cli.robot_options.robot_from_arguments` (default: the AdeptOne XL).

    ``--start``/``--goal`` default to the scene's ``[task]``; ``--weights``, when given, must
    be six finite numbers ≥ 0, not all 0; ``--rate`` is checked by :func:`check_rate`.

    Raises
    ------
    ConfigurationError
        The scene has no start/goal and none was given.
    InvalidInputError
        Bad weights or rate, or a start/goal outside the joint limits (every joint
        outside named).
    """
    scene = scene_from_argument(args.scene)
    start, goal = args.start, args.goal
    for end in ("start", "goal"):
        if getattr(args, end) is not None and getattr(args, f"{end}_pose", None) is not None:
            raise ConfigurationError(f"give --{end} or --{end}-pose, not both")
    if start is None and getattr(args, "start_pose", None) is None:
        start = scene.start
    if goal is None and getattr(args, "goal_pose", None) is None:
        goal = scene.goal
    if (start is None and args.start_pose is None) or (goal is None and args.goal_pose is None):
        raise ConfigurationError(
            f"scene '{scene.name}' has no [task] start/goal: give --start and --goal"
        )
    if getattr(args, "elbow", None) is not None and args.start_pose is None is args.goal_pose:
        raise ConfigurationError("--elbow goes with --start-pose or --goal-pose")
    if args.weights is not None:  # None: plan's default (the paper's weights of f_c)
        weights = np.asarray(args.weights, dtype=float)
        if weights.shape != (6,) or not np.all(np.isfinite(weights)) or (weights < 0).any():
            raise InvalidInputError(
                f"--weights must be 6 finite numbers ≥ 0; got {','.join(map(str, args.weights))}"
            )
        if weights.sum() <= 0:
            raise InvalidInputError("--weights must not all be 0")
    check_rate(args.rate)
    keep_heap()  # the command's own process: evaluation blocks reuse the freed heap
    robot = robot_from_arguments(args, args.scene)
    start = check_task(robot, start, "start") if start is not None else None
    start = _pose_joints(robot, getattr(args, "start_pose", None), "start", start, None, args)
    goal = check_task(robot, goal, "goal") if goal is not None else None
    goal = _pose_joints(robot, getattr(args, "goal_pose", None), "goal", goal, start, args)
    workers = available_cores() if args.workers is None else args.workers
    start_time = getattr(args, "start_time", None)  # plan --start-time; None: 0
    if start_time is not None:
        as_scalar(start_time, "--start-time", "[s] (a scene time)", minimum=0)
    return Task(robot, scene, start, goal, workers, start_time)


def problem_from_task(args: argparse.Namespace, task: Task) -> TrajectoryProblem:
    """The :class:`~adept_traj.problem.TrajectoryProblem` of ``task`` (its unit warnings
    printed on standard error).

    Raises
    ------
    CollidingConfigurationError
        A start or goal closer than the margin to an obstacle or (self-collision on) to
        another link (:func:`~adept_traj.analysis.check_rest_poses`): checked before any
        search.
    """
    extra = {} if task.start_time is None else {"start_time": task.start_time}
    problem = TrajectoryProblem(
        task.robot, task.scene, task.start, task.goal, workers=task.workers, **extra
    )
    try:
        raw = None if args.scene in SHIPPED_SCENES else read_toml(args.scene, SceneError)
        for warning in unit_warnings(problem, raw):
            print(f"adept-traj: warning: {warning}", file=sys.stderr)
        check_rest_poses(problem)
    except CollidingConfigurationError:
        problem.close()
        raise
    return problem
