"""Obstacle shapes as triangle meshes for drawing: :func:`shape_triangles`.

The front explorer (:mod:`adept_traj.viz.explorer`) draws every obstacle as triangles;
the primitives have no triangles of their own, so they are tessellated here: circles as
regular :data:`SEGMENTS`-gons, spheres as UV spheres of :data:`RINGS` rings, capsules as a
cylinder and two spheres (:func:`~adept_traj.scene.merge_meshes`). The distances never use
these triangles: coal's exact primitives do (:mod:`adept_traj.collision`).
"""

from __future__ import annotations

import math

import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.scene.meshes import Mesh, merge_meshes
from adept_traj.scene.point_clouds import PointCloud
from adept_traj.scene.shapes import Box, Capsule, Cylinder, Shape, Sphere

__all__ = ["RINGS", "SEGMENTS", "shape_triangles"]

#: Segments of the drawn circles of spheres, cylinders and capsules.
SEGMENTS = 16
#: Rings of a drawn sphere, pole to pole.
RINGS = 8


def _sphere(radius: float, centre_z: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (v, 3) and triangles (f, 3) of a UV sphere centred at (0, 0, centre_z)."""
    theta = np.linspace(0.0, math.pi, RINGS + 1)
    phi = np.linspace(0.0, 2 * math.pi, SEGMENTS, endpoint=False)
    th, ph = np.meshgrid(theta, phi, indexing="ij")
    v = radius * np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], -1)
    v = v.reshape(-1, 3) + np.array([0.0, 0.0, centre_z])
    i, j = np.meshgrid(np.arange(RINGS), np.arange(SEGMENTS), indexing="ij")
    a = i * SEGMENTS + j
    b = i * SEGMENTS + (j + 1) % SEGMENTS
    c, d = a + SEGMENTS, b + SEGMENTS
    faces = np.concatenate([np.stack([a, d, b], -1), np.stack([a, c, d], -1)]).reshape(-1, 3)
    return v, faces


def _cylinder(radius: float, length: float) -> tuple[np.ndarray, np.ndarray]:
    """A closed cylinder along z, centred (vertices, triangles)."""
    phi = np.linspace(0.0, 2 * math.pi, SEGMENTS, endpoint=False)
    ring = np.stack([radius * np.cos(phi), radius * np.sin(phi)], -1)
    z = 0.5 * length
    v = np.vstack([np.column_stack([ring, np.full(SEGMENTS, -z)]),
                   np.column_stack([ring, np.full(SEGMENTS, z)]),
                   [[0, 0, -z], [0, 0, z]]])  # fmt: skip
    j = np.arange(SEGMENTS)
    k = (j + 1) % SEGMENTS
    n = SEGMENTS
    side = np.concatenate([np.stack([j, k, k + n], -1), np.stack([j, k + n, j + n], -1)])
    caps = np.concatenate([np.stack([np.full(n, 2 * n), k, j], -1),
                           np.stack([np.full(n, 2 * n + 1), j + n, k + n], -1)])  # fmt: skip
    return v, np.concatenate([side, caps])


def _box(size: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The 8 corners (8, 3) and 12 triangles (12, 3) of a centred box of edges ``size`` [m]."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7],
                      [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])  # fmt: skip
    return corners * (0.5 * np.asarray(size, float)), faces


def shape_triangles(shape: Shape | Mesh | PointCloud) -> tuple[np.ndarray, np.ndarray]:
    """An obstacle shape as a triangle mesh in the shape's frame, for drawing.

    Parameters
    ----------
    shape: a :class:`~adept_traj.scene.Box`, :class:`~adept_traj.scene.Sphere`,
        :class:`~adept_traj.scene.Cylinder`, :class:`~adept_traj.scene.Capsule` (each
        circle a regular :data:`SEGMENTS`-gon, a sphere :data:`RINGS` rings from pole to
        pole: the drawn solid lies inside the true one, its vertices on its surface), a
        :class:`~adept_traj.scene.Mesh` (its own triangles) or a
        :class:`~adept_traj.scene.PointCloud` (the box of its points).

    Returns
    -------
    vertices : numpy.ndarray
        ``(v, 3)`` [m], in the shape's frame.
    triangles : numpy.ndarray
        ``(f, 3)`` vertex indices; a closed primitive's triangles face outwards.

    Raises
    ------
    InvalidInputError
        ``shape`` is none of these.
    """
    if isinstance(shape, Box):
        return _box(shape.size)
    if isinstance(shape, Sphere):
        return _sphere(shape.radius)
    if isinstance(shape, Cylinder):
        return _cylinder(shape.radius, shape.length)
    if isinstance(shape, Capsule):
        parts = [_cylinder(shape.radius, shape.length)]
        parts += [_sphere(shape.radius, z) for z in (-0.5 * shape.length, 0.5 * shape.length)]
        return merge_meshes(*parts)
    if isinstance(shape, Mesh):  # its own triangles
        return np.asarray(shape.vertices, dtype=float), np.asarray(shape.triangles)
    if isinstance(shape, PointCloud):  # drawn as the box of its points (the page stays small)
        points = np.asarray(shape.points, dtype=float)
        lo, hi = points.min(axis=0), points.max(axis=0)
        v, f = _box(hi - lo)
        return v + 0.5 * (lo + hi), f
    raise InvalidInputError(
        f"cannot draw obstacle shape {type(shape).__name__} "
        "(box, sphere, cylinder, capsule, mesh, point cloud)"
    )
