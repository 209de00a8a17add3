r"""Closed-form signed distances of points to the primitive shapes, batched.

:func:`point_signed_distance` gives the exact signed distance [m] (negative inside) of
points to a :class:`~adept_traj.scene.Box`, :class:`~adept_traj.scene.Sphere`,
:class:`~adept_traj.scene.Cylinder` or :class:`~adept_traj.scene.Capsule` in the shape's
own frame; :func:`signed_distance_xyz` is the same with the coordinates as separate arrays,
:func:`obstacle_signed_distance` with the points in the robot base frame and the obstacle
at a (possibly moving) pose. :func:`points_in_joint` maps points fixed in a joint frame to
the base frame at many samples at once. The broad phase bounds solid–obstacle distances
with them (enclosing balls, covering spheres) and computes sphere obstacles exactly; a mesh
or a point cloud gets the signed distance to its bounding box, a lower bound. Each
is a few elementwise numpy operations on whole arrays, exact to rounding (~1e-16 m).
"""

from __future__ import annotations

import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.scene.meshes import Mesh
from adept_traj.scene.point_clouds import PointCloud
from adept_traj.scene.shapes import Box, Capsule, Cylinder, Sphere

__all__ = [
    "obstacle_signed_distance",
    "point_signed_distance",
    "points_in_joint",
    "signed_distance_xyz",
]


def _norm3(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    return np.sqrt(x * x + y * y + z * z)


def point_signed_distance(shape: object, p: np.ndarray) -> np.ndarray:
    """Exact signed distance [m] of points ``p`` (..., 3), in the shape's own frame, to a
    :class:`Box`, :class:`Sphere`, :class:`Cylinder` (axis z) or :class:`Capsule` (axis z);
    negative inside.

    .. math::
        d_\\text{box}(p) = \\lVert \\max(e, 0) \\rVert + \\min(\\max_k e_k, 0),
        \\qquad e = |p| - h

    (h the half sides; the cylinder is the same in the (radial, axial) plane).
    """
    p = np.asarray(p, dtype=float)
    return signed_distance_xyz(shape, p[..., 0], p[..., 1], p[..., 2])


def signed_distance_xyz(shape: object, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """:func:`point_signed_distance` with the coordinates [m] as separate arrays (...)
    (the broad phase keeps points component-major: contiguous, fast elementwise)."""
    if isinstance(shape, Sphere):
        return _norm3(x, y, z) - shape.radius
    if isinstance(shape, Box):
        return _box_distance(shape, x, y, z)
    if isinstance(shape, Cylinder):
        return _cylinder_distance(shape, np.sqrt(x * x + y * y), z)
    if isinstance(shape, Capsule):
        half = 0.5 * shape.length
        dz = z - np.clip(z, -half, half)
        return _norm3(x, y, dz) - shape.radius
    if isinstance(shape, (Mesh, PointCloud)):  # a lower bound: the distance to its box
        lo, hi = shape.local_box
        c, h = 0.5 * (lo + hi), 0.5 * (hi - lo)
        box = _half_box_distance(h.tolist(), x - c[0], y - c[1], z - c[2])
        field = shape.lower_bound(x, y, z) if isinstance(shape, PointCloud) else None
        return box if field is None else np.maximum(box, field)
    raise InvalidInputError(f"no point distance for obstacle shape {type(shape).__name__}")


def _box_distance(shape: Box, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Signed distance [m] of points (x, y, z) (...) in the box's frame; the same
    operations as the formula of :func:`point_signed_distance`, on few temporaries."""
    return _half_box_distance([0.5 * float(v) for v in shape.size], x, y, z)


def _half_box_distance(half: list[float], x: np.ndarray, y: np.ndarray, z: np.ndarray):
    """:func:`_box_distance` of the centred box of half sides ``half`` (3,) [m]."""
    hx, hy, hz = half
    shape_xyz = np.broadcast_shapes(np.shape(x), np.shape(y), np.shape(z))
    ex, ey, ez = (np.abs(v, out=np.empty(shape_xyz)) for v in (x, y, z))
    ex -= hx
    ey -= hy
    ez -= hz
    inside = np.maximum(ex, ey, out=np.empty(shape_xyz))
    np.maximum(inside, ez, out=inside)
    np.minimum(inside, 0.0, out=inside)
    np.maximum(ex, 0.0, out=ex)
    np.maximum(ey, 0.0, out=ey)
    np.maximum(ez, 0.0, out=ez)
    ex *= ex
    ey *= ey
    ez *= ez
    ex += ey
    ex += ez
    outside = np.sqrt(ex, out=ex)
    outside += inside
    return outside[()]  # a scalar for scalar coordinates


def _cylinder_distance(shape: Cylinder, rho: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Signed distance [m] of points at distance ``rho`` (...) [m] from the cylinder's
    axis and ``z`` (...) [m] along it (from its centre)."""
    shape_rz = np.broadcast_shapes(np.shape(rho), np.shape(z))
    radial = np.subtract(rho, shape.radius, out=np.empty(shape_rz))
    axial = np.abs(z, out=np.empty(shape_rz))
    axial -= 0.5 * shape.length
    inside = np.maximum(radial, axial, out=np.empty(shape_rz))
    np.minimum(inside, 0.0, out=inside)
    outside = np.hypot(np.maximum(radial, 0.0, out=radial), np.maximum(axial, 0.0, out=axial))
    outside += inside
    return outside[()]


def _in_obstacle_frame(points: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Points (3, m, R) [m] expressed in the frame of an obstacle at ``pose`` (4, 4) or
    (R, 4, 4): :math:`R_o^\\top (p - t_o)`, component-major."""
    if pose.ndim == 2:  # fixed obstacle: one GEMM
        flat = points.reshape(3, -1) - pose[:3, 3, None]
        return (pose[:3, :3].T @ flat).reshape(points.shape)
    delta = points - _origins(pose)  # (3, m, R)
    rt = np.ascontiguousarray(pose[:, :3, :3].transpose(2, 1, 0))  # rt[i, j] = R[:, j, i]
    out = np.empty_like(delta)
    for i in range(3):
        out[i] = rt[i, 0] * delta[0] + rt[i, 1] * delta[1] + rt[i, 2] * delta[2]
    return out


def _origins(pose: np.ndarray) -> np.ndarray:
    """The origins (3, 1, R) [m] of poses (R, 4, 4), component-major and contiguous (a
    subtraction broadcasting the strided view ``pose[:, :3, 3].T`` is several times
    slower than the copy)."""
    return np.ascontiguousarray(pose[:, :3, 3].T)[:, None]


def obstacle_signed_distance(shape: object, points: np.ndarray, pose: np.ndarray) -> np.ndarray:
    """Exact signed distance (m, R) [m] of points (3, m, R) (base frame, component-major) to
    an obstacle ``shape`` at ``pose`` (4, 4) or (R, 4, 4).

    A moving sphere needs only its centre, a moving cylinder or capsule only its axis
    :math:`a` (the third column of its rotation): with :math:`d = p - t_o`,
    :math:`z = a \\cdot d` and :math:`\\rho = \\sqrt{\\lVert d \\rVert^2 - z^2}`.
    """
    if pose.ndim == 2 or not isinstance(shape, (Sphere, Cylinder, Capsule)):
        return signed_distance_xyz(shape, *_in_obstacle_frame(points, pose))
    delta = points - _origins(pose)  # (3, m, R)
    sq = _dot3(delta, delta)
    if isinstance(shape, Sphere):
        sq = np.sqrt(sq, out=sq)
        sq -= shape.radius
        return sq
    z = _dot3(np.ascontiguousarray(pose[:, :3, 2].T)[:, None], delta)  # axis (3, 1, R)
    rho = np.subtract(sq, np.multiply(z, z), out=sq)
    rho = np.sqrt(np.maximum(rho, 0.0, out=rho), out=rho)
    if isinstance(shape, Cylinder):  # sqrt(rho² + 0²) is rho exactly: skip it
        return _cylinder_distance(shape, rho, z)
    return signed_distance_xyz(shape, rho, np.zeros_like(rho), z)


def points_in_joint(
    frames: np.ndarray, points: np.ndarray, out: np.ndarray | None = None
) -> np.ndarray:
    """Points (3, m, R) [m] in the base frame, component-major with the samples innermost,
    for joint frames ``frames`` (12, R) (rows: the 3 × 4 top of each pose, row-major) and
    points (m, 3) fixed in the joint frame; written into ``out`` (3, m, R) if given."""
    f = frames.reshape(3, 4, -1)  # (row i, column j, R)
    if out is None:
        out = np.empty((3, len(points), f.shape[-1]))
    px, py, pz = (points[:, j, None] for j in range(3))
    term = np.empty(out.shape[1:])
    for i in range(3):  # px f_i0 + py f_i1 + pz f_i2 + f_i3, in that order, in place
        np.multiply(px, f[i, 0], out=out[i])
        out[i] += np.multiply(py, f[i, 1], out=term)
        out[i] += np.multiply(pz, f[i, 2], out=term)
        out[i] += f[i, 3]
    return out


def _dot3(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """:math:`a_0 b_0 + a_1 b_1 + a_2 b_2` (summed in that order) of component-major
    arrays (3, ...), into one new array."""
    out = np.multiply(a[0], b[0])
    term = np.multiply(a[1], b[1])
    out += term
    out += np.multiply(a[2], b[2], out=term)
    return out
