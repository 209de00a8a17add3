"""The robot a command works on: ``--robot URDF [--params TOML] [--tool-frame NAME]
[--srdf FILE] [--package-dir DIR ...] [--locked-joint NAME=VALUE ...]`` (the URDF and the
SRDF may be ``package://`` URIs, as in a scene file),
else the scene file's ``[robot]`` table, else the AdeptOne XL.

:func:`add_robot_arguments` declares the options; :func:`source_from_arguments` gives
where the robot loads from (a :class:`~adept_traj.robot.RobotSource`, also handed to the
workers of a seed study), :func:`robot_from_arguments` loads it; :func:`check_task` checks
a start/goal against the robot's joint count.
"""

from __future__ import annotations

import argparse
import math
from typing import Any

import numpy as np

from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.robot import Robot, RobotSource
from adept_traj.scene import SHIPPED_SCENES, read_robot_files

__all__ = [
    "add_robot_arguments",
    "check_task",
    "locked_joints",
    "options_given",
    "robot_from_arguments",
    "source_from_arguments",
]


def add_robot_arguments(
    parser: argparse.ArgumentParser,
    flag: str = "--robot",
    help_urdf: str = "URDF of the robot (default: the scene file's [robot] urdf, else the "
    "AdeptOne XL)",
    help_tool_frame: str = "tool frame name (default: the parameter file's)",
) -> None:
    """Declare ``--robot`` (or ``flag``; its help line ``help_urdf``), ``--params``,
    ``--tool-frame`` (its help line ``help_tool_frame``), ``--srdf``, ``--package-dir``."""
    parser.add_argument(flag, dest="robot", help=help_urdf)
    parser.add_argument("--params", help="parameter file (TOML) of the robot")
    parser.add_argument("--tool-frame", help=help_tool_frame)
    parser.add_argument("--srdf", help="SRDF: its disable_collisions pairs are not self-checked")
    parser.add_argument(
        "--package-dir",
        action="append",
        help="folder searched first for package:// meshes (repeatable)",
    )
    parser.add_argument(
        "--locked-joint",
        action="append",
        metavar="NAME=VALUE",
        help="fix joint NAME at VALUE [rad | m] and remove it from q (repeatable)",
    )


def locked_joints(values: list[str] | None) -> tuple[tuple[str, float], ...]:
    """The ``--locked-joint NAME=VALUE`` options as ``(name, value)`` pairs, else
    :class:`~adept_traj.errors.InvalidInputError` naming the option given."""
    out = []
    for text in values or ():
        name, sep, value = text.partition("=")
        try:
            number = float(value)
        except ValueError:
            number = math.nan
        if not sep or not name.strip() or not math.isfinite(number):
            raise InvalidInputError(
                f"--locked-joint must be NAME=VALUE with a finite VALUE [rad | m]; got {text!r}"
            )
        out.append((name.strip(), number))
    return tuple(out)


def source_from_arguments(args: argparse.Namespace, scene: str | None = None) -> RobotSource:
    """Where the robot of the options is loaded from: ``--robot`` etc. if given, else the
    ``[robot]`` table of the scene file ``scene`` (``None`` or a shipped scene's name:
    none), else the AdeptOne XL. An option given overrides the scene file's value of the
    same field; ``--package-dir`` folders are searched before the scene file's."""
    named = RobotSource()
    if scene is not None and scene not in SHIPPED_SCENES:
        named = read_robot_files(scene)
    return named.overridden(**options_given(args))


def robot_from_arguments(args: argparse.Namespace, scene: str | None = None) -> Robot:
    """The robot of :func:`source_from_arguments`, loaded."""
    return source_from_arguments(args, scene).load()


def options_given(args: argparse.Namespace) -> dict[str, Any]:
    """The robot options given (``None`` or ``()``: not given), as
    :class:`~adept_traj.robot.RobotSource` fields."""
    return {
        "urdf": getattr(args, "robot", None),
        "params": getattr(args, "params", None),
        "tool_frame": getattr(args, "tool_frame", None),
        "srdf": getattr(args, "srdf", None),
        "package_dirs": tuple(getattr(args, "package_dir", None) or ()),
        "locked_joints": locked_joints(getattr(args, "locked_joint", None)),
    }


def check_task(robot: Robot, q: object, option: str) -> np.ndarray:
    """``q`` as an (nq,) array of the robot's joint values, else
    :class:`~adept_traj.errors.InputShapeError` naming the robot's joint count and joints."""
    arr = np.asarray(q, dtype=float)
    if arr.shape != (robot.nq,):
        raise InputShapeError(
            f"{option} must hold {robot.nq} joint values for robot '{robot.name}' "
            f"({', '.join(robot.joint_names)}); got {arr.size}"
        )
    return arr
