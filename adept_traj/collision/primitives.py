r"""The coal primitives of the robot solids and obstacles, and how coal measures them.

Their kind and dimensions (:func:`coal_kind`), the matching :mod:`adept_traj.scene.shapes`
object (:func:`shape_of`), the ball enclosing a geometry and the spheres covering it (from
its local bounding box), the half-length of a primitive's projection on a direction (for
the separating-axis bound), and the coal request every distance call of the package uses
(:func:`distance_request`).

What "exact" means for a coal distance
--------------------------------------
coal computes a separation distance by GJK and a penetration depth by EPA, each to a
tolerance, 1e-6 by default, which leaves curved pairs (a cylinder against a box face) up
to 0.7 µm too large. :func:`distance_request` sets the GJK tolerance to
:data:`DISTANCE_TOLERANCE` (1e-9) and leaves EPA at its default: with an EPA tolerance of
1e-9, coal 3.0.3 returns wrong depths (−0.2345 m instead of −0.1102 m for a cylinder
deep in a cylinder: ``test_broad_phase_is_sound_for_every_shape_kind`` fails with it),
and no tolerance makes EPA more accurate than about 3 µm on curved pairs. Measured
against the closed-form distance of a cylinder to a box face (6 000 random poses for each
cylinder of the AdeptOne XL and the pendulum rod, distances from −1 cm to 5 cm), the error
:math:`e = d_\text{coal} - d` [m] is

========================  =====================  ==========================
true distance :math:`d`   coal's default         :func:`distance_request`
========================  =====================  ==========================
1 mm … 5 cm               0 ≤ e ≤ 0.74 µm        0 ≤ e ≤ 2 nm
10 µm … 1 mm              0 ≤ e ≤ 0.85 µm        0 ≤ e ≤ 70 nm
0 … 10 µm                 −1.0 µm ≤ e ≤ 1.2 µm   0 ≤ e ≤ 0.8 µm
penetration (d < 0)       0 ≤ e ≤ 3.0 µm         0 ≤ e ≤ 3.4 µm
========================  =====================  ==========================

so a distance is never understated and, at the safety margins that matter (≥ 1 mm),
within 2 nm. Capsules, spheres and boxes against a box face come out to rounding
(~1e-15 m). The cost was measured within the noise of the shared machine, both for
``evaluate_batch`` and for :func:`~adept_traj.certification.certificate.certify`
(``benchmarks/results/notebook.md``).
"""

from __future__ import annotations

import coal
import numpy as np

from adept_traj.scene.shapes import Box, Capsule, Cylinder, Sphere

__all__ = [
    "DISTANCE_TOLERANCE",
    "coal_kind",
    "covering_spheres",
    "distance_request",
    "enclosing_ball",
    "half_extent",
    "shape_of",
]

#: GJK tolerance of every coal distance call (coal's default: 1e-6); EPA keeps its default.
DISTANCE_TOLERANCE = 1e-9


def distance_request() -> coal.DistanceRequest:
    """A new coal distance request with the GJK tolerance :data:`DISTANCE_TOLERANCE` and
    EPA at its default (see the module docstring for the resulting accuracy)."""
    request = coal.DistanceRequest()
    request.gjk_tolerance = DISTANCE_TOLERANCE
    return request


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
