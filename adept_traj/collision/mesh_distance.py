r"""Distances to mesh obstacles that see a robot solid *inside* a closed mesh.

coal's distance to a ``BVHModel`` is the distance to its triangles: a solid that lies
wholly inside a closed mesh is at a positive distance :math:`d` from every triangle. Such
a solid does not touch the surface, and it is connected, so it is either wholly inside or
wholly outside the mesh; any one of its points tells which. :class:`MeshDistance` takes
coal's witness point on the solid (``getNearestPoint1``, a point of the solid) and asks the
mesh's winding-number test (:meth:`~adept_traj.scene.Mesh.contains`); inside, the distance
is reported as :math:`-d` and coal's normal is reversed (so the distance gradients push
the solid towards the nearest surface, the way out).

What the numbers mean: a negative distance is a collision, as for every obstacle; its
magnitude inside a mesh is the depth below the nearest triangle, a lower bound of the
depth the solid would need to leave the mesh. A solid crossing the surface gets coal's
triangle-level penetration depth (negative). An open mesh has no inside (a thin surface).

The test runs only where coal's distance is positive and the witness point is inside the
mesh's bounding box (else it is outside), at the cost of one winding-number sum over the
mesh's triangles (a few numpy passes over (m,) arrays).
"""

from __future__ import annotations

from typing import Any

import coal
import numpy as np

from adept_traj.collision.cloud_distance import CloudDistance, supports_distance_bound
from adept_traj.scene.meshes import Mesh
from adept_traj.scene.point_clouds import PointCloud

__all__ = ["MeshDistance", "distance_functor"]


class MeshDistance:
    """A coal ``ComputeDistance`` of a robot solid and a closed :class:`Mesh` obstacle,
    with the inside test of the module docstring; called as coal's functor
    ``(tf_solid, tf_mesh, request, result) -> distance`` [m]."""

    def __init__(self, solid: coal.CollisionGeometry, mesh_geometry: Any, mesh: Mesh) -> None:
        self._functor = coal.ComputeDistance(solid, mesh_geometry)
        self._geometries = (solid, mesh_geometry)  # coal's functor keeps raw pointers
        self.mesh = mesh
        self._lo, self._hi = mesh.local_box

    def __call__(
        self,
        tf_solid: coal.Transform3s,
        tf_mesh: coal.Transform3s,
        request: coal.DistanceRequest,
        result: coal.DistanceResult,
    ) -> float:
        d = self._functor(tf_solid, tf_mesh, request, result)
        if d <= 0.0:
            return d
        p = np.asarray(result.getNearestPoint1(), dtype=float)
        local = np.asarray(tf_mesh.getRotation()).T @ (p - np.asarray(tf_mesh.getTranslation()))
        if ((local < self._lo) | (local > self._hi)).any():
            return d
        if not self.mesh.contains(local[None])[0]:
            return d
        result.min_distance = -d
        result.normal = -np.asarray(result.normal, dtype=float)
        return -d


def distance_functor(
    solid: coal.CollisionGeometry, obstacle_geometry: Any, shape: object, cap: float = np.inf
) -> Any:
    """The distance functor of a robot solid and an obstacle's coal geometry: a
    :class:`MeshDistance` for a closed :class:`Mesh` obstacle, a
    :class:`~adept_traj.collision.cloud_distance.CloudDistance` for a primitive solid and
    a :class:`PointCloud` (distances above ``cap`` [m] returned as a lower bound above
    it), else coal's own ``ComputeDistance``."""
    if isinstance(shape, Mesh) and shape.closed:
        return MeshDistance(solid, obstacle_geometry, shape)
    if isinstance(shape, PointCloud) and supports_distance_bound(solid):
        return CloudDistance(solid, obstacle_geometry, shape, cap)
    return coal.ComputeDistance(solid, obstacle_geometry)
