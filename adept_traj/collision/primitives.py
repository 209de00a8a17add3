"""The coal primitives of the robot solids and obstacles, as the broad phase sees them.

Their kind and dimensions (:func:`coal_kind`), the matching :mod:`adept_traj.scene.shapes`
object (:func:`shape_of`), the ball enclosing a geometry and the spheres covering it (from
its local bounding box), and the half-length of a primitive's projection on a direction
(for the separating-axis bound).
"""

from __future__ import annotations

import coal
import numpy as np

from adept_traj.scene.shapes import Box, Capsule, Cylinder, Sphere

__all__ = ["coal_kind", "covering_spheres", "enclosing_ball", "half_extent", "shape_of"]


def _local_box(geometry: coal.CollisionGeometry) -> tuple[np.ndarray, np.ndarray]:
    """Corners (lo, hi) (3,) [m] of a geometry's bounding box in its own frame."""
    geometry.computeLocalAABB()
    return np.array(geometry.aabb_local.min_), np.array(geometry.aabb_local.max_)


def covering_spheres(geometry: coal.CollisionGeometry) -> tuple[np.ndarray, np.ndarray]:
    """Centres (k, 3) in the geometry frame and radii (k,) of spheres covering its local
    bounding box, cut into k near-cubic pieces along its longest side."""
    lo, hi = _local_box(geometry)
    extent = hi - lo
    axis = int(np.argmax(extent))
    others = np.delete(extent, axis)
    k = max(1, int(np.ceil(extent[axis] / max(others.max(), 1e-9))))
    piece = extent.copy()
    piece[axis] /= k
    centres = np.tile(0.5 * (lo + hi), (k, 1))
    centres[:, axis] = lo[axis] + piece[axis] * (np.arange(k) + 0.5)
    return centres, np.full(k, 0.5 * np.linalg.norm(piece))


def enclosing_ball(geometry: coal.CollisionGeometry) -> tuple[np.ndarray, float]:
    """Centre (3,) in the geometry frame and radius of a ball containing the geometry (the
    ball around its local bounding box)."""
    lo, hi = _local_box(geometry)
    return 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo))


def half_extent(kind: str, dims: np.ndarray, n_local: np.ndarray) -> np.ndarray:
    """Half-length (...) of the projection of a centred shape on unit directions ``n_local``
    (..., 3) given in the shape's frame. ``kind``/``dims``: box (hx, hy, hz), cylinder
    (r, h), sphere (r,), capsule (r, h), with h the half length along local z."""
    if kind == "box":
        return np.abs(n_local) @ dims
    if kind == "sphere":
        return np.full(n_local.shape[:-1], dims[0])
    axial = np.abs(n_local[..., 2])
    if kind == "capsule":
        return dims[1] * axial + dims[0]
    return dims[1] * axial + dims[0] * np.sqrt(np.maximum(0.0, 1.0 - axial**2))


def coal_kind(geometry: coal.CollisionGeometry) -> tuple[str, np.ndarray] | None:
    """(kind, dims) of a coal primitive for the separating-axis level, or None (no bound)."""
    if isinstance(geometry, coal.Box):
        return "box", np.array(geometry.halfSide)
    if isinstance(geometry, coal.Cylinder):
        return "cylinder", np.array([geometry.radius, geometry.halfLength])
    if isinstance(geometry, coal.Capsule):
        return "capsule", np.array([geometry.radius, geometry.halfLength])
    if isinstance(geometry, coal.Sphere):
        return "sphere", np.array([geometry.radius])
    return None


def shape_of(kind: tuple[str, np.ndarray] | None) -> object | None:
    """The :mod:`adept_traj.scene.shapes` shape of a coal primitive (for point distances)."""
    if kind is None:
        return None
    name, dims = kind
    if name == "box":
        return Box(2.0 * dims)
    if name == "sphere":
        return Sphere(float(dims[0]))
    if name == "cylinder":
        return Cylinder(float(dims[0]), 2.0 * float(dims[1]))
    return Capsule(float(dims[0]), 2.0 * float(dims[1]))
