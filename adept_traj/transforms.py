"""Homogeneous transforms: URDF roll-pitch-yaw and back, rotations about an axis, checks.

Conventions: a transform is a ``(..., 4, 4)`` array (rotation block, translation [m]);
``rpy`` follows URDF, R = Rz(yaw) · Ry(pitch) · Rx(roll) [rad].
All functions are batched over leading axes.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.validation import as_batch, as_finite_array

__all__ = [
    "as_rigid_transform",
    "axis_rotation",
    "rotation_from_rpy",
    "transform_from_xyz_rpy",
    "xyz_rpy_from_transform",
]

#: Largest deviation allowed from a rigid transform (orthonormal rotation, last row 0 0 0 1).
_RIGID_TOL = 1e-6


def rotation_from_rpy(rpy: Any) -> np.ndarray:
    """Rotation matrices from roll-pitch-yaw angles, URDF convention.

    ``R = Rz(yaw) · Ry(pitch) · Rx(roll)``: fixed-axis rotations about world x (roll), then
    world y (pitch), then world z (yaw).

    Args:
        rpy: (..., 3) roll, pitch, yaw [rad].

    Returns:
        (..., 3, 3) rotation matrices (a new array).
    """
    a = as_batch(rpy, "rpy", 3, "[rad]")
    cr, cp, cy = np.cos(a[..., 0]), np.cos(a[..., 1]), np.cos(a[..., 2])
    sr, sp, sy = np.sin(a[..., 0]), np.sin(a[..., 1]), np.sin(a[..., 2])
    r = np.empty((*a.shape[:-1], 3, 3))
    r[..., 0, 0] = cy * cp
    r[..., 0, 1] = cy * sp * sr - sy * cr
    r[..., 0, 2] = cy * sp * cr + sy * sr
    r[..., 1, 0] = sy * cp
    r[..., 1, 1] = sy * sp * sr + cy * cr
    r[..., 1, 2] = sy * sp * cr - cy * sr
    r[..., 2, 0] = -sp
    r[..., 2, 1] = cp * sr
    r[..., 2, 2] = cp * cr
    return r + 0.0  # + 0.0 turns -0.0 into 0.0 (cosmetic, in printed matrices)


def transform_from_xyz_rpy(xyz: Any = (0.0, 0.0, 0.0), rpy: Any = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Homogeneous transforms from a translation and roll-pitch-yaw angles (URDF ``<origin>``).

    Args:
        xyz: (..., 3) translation [m].
        rpy: (..., 3) roll, pitch, yaw [rad], ``R = Rz(yaw) · Ry(pitch) · Rx(roll)``.
            ``xyz`` and ``rpy`` broadcast against each other.

    Returns:
        (..., 4, 4) transforms (a new array).
    """
    p = as_batch(xyz, "xyz", 3, "[m]")
    r = rotation_from_rpy(rpy)
    batch = np.broadcast_shapes(p.shape[:-1], r.shape[:-2])
    t = np.zeros((*batch, 4, 4))
    t[..., :3, :3] = r
    t[..., :3, 3] = p
    t[..., 3, 3] = 1.0
    return t


def xyz_rpy_from_transform(transform: Any) -> tuple[np.ndarray, np.ndarray]:
    """Translation and URDF roll-pitch-yaw angles of rigid transforms.

    Inverse of :func:`transform_from_xyz_rpy`, with pitch in [-π/2, π/2] and roll, yaw in
    (-π, π]. At gimbal lock (``|pitch| = π/2``) roll is set to 0 and yaw carries the rotation.

    Args:
        transform: (..., 4, 4) rigid transforms.

    Returns:
        ``(xyz, rpy)``: (..., 3) translation [m] and (..., 3) roll, pitch, yaw [rad].
    """
    t = as_rigid_transform(transform, "transform", batched=True)
    r = t[..., :3, :3]
    cp = np.hypot(r[..., 0, 0], r[..., 1, 0])
    pitch = np.arctan2(-r[..., 2, 0], cp)
    locked = cp < 1e-12
    roll = np.where(locked, 0.0, np.arctan2(r[..., 2, 1], r[..., 2, 2]))
    yaw = np.where(
        locked,
        np.arctan2(-r[..., 0, 1], r[..., 1, 1]),
        np.arctan2(r[..., 1, 0], r[..., 0, 0]),
    )
    return t[..., :3, 3].copy(), np.stack([roll, pitch, yaw], axis=-1)


def as_rigid_transform(value: Any, name: str, *, batched: bool = False) -> np.ndarray:
    """Return ``value`` as a new float64 rigid transform, (4, 4) or (..., 4, 4) if batched.

    Raises :class:`InputShapeError` for a wrong shape and :class:`InvalidInputError` when the
    rotation block is not orthonormal with determinant +1 or the last row is not 0 0 0 1
    (tolerance 1e-6).
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


def axis_rotation(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    r"""Rotations (..., 3, 3) by ``angle`` (...) [rad] about the unit ``axis`` (3,) (Rodrigues).

    .. math:: R = \mathbf{1} + \sin\theta\,[u]_\times + (1-\cos\theta)\,[u]_\times^2
    """
    u = np.asarray(axis, dtype=float)
    k = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    s = np.sin(angle)[..., None, None]
    c = np.cos(angle)[..., None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)
