"""Homogeneous transforms: URDF roll-pitch-yaw, batched rotations about an axis.

Conventions: a transform is a ``(..., 4, 4)`` array [m]; ``rpy`` follows URDF,
:math:`R = R_z(\\text{yaw}) R_y(\\text{pitch}) R_x(\\text{roll})` [rad].
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["axis_rotation", "rpy_matrix", "transform"]


def rpy_matrix(rpy: Sequence[float]) -> np.ndarray:
    """Rotation matrix (3, 3) of URDF roll-pitch-yaw angles ``rpy`` (3,) [rad]."""
    r, p, y = (float(a) for a in rpy)
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def transform(xyz: Sequence[float] = (0.0, 0.0, 0.0), rpy: Sequence[float] = (0.0, 0.0, 0.0)):
    """Homogeneous transform (4, 4) from a translation ``xyz`` [m] and URDF ``rpy`` [rad]."""
    out = np.eye(4)
    out[:3, :3] = rpy_matrix(rpy)
    out[:3, 3] = np.asarray(xyz, dtype=float)
    return out


def axis_rotation(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    r"""Rotations (..., 3, 3) by ``angle`` (...) [rad] about the unit ``axis`` (3,) (Rodrigues).

    .. math:: R = \mathbf{1} + \sin\theta\,[u]_\times + (1-\cos\theta)\,[u]_\times^2
    """
    u = np.asarray(axis, dtype=float)
    k = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    s = np.sin(angle)[..., None, None]
    c = np.cos(angle)[..., None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)
