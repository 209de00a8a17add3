r"""Capsules around solids and the distance between two segments, batched.

A capsule is a segment :math:`[p_0, p_1]` [m] and a radius :math:`r` [m]: the points
within :math:`r` of the segment. :func:`enclosing_capsule` puts one around a geometry's
local bounding box (the segment along its longest side, the radius the half-diagonal of
its cross-section), so the distance between two solids is at least

.. math::
    d(A, B) \ge \operatorname{dist}([a_0, a_1], [b_0, b_1]) - r_A - r_B,

tighter than the enclosing balls for the long links of an arm (used by
:class:`~adept_traj.collision.SelfCollision`). :func:`segment_distance` is the closed form
of Ericson, *Real-Time Collision Detection* (2005), §5.1.9, on (3, R) arrays.
"""

from __future__ import annotations

import coal
import numpy as np

__all__ = ["enclosing_capsule", "segment_distance"]


def enclosing_capsule(geometry: coal.CollisionGeometry) -> tuple[np.ndarray, np.ndarray, float]:
    """Ends (3,), (3,) [m] in the geometry frame and radius [m] of a capsule containing the
    geometry's local bounding box."""
    geometry.computeLocalAABB()
    lo, hi = np.array(geometry.aabb_local.min_), np.array(geometry.aabb_local.max_)
    extent, centre = hi - lo, 0.5 * (lo + hi)
    axis = int(np.argmax(extent))
    half = np.zeros(3)
    half[axis] = 0.5 * extent[axis]
    radius = 0.5 * float(np.linalg.norm(np.delete(extent, axis)))
    return centre - half, centre + half, radius


def segment_distance(a0: np.ndarray, a1: np.ndarray, b0: np.ndarray, b1: np.ndarray) -> np.ndarray:
    """Distances (R,) [m] between the segments ``[a0, a1]`` and ``[b0, b1]``, each end
    (3, R) [m] (component-major)."""
    d1, d2, r = a1 - a0, b1 - b0, a0 - b0
    a = np.maximum((d1 * d1).sum(axis=0), 1e-30)
    e = np.maximum((d2 * d2).sum(axis=0), 1e-30)
    b, c, f = (d1 * d2).sum(axis=0), (d1 * r).sum(axis=0), (d2 * r).sum(axis=0)
    denom = a * e - b * b
    safe = np.where(denom > 1e-12 * a * e, denom, 1.0)
    s = np.where(denom > 1e-12 * a * e, np.clip((b * f - c * e) / safe, 0.0, 1.0), 0.0)
    t = (b * s + f) / e
    s = np.where(
        t < 0.0, np.clip(-c / a, 0.0, 1.0), np.where(t > 1.0, np.clip((b - c) / a, 0.0, 1.0), s)
    )
    t = np.clip(t, 0.0, 1.0)
    gap = r + d1 * s - d2 * t
    return np.sqrt((gap * gap).sum(axis=0))
