"""Batched forward kinematics and frame Jacobians of a Pinocchio chain, in numpy.

Pinocchio's Python API works one configuration per call (≈ 1.4 µs plus Python overhead);
a planner evaluates 10⁴–10⁶ configurations per generation. :class:`BatchKinematics` reads
the joint placements and axes of a Pinocchio model once and then evaluates whole
``(..., nq)`` batches with a few array operations per joint. It supports trees of 1-DoF
revolute and prismatic joints (any axis), which covers serial industrial arms; other joint
types raise :class:`~adept_traj.errors.RobotModelError`. Tests check it against Pinocchio.

Conventions: world = the robot base frame (Pinocchio's universe); poses ``(..., 4, 4)``;
Jacobians ``(..., 6, nq)`` with rows (v_x, v_y, v_z, ω_x, ω_y, ω_z) of the frame origin,
expressed in world axes (Pinocchio's ``LOCAL_WORLD_ALIGNED``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from .errors import RobotModelError
from .transforms import axis_rotation

__all__ = ["BatchKinematics"]


@dataclass(frozen=True)
class _Joint:
    parent: int
    placement: np.ndarray  # (4, 4) in the parent joint frame
    axis: np.ndarray  # (3,) unit, in the joint frame
    revolute: bool
    index: int  # index in q


class BatchKinematics:
    """Forward kinematics and Jacobians over batches (see the module docstring).

    Parameters
    ----------
    model:
        A Pinocchio model whose joints are all 1-DoF revolute or prismatic.
    """

    def __init__(self, model: pin.Model) -> None:
        data = model.createData()
        q0 = pin.neutral(model)
        pin.computeJointJacobians(model, data, q0)
        joints: list[_Joint] = []
        for i in range(1, model.njoints):
            jm = model.joints[i]
            if jm.nq != 1 or jm.nv != 1:
                raise RobotModelError(
                    f"joint '{model.names[i]}' is a {jm.shortname()} (nq={jm.nq}, nv={jm.nv}); "
                    "only 1-DoF revolute and prismatic joints are supported"
                )
            # The joint's motion subspace in its own frame: [v; ω] = [axis; 0] or [0; axis].
            s = pin.getJointJacobian(model, data, i, pin.LOCAL)[:, jm.idx_v]
            lin, ang = np.linalg.norm(s[:3]), np.linalg.norm(s[3:])
            revolute = ang > 0.5
            if not (np.isclose(max(lin, ang), 1.0) and min(lin, ang) < 1e-12):
                raise RobotModelError(
                    f"joint '{model.names[i]}' ({jm.shortname()}) is neither a pure revolute "
                    "nor a pure prismatic joint"
                )
            joints.append(
                _Joint(
                    parent=model.parents[i],
                    placement=model.jointPlacements[i].homogeneous.copy(),
                    axis=(s[3:] if revolute else s[:3]).copy(),
                    revolute=bool(revolute),
                    index=jm.idx_q,
                )
            )
        self._joints = tuple(joints)
        self.nq = model.nq
        #: ``support[i, k]`` is true when q_k moves joint frame i (row 0 = universe).
        self.support = np.zeros((model.njoints, model.nq), dtype=bool)
        for i, j in enumerate(joints, start=1):
            self.support[i] = self.support[j.parent]
            self.support[i, j.index] = True
        self.revolute = np.array([j.revolute for j in joints])

    def joint_poses(self, q: np.ndarray) -> np.ndarray:
        """World poses (..., njoints, 4, 4) of every joint frame (index 0 = universe)
        for configurations ``q`` (..., nq) [rad | m]."""
        batch = q.shape[:-1]
        out = np.empty((*batch, len(self._joints) + 1, 4, 4))
        out[..., 0, :, :] = np.eye(4)
        for i, j in enumerate(self._joints, start=1):
            local = np.broadcast_to(j.placement, (*batch, 4, 4)).copy()
            qi = q[..., j.index]
            if j.revolute:
                local[..., :3, :3] = j.placement[:3, :3] @ axis_rotation(j.axis, qi)
            else:
                local[..., :3, 3] += (j.placement[:3, :3] @ j.axis) * qi[..., None]
            out[..., i, :, :] = out[..., j.parent, :, :] @ local
        return out

    def jacobian(self, joint_poses: np.ndarray, point_joint: int, point: np.ndarray) -> np.ndarray:
        r"""Jacobians (..., 6, nq) of a point rigidly attached to joint frame ``point_joint``.

        ``joint_poses`` are from :meth:`joint_poses`; ``point`` (..., 3) is the point's world
        position [m]. Columns: revolute :math:`[z_k \times (p - o_k);\ z_k]`, prismatic
        :math:`[z_k;\ 0]`, zero for joints not supporting ``point_joint``.
        """
        batch = joint_poses.shape[:-3]
        jac = np.zeros((*batch, 6, self.nq))
        for i, j in enumerate(self._joints, start=1):
            if not self.support[point_joint, j.index]:
                continue
            z = joint_poses[..., i, :3, :3] @ j.axis
            if j.revolute:
                jac[..., :3, j.index] = np.cross(z, point - joint_poses[..., i, :3, 3])
                jac[..., 3:, j.index] = z
            else:
                jac[..., :3, j.index] = z
        return jac
