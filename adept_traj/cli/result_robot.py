r"""The robot ``verify`` and ``show`` use for a saved result: the one it records, or the one
the options give (``--robot URDF [--params TOML] [--srdf FILE] [--tool-frame NAME]
[--package-dir DIR ...]``), checked to be the recorded robot.

Without any of these options the robot is rebuilt from the result's record
(:meth:`~adept_traj.results.RobotInfo.load`). With them:

- ``--robot URDF``: the robot is loaded from that URDF (e.g. the robot's files moved), with
  ``--params``/``--srdf`` if given (the recorded files are not used), the recorded tool
  frame and locked joints unless ``--tool-frame`` is given;
- without ``--robot``: the recorded robot, with the options given replacing its fields;
  ``--package-dir`` alone only adds folders where ``package://`` meshes are looked for
  first (meshes moved).

A robot so given must be the recorded one (:func:`check_recorded_robot`), else
:class:`~adept_traj.errors.RobotMismatchError` names both and what differs: the joint
names (in order, hence their count), the tool frame, every joint limit, and the inverse
dynamics at :data:`TORQUE_SAMPLES` samples of the stored certificate (masses, inertias,
friction and the joint placements they hang on):

.. math::

    |\tau_{\text{given}} - \tau_{\text{stored}}| \le 10^{-6} \max_{\text{samples}}
    |\tau_{\text{stored}}| + 10^{-9} \quad \text{per joint [N·m | N]}

Collision geometry (e.g. meshes) is not part of this check; ``verify`` audits it anyway
(the stored minimum distance at every certificate sample).
"""

from __future__ import annotations

import argparse

import numpy as np

from adept_traj.cli.robot_options import add_robot_arguments, options_given
from adept_traj.errors import RobotMismatchError, RobotModelError
from adept_traj.results import PlanningResult
from adept_traj.robot import LIMITS, Robot, RobotSource

__all__ = [
    "TORQUE_RTOL",
    "TORQUE_SAMPLES",
    "add_result_robot_arguments",
    "check_recorded_robot",
    "result_robot",
]

#: Certificate samples at which the given robot's inverse dynamics is compared.
TORQUE_SAMPLES = 16
#: Relative tolerance of that comparison (of the largest stored torque of each joint).
TORQUE_RTOL = 1e-6


def add_result_robot_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare ``--robot``, ``--params``, ``--tool-frame``, ``--srdf``, ``--package-dir``
    for a command on a saved result."""
    add_robot_arguments(
        parser,
        help_urdf="URDF of the recorded robot (default: the recorded path)",
        help_tool_frame="tool frame name (default: the recorded one)",
    )


def result_robot(args: argparse.Namespace, result: PlanningResult) -> Robot | None:
    """The robot the options give for ``result`` (module doc), checked against the record;
    ``None`` when no robot option is given (the caller rebuilds the recorded robot)."""
    given = options_given(args)
    urdf = given.pop("urdf")
    if urdf is None and not any(given.values()):
        return None
    recorded = result.robot.source()
    if urdf is not None:
        recorded = RobotSource(
            urdf,
            tool_frame=result.robot.tool_frame,
            locked_joints=result.robot.locked_joints,
        )
    source = recorded.overridden(**given)
    try:
        robot = source.load()
    except RobotModelError as exc:
        if urdf is None:
            raise
        info = result.robot
        raise RobotMismatchError(
            f"{urdf} does not load as the result's robot '{info.name}' ({info.urdf}; joints "
            f"{list(info.joint_names)}, tool frame {source.tool_frame!r}, locked joints "
            f"{dict(source.locked_joints)}): {exc}"
        ) from None
    check_recorded_robot(result, robot)
    return robot


def check_recorded_robot(result: PlanningResult, robot: Robot) -> None:
    """Raise :class:`~adept_traj.errors.RobotMismatchError` when ``robot`` is not the robot
    ``result`` records (joint names, tool frame, limits, inverse dynamics; module doc)."""
    info = result.robot
    theirs = f"the result's robot '{info.name}' ({info.urdf})"
    ours = f"robot '{robot.name}' ({robot.urdf_path})"

    def refuse(what: str) -> RobotMismatchError:
        return RobotMismatchError(f"{ours} is not {theirs}: {what}")

    if tuple(robot.joint_names) != info.joint_names:
        raise refuse(
            f"its {robot.nq} joints {list(robot.joint_names)} differ from the recorded "
            f"{len(info.joint_names)} {list(info.joint_names)}"
        )
    if robot.tool_frame != info.tool_frame:
        raise refuse(f"tool frame {robot.tool_frame!r}, recorded {info.tool_frame!r}")
    stored, now = result.limits, robot.limits
    pairs = [("position lower", stored.lower, now.lower)]
    pairs += [("position upper", stored.upper, now.upper)]
    pairs += [(kind.name, stored.bound(kind.name), now.bound(kind.name)) for kind in LIMITS[1:]]
    for name, a, b in pairs:
        if not np.array_equal(a, b):
            raise refuse(
                f"{name} limits {np.asarray(b).tolist()} differ from the recorded "
                f"{np.asarray(a).tolist()} (a parameter file not given? --params)"
            )
    dense = result.certificate.dense
    k = np.unique(np.linspace(0, len(dense.t) - 1, TORQUE_SAMPLES).round().astype(int))
    tau = robot.inverse_dynamics(dense.q[k], dense.qd[k], dense.qdd[k])
    scale = TORQUE_RTOL * np.max(np.abs(dense.tau), axis=0) + 1e-9
    worst = np.max(np.abs(tau - dense.tau[k]) / scale, axis=0)
    if (worst > 1.0).any():
        j = int(np.argmax(worst))
        raise refuse(
            f"its inverse dynamics differs from the stored certificate's (masses, inertias, "
            f"friction or joint placements): joint '{robot.joint_names[j]}' by "
            f"{worst[j] * scale[j]:.3g} [N·m | N] at most, tolerance {scale[j]:.3g}"
        )
