"""The obstacle shapes as triangle meshes (adept_traj.scene.triangulation), against closed
forms: the volume of a box and of a regular-polygon prism by the divergence theorem, every
vertex on the true surface, the triangles facing outwards, every edge shared by two
triangles in opposite directions."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest

from adept_traj.errors import InvalidInputError
from adept_traj.scene import (
    Box,
    Capsule,
    Cylinder,
    Mesh,
    PointCloud,
    Sphere,
    shape_triangles,
)
from adept_traj.scene.triangulation import RINGS, SEGMENTS


def _volume(v: np.ndarray, f: np.ndarray) -> float:
    """Signed volume of a closed triangle mesh: the sum of the tetrahedra (0, a, b, c)."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def _edges_paired(v: np.ndarray, f: np.ndarray) -> bool:
    """Every directed edge of the triangles of non-zero area (points joined by coordinates)
    is traversed once, and its reverse once: a closed, consistently oriented surface."""
    key = {tuple(p): i for i, p in enumerate(np.round(v, 12).tolist())}
    ids = np.array([key[tuple(p)] for p in np.round(v, 12).tolist()])
    edges = Counter()
    for tri in ids[f]:
        if len(set(tri)) < 3:  # a zero-area triangle at a sphere's pole
            continue
        for i, j in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            edges[(i, j)] += 1
    return all(n == 1 and edges.get((j, i)) == 1 for (i, j), n in edges.items())


def _outward(v: np.ndarray, f: np.ndarray, centre: np.ndarray) -> bool:
    """Every triangle of non-zero area has its normal pointing away from ``centre``."""
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    normal = np.cross(b - a, c - a)
    area = np.linalg.norm(normal, axis=1)
    keep = area > 1e-12
    towards = np.einsum("ij,ij->i", normal, (a + b + c) / 3.0 - centre)
    return bool(keep.any() and (towards[keep] > 0).all())


def test_box_has_its_volume_and_faces_outwards() -> None:
    v, f = shape_triangles(Box(size=(0.1, 0.2, 0.3)))
    assert v.shape == (8, 3)
    assert f.shape == (12, 3)
    assert np.allclose(np.abs(v), [0.05, 0.1, 0.15])
    assert _volume(v, f) == pytest.approx(0.1 * 0.2 * 0.3, rel=1e-12)
    assert _edges_paired(v, f)
    assert _outward(v, f, np.zeros(3))


def test_cylinder_is_the_regular_prism_inscribed() -> None:
    r, length = 0.04, 0.3
    v, f = shape_triangles(Cylinder(radius=r, length=length))
    ring = v[np.abs(np.hypot(v[:, 0], v[:, 1])) > 1e-12]
    assert len(ring) == 2 * SEGMENTS
    assert np.allclose(np.hypot(ring[:, 0], ring[:, 1]), r)
    assert np.allclose(np.abs(v[:, 2]), length / 2)
    prism = 0.5 * SEGMENTS * r**2 * math.sin(2 * math.pi / SEGMENTS) * length
    assert _volume(v, f) == pytest.approx(prism, rel=1e-12)
    assert _edges_paired(v, f)
    assert _outward(v, f, np.zeros(3))


def test_sphere_vertices_lie_on_it_and_its_volume_is_inside() -> None:
    r = 0.05
    v, f = shape_triangles(Sphere(radius=r))
    assert len(v) == (RINGS + 1) * SEGMENTS
    assert np.allclose(np.linalg.norm(v, axis=1), r)
    volume = _volume(v, f)
    assert 0.9 * (4 / 3) * math.pi * r**3 < volume < (4 / 3) * math.pi * r**3
    assert _edges_paired(v, f)
    assert _outward(v, f, np.zeros(3))


def test_capsule_is_a_cylinder_and_two_spheres() -> None:
    r, length = 0.02, 0.2
    v, f = shape_triangles(Capsule(radius=r, length=length))
    cyl_v, cyl_f = shape_triangles(Cylinder(radius=r, length=length))
    sph_v, sph_f = shape_triangles(Sphere(radius=r))
    assert len(v) == len(cyl_v) + 2 * len(sph_v)
    assert len(f) == len(cyl_f) + 2 * len(sph_f)
    # every vertex on or inside the capsule (the parts overlap: no boolean union), the
    # outer half of each end sphere on its surface
    z = np.clip(v[:, 2], -length / 2, length / 2)
    distance = np.linalg.norm(v - np.column_stack([0 * z, 0 * z, z]), axis=1)
    assert (distance <= r + 1e-12).all()
    outer = np.abs(v[:, 2]) >= length / 2 + 1e-9
    assert outer.sum() == 2 * (RINGS // 2) * SEGMENTS
    assert np.allclose(distance[outer], r)


def test_mesh_is_its_own_triangles_and_a_cloud_the_box_of_its_points() -> None:
    verts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    tris = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    v, f = shape_triangles(Mesh(verts, tris))
    assert np.array_equal(v, verts)
    assert np.array_equal(f, tris)
    points = np.array([[0.1, 0.2, 0.3], [0.5, -0.2, 0.4], [0.3, 0.0, 0.9]])
    v, f = shape_triangles(PointCloud(points, 0.05))
    assert np.allclose(v.min(axis=0), points.min(axis=0))
    assert np.allclose(v.max(axis=0), points.max(axis=0))
    assert _volume(v, f) == pytest.approx(float(np.prod(np.ptp(points, axis=0))), rel=1e-12)


def test_another_object_is_refused_by_name() -> None:
    with pytest.raises(InvalidInputError, match="cannot draw obstacle shape str"):
        shape_triangles("box")
