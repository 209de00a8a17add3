"""Meshcat objects for the solids of a playback: obstacle shapes, robot solids (coal
primitives or mesh files) and their placement in the solid's frame.

A meshcat (three.js) cylinder has its axis along local y; coal's and the scene's along
local z. Every cylinder is therefore placed by a quarter turn about x (:data:`Y_TO_Z`);
a capsule is a cylinder and two spheres.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import coal
import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.scene import (
    Box,
    Capsule,
    Cylinder,
    Mesh,
    PointCloud,
    Scene,
    Shape,
    Sphere,
)
from adept_traj.viz.meshcat_modules import mg

__all__ = [
    "MAX_DRAWN_POINTS",
    "Y_TO_Z",
    "Part",
    "hex_colour",
    "pendulum_pivots",
    "rotations_y_to",
    "shape_parts",
    "solid_parts",
    "translation",
]

#: Most points of a point-cloud obstacle drawn (an evenly strided subset beyond: the page
#: stays small); the planner uses every point.
MAX_DRAWN_POINTS = 100_000
_PIVOT_RADIUS = 0.025  # pendulum pivot ball [m]
_AXLE_RADIUS, _AXLE_LENGTH = 0.008, 0.14  # pendulum axle along the swing normal [m]

#: (4, 4) turns a meshcat cylinder, axis along local y, onto coal's z axis (90° about x).
Y_TO_Z = np.array([[1.0, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]])
Y_TO_Z.flags.writeable = False


@dataclass(frozen=True, eq=False)
class Part:
    """One drawable of a :class:`~adept_traj.viz.playback.SceneObject`.

    Attributes
    ----------
    obj: the meshcat object (``meshcat.geometry.Mesh`` or ``Line``).
    local: (4, 4) its placement in the object's frame [m] (e.g. :data:`Y_TO_Z` for a
        cylinder).
    """

    obj: mg.Object
    local: np.ndarray


def hex_colour(rgb: Any) -> int:
    """``0xRRGGBB`` of an (r, g, b) colour in [0, 1] (values outside are clipped)."""
    r, g, b = (round(255 * min(max(float(c), 0.0), 1.0)) for c in rgb)
    return (r << 16) | (g << 8) | b


def translation(p: Any) -> np.ndarray:
    """(4, 4) pure translation by ``p`` (3,) [m]."""
    m = np.eye(4)
    m[:3, 3] = p
    return m


def _cylinder(radius: float, length: float, material: mg.Material) -> Part:
    return Part(mg.Mesh(mg.Cylinder(length, radius), material), Y_TO_Z.copy())


def _capsule(radius: float, length: float, material: mg.Material) -> tuple[Part, ...]:
    caps = tuple(
        Part(mg.Mesh(mg.Sphere(radius), material), translation([0.0, 0.0, z]))
        for z in (-0.5 * length, 0.5 * length)
    )
    return (_cylinder(radius, length, material), *caps)


def shape_parts(shape: Shape, material: mg.Material) -> tuple[Part, ...]:
    """Meshcat parts of an obstacle shape (centred, axis along local z; sizes [m])."""
    if isinstance(shape, Box):
        return (Part(mg.Mesh(mg.Box([float(s) for s in shape.size]), material), np.eye(4)),)
    if isinstance(shape, Sphere):
        return (Part(mg.Mesh(mg.Sphere(shape.radius), material), np.eye(4)),)
    if isinstance(shape, Cylinder):
        return (_cylinder(shape.radius, shape.length, material),)
    if isinstance(shape, Capsule):
        return _capsule(shape.radius, shape.length, material)
    if isinstance(shape, Mesh):  # its triangles, in the mesh frame
        geometry = mg.TriangularMeshGeometry(np.array(shape.vertices), np.array(shape.triangles))
        return (Part(mg.Mesh(geometry, material), np.eye(4)),)
    if isinstance(shape, PointCloud):
        step = max(1, -(-shape.n_points // MAX_DRAWN_POINTS))
        points = np.array(shape.points[::step].T, dtype=np.float32)
        colour = np.tile(np.array([[0.55], [0.45], [0.35]], dtype=np.float32), points.shape[1])
        cloud = mg.PointCloud(points, colour, size=shape.resolution)
        return (Part(cloud, np.eye(4)),)
    raise InvalidInputError(
        f"cannot draw obstacle shape {type(shape).__name__} (box, sphere, cylinder, capsule, "
        "mesh, point cloud)"
    )


_MESH_LOADERS = {
    ".stl": mg.StlMeshGeometry,
    ".obj": mg.ObjMeshGeometry,
    ".dae": mg.DaeMeshGeometry,
}


def solid_parts(gobj: Any, material: mg.Material) -> tuple[Part, ...]:
    """Meshcat parts of a robot solid (a ``pinocchio.GeometryObject``: a coal geometry in
    the solid's frame, or a mesh file scaled by its ``meshScale``).

    Raises
    ------
    InvalidInputError
        A geometry meshcat cannot draw (supported: box, sphere, cylinder, capsule, cone,
        ellipsoid, .stl/.obj/.dae mesh).
    """
    geometry, name = gobj.geometry, gobj.name
    if isinstance(geometry, coal.Box):
        lengths = [2.0 * float(h) for h in geometry.halfSide]
        return (Part(mg.Mesh(mg.Box(lengths), material), np.eye(4)),)
    if isinstance(geometry, coal.Sphere):
        return (Part(mg.Mesh(mg.Sphere(float(geometry.radius)), material), np.eye(4)),)
    if isinstance(geometry, coal.Cylinder):
        return (_cylinder(float(geometry.radius), 2.0 * float(geometry.halfLength), material),)
    if isinstance(geometry, coal.Capsule):
        return _capsule(float(geometry.radius), 2.0 * float(geometry.halfLength), material)
    if isinstance(geometry, coal.Cone):  # base at z = -h/2, apex at +h/2 (three.js: +y)
        height, radius = 2.0 * float(geometry.halfLength), float(geometry.radius)
        cone = mg.Cylinder(height, radiusTop=0.0, radiusBottom=radius)
        return (Part(mg.Mesh(cone, material), Y_TO_Z.copy()),)
    if isinstance(geometry, coal.Ellipsoid):
        return (Part(mg.Mesh(mg.Ellipsoid(list(geometry.radii)), material), np.eye(4)),)
    mesh_path = str(getattr(gobj, "meshPath", "") or "")
    path = Path(mesh_path) if mesh_path else None
    loader = _MESH_LOADERS.get(path.suffix.lower()) if path is not None else None
    if path is not None and loader is not None and path.is_file():
        scale = np.diag([*np.asarray(gobj.meshScale, dtype=float), 1.0])
        return (Part(mg.Mesh(loader.from_file(str(path)), material), scale),)
    raise InvalidInputError(
        f"robot solid {name!r}: cannot draw a {type(geometry).__name__} "
        "(supported: box, sphere, cylinder, capsule, cone, ellipsoid, .stl/.obj/.dae mesh)"
    )


def pendulum_pivots(scene: Scene, color: int) -> list[tuple[str, tuple[Part, ...], np.ndarray]]:
    """The pivot of each pendulum of ``scene`` (:attr:`~adept_traj.scene.Scene.pendulums`)
    as (node path, parts, (4, 4) world pose) of a fixed node ``pivots/NAME`` (NAME: the
    pendulum's name): a ball at the pivot and an axle along the swing plane's normal
    ``e_n``, the axis the pendulum turns about, in ``color`` (0xRRGGBB). The node's frame:
    origin at the pivot, axes (e_swing, e_n, e_z)."""
    material = mg.MeshLambertMaterial(color=color)
    ball = Part(mg.Mesh(mg.Sphere(_PIVOT_RADIUS), material), np.eye(4))
    axle = Part(mg.Mesh(mg.Cylinder(_AXLE_LENGTH, _AXLE_RADIUS), material), np.eye(4))  # along y
    nodes = []
    for name, motion in scene.pendulums.items():
        pose = np.eye(4)
        pose[:3, 0], pose[:3, 1], pose[:3, 2] = motion.swing_axis, motion.normal_axis, (0, 0, 1)
        pose[:3, 3] = motion.pivot
        nodes.append((f"pivots/{name}", (ball, axle), pose))
    return nodes


def rotations_y_to(u: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotations taking the y axis (that of meshcat's cylinders) onto the unit
    vectors ``u`` (n, 3) (Rodrigues; a half turn about x for ``u = -y``)."""
    c = u[:, 1]  # y · u
    v = np.stack([u[:, 2], np.zeros_like(c), -u[:, 0]], axis=-1)  # y × u
    vx = np.zeros((len(u), 3, 3))
    vx[:, 0, 1], vx[:, 0, 2] = -v[:, 2], v[:, 1]
    vx[:, 1, 0], vx[:, 1, 2] = v[:, 2], -v[:, 0]
    vx[:, 2, 0], vx[:, 2, 1] = -v[:, 1], v[:, 0]
    flip = c < -1.0 + 1e-12
    scale = 1.0 / np.where(flip, 1.0, 1.0 + c)
    out = np.eye(3) + vx + (vx @ vx) * scale[:, None, None]
    out[flip] = np.diag([1.0, -1.0, -1.0])
    return out
