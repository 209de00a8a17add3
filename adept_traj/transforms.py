r"""Homogeneous transforms: URDF roll-pitch-yaw and back, and the rigid-transform check.

Conventions: a transform is a ``(..., 4, 4)`` array (rotation block, translation [m]);
``rpy`` follows URDF, :math:`R = R_z(\text{yaw})\,R_y(\text{pitch})\,R_x(\text{roll})` [rad].

The conversions are Pinocchio's (``pin.rpy.rpyToMatrix``, ``pin.rpy.matrixToRpy``,
``pin.SE3``), one call per pose. They serve file reading and writing (scene files, the
robot's parameter file), a handful of poses at a time: leading batch axes are accepted and
looped over (slower per pose than a closed-form numpy batch would be; no hot path converts
batches of angles).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.validation import as_batch, as_finite_array

__all__ = [
    "as_rigid_transform",
    "rotation_from_rpy",
    "transform_from_xyz_rpy",
    "xyz_rpy_from_transform",
]

#: Largest deviation allowed from a rigid transform (orthonormal rotation, last row 0 0 0 1).
_RIGID_TOL = 1e-6


def rotation_from_rpy(rpy: Any) -> np.ndarray:
    r"""Rotation matrices from roll-pitch-yaw angles, URDF convention (``pin.rpy.rpyToMatrix``).

    .. math:: R = R_z(\text{yaw})\,R_y(\text{pitch})\,R_x(\text{roll})

    fixed-axis rotations about world x (roll), then world y (pitch), then world z (yaw).

    Parameters
    ----------
    rpy: (..., 3) roll, pitch, yaw [rad].

    Returns
    -------
    (..., 3, 3) rotation matrices (a new array).
    """
    a = as_batch(rpy, "rpy", 3, "[rad]")
    rows = [pin.rpy.rpyToMatrix(r) for r in a.reshape(-1, 3)]
    return np.array(rows).reshape(*a.shape[:-1], 3, 3) + 0.0  # + 0.0: no -0.0 in printouts


def transform_from_xyz_rpy(xyz: Any = (0.0, 0.0, 0.0), rpy: Any = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Homogeneous transforms from a translation and roll-pitch-yaw angles (URDF ``<origin>``).

    Parameters
    ----------
    xyz: (..., 3) translation [m].
    rpy: (..., 3) roll, pitch, yaw [rad], ``R = Rz(yaw) · Ry(pitch) · Rx(roll)``.
        ``xyz`` and ``rpy`` broadcast against each other.

    Returns
    -------
    (..., 4, 4) transforms (a new array).
    """
    p = as_batch(xyz, "xyz", 3, "[m]")
    r = rotation_from_rpy(rpy)
    try:
        batch = np.broadcast_shapes(p.shape[:-1], r.shape[:-2])
    except ValueError:
        raise InputShapeError(
            f"xyz (..., 3) and rpy (..., 3) must broadcast together; got shapes {p.shape} and "
            f"{r.shape[:-1]}"
        ) from None
    t = np.zeros((*batch, 4, 4))
    t[..., :3, :3] = r
    t[..., :3, 3] = p
    t[..., 3, 3] = 1.0
    return t


def xyz_rpy_from_transform(transform: Any) -> tuple[np.ndarray, np.ndarray]:
    """Translation and URDF roll-pitch-yaw angles of rigid transforms (``pin.rpy.matrixToRpy``).

    Inverse of :func:`transform_from_xyz_rpy`: pitch in [-π/2, π/2], roll and yaw in [-π, π].
    At gimbal lock (``|pitch| = π/2``) only roll − yaw (pitch = π/2) or roll + yaw
    (pitch = −π/2) is determined; the angles returned give back the same rotation.

    Parameters
    ----------
    transform: (..., 4, 4) rigid transforms.

    Returns
    -------
    ``(xyz, rpy)``: (..., 3) translation [m] and (..., 3) roll, pitch, yaw [rad].
    """
    t = as_rigid_transform(transform, "transform", batched=True)
    poses = [pin.SE3(m) for m in t.reshape(-1, 4, 4)]
    xyz = np.array([pose.translation for pose in poses]).reshape(*t.shape[:-2], 3)
    rpy = np.array([pin.rpy.matrixToRpy(pose.rotation) for pose in poses])
    return xyz, rpy.reshape(*t.shape[:-2], 3) + 0.0


def as_rigid_transform(value: Any, name: str, *, batched: bool = False) -> np.ndarray:
    """Return ``value`` as a new float64 rigid transform, (4, 4) or (..., 4, 4) if batched.

    Raises :class:`InputShapeError` for a wrong shape and :class:`InvalidInputError` when the
    rotation block is not orthonormal with determinant +1 or the last row is not 0 0 0 1
    (tolerance 1e-6). Batched numpy: the check runs on every pose an obstacle or a scene is
    built with.
    """
    t = as_finite_array(value, name)
    if (batched and (t.ndim < 2 or t.shape[-2:] != (4, 4))) or (not batched and t.shape != (4, 4)):
        expected = "(..., 4, 4)" if batched else "(4, 4)"
        raise InputShapeError(f"{name} must have shape {expected}; got shape {t.shape}")
    r = t[..., :3, :3]
    gram_err = np.abs(np.swapaxes(r, -1, -2) @ r - np.eye(3)).max(initial=0.0)
    row_err = np.abs(t[..., 3, :] - np.array([0.0, 0.0, 0.0, 1.0])).max(initial=0.0)
    if gram_err > _RIGID_TOL or row_err > _RIGID_TOL or (np.linalg.det(r) <= 0.0).any():
        raise InvalidInputError(
            f"{name} must be a rigid transform (orthonormal rotation block with determinant +1, "
            f"last row [0, 0, 0, 1], tolerance {_RIGID_TOL}); rotation error {gram_err:.3g}, "
            f"last-row error {row_err:.3g}"
        )
    return t
