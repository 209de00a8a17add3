"""What one forward-kinematics pass gives: joint frames, tool pose, manipulability, solids.

:class:`ForwardKinematics` is returned by :meth:`Robot.forward_kinematics
<adept_traj.robot.Robot.forward_kinematics>`; :func:`solid_frames` and :func:`place_solids`
place the collision solids of a geometry model on the joint poses.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import pinocchio as pin

from adept_traj.robot.kinematics import frames_to_poses

__all__ = ["ForwardKinematics", "place_solids", "solid_frames"]


@dataclass(frozen=True)
class ForwardKinematics:
    """Everything the planner needs from one forward-kinematics pass over ``q`` (..., nq).

    Attributes
    ----------
    joint_frames: (njoints, 3, 4, N) joint frames in the base frame, component-major
        (:meth:`~adept_traj.robot.kinematics.BatchKinematics.joint_frames`; N = ∏ ``...``).
    joint_poses: (..., njoints, 4, 4) the same as poses (index 0 = universe; formed on
        first access).
    tool_pose: (..., 4, 4) tool frame in the base frame.
    manipulability: (...) as :meth:`Robot.manipulability` [m² for the SCARA], or ``None``
        when the robot has no task rows.
    geometry_poses: (..., n_geom, 4, 4) collision solids in the base frame (computed on
        first access: the collision checker works from the joint poses and forms solid
        poses only near obstacles).
    """

    joint_frames: np.ndarray
    tool_pose: np.ndarray
    manipulability: np.ndarray | None
    #: (parent joint per solid (n_geom,), solid placements in them (n_geom, 4, 4)).
    solid_frames: tuple[np.ndarray, np.ndarray] = field(repr=False)

    @cached_property
    def joint_poses(self) -> np.ndarray:
        return frames_to_poses(self.joint_frames, self.tool_pose.shape[:-2])

    @cached_property
    def geometry_poses(self) -> np.ndarray:
        return place_solids(self.joint_poses, self.solid_frames)


def solid_frames(gm: pin.GeometryModel) -> tuple[np.ndarray, np.ndarray]:
    """(parent joint of each object (n_geom,), its placement in that joint's frame
    (n_geom, 4, 4)) of a geometry model."""
    parents = np.array([g.parentJoint for g in gm.geometryObjects], dtype=int)
    local = np.array([g.placement.homogeneous for g in gm.geometryObjects]).reshape(-1, 4, 4)
    return parents, local


def place_solids(joint_poses: np.ndarray, frames: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """Poses (..., n_geom, 4, 4) of the objects of :func:`solid_frames` ``frames`` for joint
    poses (..., njoints, 4, 4)."""
    parents, local = frames
    return joint_poses[..., parents, :, :] @ local
