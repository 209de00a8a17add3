"""The robot a command works on: ``--robot URDF [--params TOML] [--tool-frame NAME]
[--srdf FILE] [--package-dir DIR ...]``,
else the scene file's ``[robot]`` table, else the AdeptOne XL.

:func:`add_robot_arguments` declares the options; :func:`robot_from_arguments` loads the
robot; :func:`check_task` checks a start/goal against the robot's joint count.
"""

from __future__ import annotations

import argparse

import numpy as np

from adept_traj.errors import ConfigurationError, InputShapeError
from adept_traj.robot import Robot
from adept_traj.scene import SHIPPED_SCENES, read_robot_files

__all__ = ["add_robot_arguments", "check_task", "robot_from_arguments"]


def add_robot_arguments(parser: argparse.ArgumentParser, flag: str = "--robot") -> None:
    """Declare ``--robot`` (or ``flag``), ``--params``, ``--tool-frame``, ``--srdf``,
    ``--package-dir``."""
    parser.add_argument(
        flag,
        dest="robot",
        help="URDF of the robot (default: the scene file's [robot] urdf, else the AdeptOne XL)",
    )
    parser.add_argument("--params", help="parameter file (TOML) of the robot")
    parser.add_argument("--tool-frame", help="tool frame name (default: the parameter file's)")
    parser.add_argument("--srdf", help="SRDF: its disable_collisions pairs are not self-checked")
    parser.add_argument(
        "--package-dir",
        action="append",
        help="folder searched first for package:// meshes (repeatable)",
    )


def robot_from_arguments(args: argparse.Namespace, scene: str | None = None) -> Robot:
    """The robot of the options: ``--robot`` etc. if given, else the ``[robot]`` table of
    the scene file ``scene`` (``None`` or a shipped scene's name: none), else the AdeptOne
    XL. An option given overrides the scene file's value of the same field."""
    named = {"urdf": None, "params": None, "tool_frame": None, "package_dirs": ()}
    if scene is not None and scene not in SHIPPED_SCENES:
        named = read_robot_files(scene)
    urdf = args.robot if getattr(args, "robot", None) is not None else named["urdf"]
    params = getattr(args, "params", None) or named["params"]
    tool_frame = getattr(args, "tool_frame", None) or named["tool_frame"]
    srdf = getattr(args, "srdf", None)
    dirs = tuple(getattr(args, "package_dir", None) or ()) + tuple(named["package_dirs"])
    if urdf is None:
        if srdf is not None:
            raise ConfigurationError("--srdf goes with --robot (or the scene file's [robot] urdf)")
        return Robot.adept_one_xl()
    return Robot.from_urdf(str(urdf), params, package_dirs=dirs, srdf=srdf, tool_frame=tool_frame)


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
