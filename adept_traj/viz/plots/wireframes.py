"""Wireframes of solids for the figures: polylines (each (k, 3), world frame [m]) outlining
a box, sphere, cylinder or capsule at a pose."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from adept_traj.collision import coal_kind, shape_of
from adept_traj.scene import Box, Capsule, Cylinder, Mesh, PointCloud, Sphere

__all__ = ["shape_wireframe", "solid_wireframe", "wireframe"]


def _circle(
    centre: np.ndarray, u: np.ndarray, v: np.ndarray, radius: float, n: int = 40
) -> np.ndarray:
    a = np.linspace(0.0, 2.0 * np.pi, n)
    return centre + radius * (np.cos(a)[:, None] * u + np.sin(a)[:, None] * v)


def wireframe(kind: str, dims: Sequence[float], pose: np.ndarray) -> list[np.ndarray]:
    """Polylines (each (k, 3), world frame [m]) outlining a solid at ``pose`` (4, 4).

    kind: ``"box"`` (dims: half sides [m]), ``"sphere"`` (radius [m]), ``"cylinder"`` and
    ``"capsule"`` (radius, half length along local z [m]); any other kind: no lines.
    """
    rot, c = pose[:3, :3], pose[:3, 3]
    ex, ey, ez = rot[:, 0], rot[:, 1], rot[:, 2]
    if kind == "box":
        h = np.asarray(dims, dtype=float)
        corners = np.array(
            [[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float
        )
        world = c + (corners * h) @ rot.T
        edges = [(a, b) for a in range(8) for b in range(a + 1, 8) if bin(a ^ b).count("1") == 1]
        return [world[[a, b]] for a, b in edges]
    if kind == "sphere":
        (rad,) = dims
        return [_circle(c, p, q, rad) for p, q in ((ex, ey), (ey, ez), (ez, ex))]
    if kind in ("cylinder", "capsule"):
        rad, half = dims
        lines = [_circle(c + s * half * ez, ex, ey, rad) for s in (-1, 1)]
        for a in np.linspace(0, 2 * np.pi, 4, endpoint=False):
            d = rad * (np.cos(a) * ex + np.sin(a) * ey)
            lines.append(np.array([c - half * ez + d, c + half * ez + d]))
        if kind == "capsule":
            a = np.linspace(0, np.pi, 20)[:, None]
            for s in (-1, 1):
                for p in (ex, ey):
                    lines.append(c + s * half * ez + rad * (np.cos(a) * p + s * np.sin(a) * ez))
        return lines
    return []


def shape_wireframe(shape: Any, pose: np.ndarray) -> list[np.ndarray]:
    """Wireframe of an obstacle shape (Box, Sphere, Cylinder, Capsule; a Mesh or a
    PointCloud: its bounding box) at ``pose`` (4, 4)."""
    if isinstance(shape, Box):
        return wireframe("box", 0.5 * shape.size, pose)
    if isinstance(shape, Sphere):
        return wireframe("sphere", (shape.radius,), pose)
    if isinstance(shape, Cylinder):
        return wireframe("cylinder", (shape.radius, 0.5 * shape.length), pose)
    if isinstance(shape, Capsule):
        return wireframe("capsule", (shape.radius, 0.5 * shape.length), pose)
    if isinstance(shape, (Mesh, PointCloud)):  # its bounding box
        lo, hi = shape.local_box
        centre = np.eye(4)
        centre[:3, 3] = 0.5 * (lo + hi)
        return wireframe("box", 0.5 * (hi - lo), pose @ centre)
    return []


def solid_wireframe(geometry: Any, pose: np.ndarray) -> list[np.ndarray]:
    """Wireframe of a robot solid (a coal collision geometry) at ``pose`` (4, 4); nothing
    for a geometry that is not a box, sphere, cylinder or capsule (e.g. a mesh)."""
    shape = shape_of(coal_kind(geometry))
    return [] if shape is None else shape_wireframe(shape, pose)
