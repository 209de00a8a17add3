"""The framing of a drawn scene: the floor under it and a camera that sees all of it.

Both take the world points [m] the scene covers (robot solids, obstacles, tool path) as
an (n, 3) array; :mod:`~adept_traj.viz.playback` adds the floor nodes to its playback and
sets the camera.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from adept_traj.viz.meshcat_geometry import Part, translation
from adept_traj.viz.meshcat_modules import mg

__all__ = ["FLOOR_COLOR", "GRID_COLOR", "camera", "floor"]

FLOOR_COLOR = 0xE5E7E9
GRID_COLOR = 0xB3B6B7
_FOV_DEG = 75.0  # meshcat's default camera: vertical field of view
_VIEW_DIRECTION = np.array([-0.7, -1.2, 0.9])  # camera offset direction from the target
_GRID_STEP = 0.1  # floor grid spacing [m]
_FLOOR_MARGIN = 0.3  # floor beyond the drawn scene [m]


def floor(points: np.ndarray) -> list[tuple[str, tuple[Part, ...], np.ndarray]]:
    """The floor z = 0 under ``points`` (n, 3) [m]: a light slab with a 0.1 m grid, and the
    world axes (x red, y green, z blue, 0.2 m) at the origin, as (node path, parts,
    (4, 4) world pose) of three fixed nodes."""
    lo = np.floor((points[:, :2].min(axis=0) - _FLOOR_MARGIN) / _GRID_STEP) * _GRID_STEP
    hi = np.ceil((points[:, :2].max(axis=0) + _FLOOR_MARGIN) / _GRID_STEP) * _GRID_STEP
    size = hi - lo
    slab = mg.Mesh(mg.Box([*size, 0.004]), mg.MeshLambertMaterial(color=FLOOR_COLOR))
    centre = translation([*(0.5 * (lo + hi)), -0.0021])
    segments: list[Any] = []
    for axis in (0, 1):
        n = round(size[axis] / _GRID_STEP)
        for v in lo[axis] + _GRID_STEP * np.arange(n + 1):
            a, b = np.zeros(3), np.zeros(3)
            a[axis] = b[axis] = v
            a[1 - axis], b[1 - axis] = lo[1 - axis], hi[1 - axis]
            segments += [a, b]
    grid = mg.LineSegments(
        mg.PointsGeometry(np.ascontiguousarray(np.array(segments).T, dtype=np.float32)),
        mg.LineBasicMaterial(color=GRID_COLOR),
    )
    return [
        ("floor/slab", (Part(slab, np.eye(4)),), centre),
        ("floor/grid", (Part(grid, np.eye(4)),), np.eye(4)),
        ("floor/axes", (Part(mg.triad(0.2), np.eye(4)),), np.eye(4)),
    ]


def camera(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A camera target (the centre of the box around ``points`` (n, 3)) and a position from
    which all of it is in view [m]."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    target = 0.5 * (lo + hi)
    radius = max(0.5 * float(np.linalg.norm(hi - lo)), 0.3) + 0.15
    distance = 1.05 * radius / math.tan(math.radians(0.5 * _FOV_DEG))
    direction = _VIEW_DIRECTION / np.linalg.norm(_VIEW_DIRECTION)
    return target, target + distance * direction
