"""Batched forward kinematics and frame Jacobians of a Pinocchio chain, in numpy.

Pinocchio's Python API works one configuration per call (plus Python overhead);
a planner evaluates 10⁴–10⁶ configurations per generation. :class:`BatchKinematics` reads
the joint placements and axes of a Pinocchio model once and then evaluates whole
``(..., nq)`` batches with a few array operations per joint. It supports trees of 1-DoF
revolute and prismatic joints (any axis), which covers serial industrial arms, and mimic
joints of those (:math:`q_i = m\\,q_\text{leader} + o`, Pinocchio's ``JointModelMimic``);
other joint types raise :class:`~adept_traj.errors.RobotModelError`. Tests check it against
Pinocchio.

Conventions: world = the robot base frame (Pinocchio's universe); poses ``(..., 4, 4)``;
Jacobians ``(..., 6, nq)`` with rows (v_x, v_y, v_z, ω_x, ω_y, ω_z) of the frame origin,
expressed in world axes (Pinocchio's ``LOCAL_WORLD_ALIGNED``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from adept_traj.errors import RobotModelError

__all__ = ["BatchKinematics", "compose", "frames_to_poses", "stack_times"]


@dataclass(frozen=True)
class _Joint:
    parent: int
    placement: np.ndarray  # (4, 4) in the parent joint frame
    axis: np.ndarray  # (3,) unit, in the joint frame
    revolute: bool
    index: int  # index in q
    scale: float = 1.0  # joint value = scale · q[index] + offset (mimic joints)
    offset: float = 0.0


def _rotation_to_axis(axis: np.ndarray) -> np.ndarray:
    """A rotation (3, 3) whose third column is the unit ``axis`` (identity for e_z)."""
    z = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    if np.array_equal(z, [0.0, 0.0, 1.0]):
        return np.eye(3)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


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
            if jm.shortname() == "JointModelMimic":
                joints.append(_mimic_joint(model, i))
                continue
            if jm.nq != 1 or jm.nv != 1:
                raise RobotModelError(
                    f"joint '{model.names[i]}' is a {jm.shortname()} (nq={jm.nq}, nv={jm.nv}); "
                    "only 1-DoF revolute and prismatic joints (and mimics of them) are supported"
                )
            # The joint's motion subspace in its own frame: [v; ω] = [axis; 0] or [0; axis].
            jacobian = pin.getJointJacobian(model, data, i, pin.LOCAL).reshape(6, model.nv)
            s = jacobian[:, jm.idx_v]  # (a 6 × 1 Jacobian comes back as a vector)
            joints.append(_one_dof_joint(model, i, s))
        self._joints = tuple(joints)
        # Revolute: T = P U Rz(q) U^T with U e_z = axis (pre = P U, post = U^T or None).
        self._pre, self._post = [], []
        for j in joints:
            u = _rotation_to_axis(j.axis) if j.revolute else np.eye(3)
            pre = j.placement.copy()
            pre[:3, :3] = j.placement[:3, :3] @ u
            self._pre.append(pre)
            post = None
            if j.revolute and not np.allclose(u, np.eye(3), atol=0.0, rtol=0.0):
                post = np.eye(4)
                post[:3, :3] = u.T
            self._post.append(post)
        self.nq = model.nq
        #: ``support[i, k]`` is true when q_k moves joint frame i (row 0 = universe).
        self.support = np.zeros((model.njoints, model.nq), dtype=bool)
        #: ``ancestor[i, k]`` is true when joint k moves joint frame i (k = i included).
        self._ancestor = np.eye(model.njoints, dtype=bool)
        for i, j in enumerate(joints, start=1):
            self.support[i] = self.support[j.parent]
            self.support[i, j.index] = True
            self._ancestor[i] |= self._ancestor[j.parent]
        self.revolute = np.array([j.revolute for j in joints])
        #: Unit axis (njoints - 1, 3) of every joint in its own frame.
        self.axes = np.array([j.axis for j in joints]).reshape(-1, 3)
        #: Parent frame (njoints - 1,) of every joint (0 = universe).
        self.parents = np.array([j.parent for j in joints], dtype=int)
        # Per joint: (c, ±1) when its axis is ±e_c (then z = ±column c of its frame), or None.
        self._axis_column = [_axis_column(j.axis) for j in joints]

    def joint_frames(self, q: np.ndarray) -> np.ndarray:
        """Joint frames, component-major: (njoints, 3, 4, N) — the top three rows of the
        world pose of every joint frame (index 0 = universe) for the N = ∏ q.shape[:-1]
        configurations ``q`` (..., nq) [rad | m] (flattened), the samples innermost.

        .. math::
            {}^0T_i = {}^0T_{p(i)}\\, P_i\\, U_i\\, R_z(q_i)\\, U_i^\\top \\ \\text{(revolute)},
            \\qquad {}^0T_{p(i)}\\, P_i\\, \\mathrm{Trans}(a_i q_i) \\ \\text{(prismatic)}

        with :math:`P_i` the joint placement and :math:`U_i` a constant rotation taking
        :math:`e_z` to the joint axis (the identity for z axes): the product by the
        constant :math:`P_i U_i` is one small GEMM over all samples per row, and the one by
        :math:`R_z(q)` only mixes two columns. Every component is a contiguous (N,) array,
        so the elementwise work streams (faster than stacked 4 × 4 products).
        """
        qf = q.reshape(-1, q.shape[-1])
        n = qf.shape[0]
        frames = np.empty((len(self._joints) + 1, 3, 4, n))
        frames[0] = np.eye(4)[:3, :, None]
        for i, (j, pre, post) in enumerate(zip(self._joints, self._pre, self._post), start=1):
            dst = frames[i]
            np.matmul(pre.T, frames[j.parent], out=dst)  # = compose(parent, pre), in place
            qi = (
                qf[:, j.index]
                if j.scale == 1.0 and j.offset == 0.0
                else j.scale * qf[:, j.index] + j.offset
            )
            if j.revolute:  # columns 0, 1: c a0 + s a1 and c a1 − s a0, in place
                c, s = np.cos(qi), np.sin(qi)
                a0, a1 = dst[:, 0].copy(), dst[:, 1].copy()
                np.multiply(c, a0, out=dst[:, 0])
                dst[:, 0] += s * a1
                np.multiply(c, a1, out=dst[:, 1])
                dst[:, 1] -= s * a0
                if post is not None:
                    dst[:] = compose(dst, post)
            else:
                dst[:, 3] += np.tensordot(j.axis, dst[:, :3], axes=([0], [1])) * qi
        return frames

    def joint_poses(self, q: np.ndarray) -> np.ndarray:
        """World poses (..., njoints, 4, 4) of every joint frame (index 0 = universe)
        for configurations ``q`` (..., nq) [rad | m] (:meth:`joint_frames`, sample-major)."""
        return frames_to_poses(self.joint_frames(q), q.shape[:-1])

    def jacobian(self, joint_poses: np.ndarray, point_joint: int, point: np.ndarray) -> np.ndarray:
        r"""Jacobians (..., 6, nq) of a point rigidly attached to joint frame ``point_joint``.

        ``joint_poses`` are from :meth:`joint_poses`; ``point`` (..., 3) is the point's world
        position [m]. See :meth:`frame_jacobian` (the same, component-major).
        """
        batch = joint_poses.shape[:-3]
        flat = joint_poses.reshape(-1, *joint_poses.shape[-3:])
        frames = np.ascontiguousarray(flat[:, :, :3, :].transpose(1, 2, 3, 0))
        points = np.ascontiguousarray(np.reshape(point, (-1, 3)).T)
        jac = self.frame_jacobian(frames, point_joint, points)  # (6, nq, N)
        return np.moveaxis(jac, -1, 0).reshape(*batch, 6, self.nq)

    def frame_jacobian(self, frames: np.ndarray, point_joint: int, point: np.ndarray) -> np.ndarray:
        r"""Jacobians (6, nq, N), component-major, of a point rigidly attached to joint frame
        ``point_joint``, from :meth:`joint_frames` ``frames`` (njoints, 3, 4, N) and the
        point's world positions ``point`` (3, N) [m]. Rows (v_x, v_y, v_z, ω_x, ω_y, ω_z);
        columns: revolute :math:`[z_k \times (p - o_k);\ z_k]`, prismatic
        :math:`[z_k;\ 0]`, zero for joints not supporting ``point_joint``.
        """
        n = frames.shape[-1]
        jac = np.zeros((6, self.nq, n))
        for i, j in enumerate(self._joints, start=1):
            if not self._ancestor[point_joint, i]:  # (a mimic shares its leader's index)
                continue
            z = np.tensordot(j.axis, frames[i, :, :3], axes=([0], [1]))  # (3, N)
            z = z if j.scale == 1.0 else j.scale * z  # a mimic moves scale × its leader
            if j.revolute:
                r = point - frames[i, :, 3]
                jac[0, j.index] += z[1] * r[2] - z[2] * r[1]  # z × r
                jac[1, j.index] += z[2] * r[0] - z[0] * r[2]
                jac[2, j.index] += z[0] * r[1] - z[1] * r[0]
                jac[3:, j.index] += z
            else:
                jac[:3, j.index] += z
        return jac

    def jacobian_rows(
        self, frames: np.ndarray, point_joint: int, point: np.ndarray, rows: list[int]
    ) -> np.ndarray:
        """The rows ``rows`` (indices into (v_x, v_y, v_z, ω_x, ω_y, ω_z)) of
        :meth:`frame_jacobian`, (len(rows), nq, N), for a manipulability measure. When they
        make a square matrix (len(rows) = nq, the measure :math:`|\\det J_t|`), only those
        rows are formed, and a joint axis along an axis of its frame reads that column of
        the frame (±1 × x instead of the dot product x + 0·y + 0·z: the same values, but a
        zero may differ in sign, which the absolute value of a determinant does not see)."""
        if len(rows) != self.nq:  # a Gram determinant: exactly frame_jacobian's rows
            return self.frame_jacobian(frames, point_joint, point)[rows]
        jac = np.zeros((len(rows), self.nq, frames.shape[-1]))
        for i, j in enumerate(self._joints, start=1):
            if not self._ancestor[point_joint, i]:
                continue
            column = self._axis_column[i - 1]
            if column is None:
                z = np.tensordot(j.axis, frames[i, :, :3], axes=([0], [1]))  # (3, N)
            else:
                z = frames[i, :, column[0]] if column[1] > 0 else -frames[i, :, column[0]]
            z = z if j.scale == 1.0 else j.scale * z
            r = point - frames[i, :, 3] if j.revolute else None
            for out, row in enumerate(rows):
                if not j.revolute:
                    if row < 3:
                        jac[out, j.index] += z[row]
                elif row >= 3:
                    jac[out, j.index] += z[row - 3]
                else:  # z × r, as in frame_jacobian
                    a, b = (row + 1) % 3, (row + 2) % 3
                    jac[out, j.index] += z[a] * r[b] - z[b] * r[a]
        return jac


def _axis_column(axis: np.ndarray) -> tuple[int, float] | None:
    """``(c, ±1)`` when the unit ``axis`` (3,) is ±e_c exactly, else None."""
    nonzero = np.flatnonzero(axis)
    if len(nonzero) == 1 and abs(axis[nonzero[0]]) == 1.0:
        return int(nonzero[0]), float(axis[nonzero[0]])
    return None


def _one_dof_joint(model: pin.Model, i: int, s: np.ndarray) -> _Joint:
    """Joint ``i`` of ``model`` (1-DoF) from its motion subspace ``s`` (6,) in its frame."""
    lin, ang = np.linalg.norm(s[:3]), np.linalg.norm(s[3:])
    revolute = ang > 0.5
    if not (np.isclose(max(lin, ang), 1.0) and min(lin, ang) < 1e-12):
        raise RobotModelError(
            f"joint '{model.names[i]}' ({model.joints[i].shortname()}) is neither a pure "
            "revolute nor a pure prismatic joint"
        )
    return _Joint(
        parent=model.parents[i],
        placement=model.jointPlacements[i].homogeneous.copy(),
        axis=(s[3:] if revolute else s[:3]).copy(),
        revolute=bool(revolute),
        index=model.joints[i].idx_q,
    )


def _mimic_joint(model: pin.Model, i: int) -> _Joint:
    """Mimic joint ``i``: its axis from its motion between two values of its leader (the
    logarithm of the joint motion divided by the change of the joint value)."""
    mimic = model.joints[i].extract()
    data = model.createData()
    motions = []
    for leader in (0.0, 0.5):
        q = pin.neutral(model)
        q[mimic.idx_q] = leader
        pin.forwardKinematics(model, data, q)
        motion = model.jointPlacements[i].inverse() * data.liMi[i]
        motions.append(pin.log6(motion).vector)
    s = (motions[1] - motions[0]) / (0.5 * mimic.scaling)
    joint = _one_dof_joint(model, i, s)
    return _Joint(
        joint.parent,
        joint.placement,
        joint.axis,
        joint.revolute,
        mimic.idx_q,
        scale=float(mimic.scaling),
        offset=float(mimic.offset),
    )


def compose(frames: np.ndarray, transform: np.ndarray) -> np.ndarray:
    """Component-major frames (3, 4, N) times a constant homogeneous ``transform`` (4, 4):
    row r of the product is :math:`T^\\top` applied to row r, one GEMM over the samples."""
    return np.matmul(transform.T, frames)


def stack_times(stack: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``stack @ b`` for a stack of matrices (..., m, k) and one constant matrix (k, n),
    as one GEMM over all the rows (numpy's stacked product calls BLAS once per matrix,
    which dominates for small ones); (..., m, n)."""
    return (stack.reshape(-1, stack.shape[-1]) @ b).reshape(*stack.shape[:-1], b.shape[-1])


def frames_to_poses(frames: np.ndarray, batch: tuple[int, ...]) -> np.ndarray:
    """Poses (``*batch``, k, 4, 4) from component-major frames (k, 3, 4, N), N = ∏ ``batch``."""
    k, n = frames.shape[0], frames.shape[-1]
    out = np.empty((n, k, 4, 4))
    out[:, :, :3, :] = frames.transpose(3, 0, 1, 2)
    out[:, :, 3, :3] = 0.0
    out[:, :, 3, 3] = 1.0
    return out.reshape(*batch, k, 4, 4)
