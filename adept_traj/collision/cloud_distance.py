r"""Distances of a primitive robot solid to a point cloud's octree, found best-first.

coal's octree distance visits every leaf whose box is nearer the solid's axis-aligned
bounding box than the best distance found so far, in a fixed child order; a long link
beside a dense scan (a fence) meets thousands of leaves in that box (``docs/scene-files.md``
has the figures). :class:`CloudDistance` computes **the same quantity** — the
smallest of coal's distances between the solid and the octree's occupied leaves
(``OcTree.toBoxes``: axis-aligned cubes in the cloud frame) — with few coal calls, by a
best-first search over *buckets* of leaves (a grid of :data:`BUCKETBUCKET_EDGE` leaves a side)
and the leaves themselves, ordered by a lower bound.

The bound: the signed distance :math:`\varphi` of the solid (a box, cylinder, capsule or
sphere; closed form in its frame) is **convex** (that of a convex set), so over an
axis-aligned box :math:`B` of centre :math:`c` and half sides :math:`e` (cloud frame),
with :math:`g` a subgradient of :math:`\varphi` at :math:`c`,

.. math::
    \min_{x \in B} \varphi(x) \;\ge\; \varphi(c) - \sum_k |g_k|\, e_k =: \ell(B)

(exact for a face-to-face contact). When the solid and a leaf are apart, their distance is
:math:`\min_B \varphi \ge \ell`; when they overlap, :math:`\ell < 0`. A bucket's
:math:`\ell`, of the box around its leaves, bounds each of its leaves': the buckets above
``cap`` are left out, the leaves of the others get their :math:`\ell` in one batch, and
those within ``cap`` are computed by coal in increasing order of :math:`\ell` until the
next bound is at least the best value :math:`v` so far (less :data:`TIE`; the value returned is then
:math:`\min(v, \ell_\text{next})`, never above the minimum over the leaves), or :math:`v`
is negative (a penetration: the depth of that leaf, one leaf's as coal's octree reports).

Only the buckets near the solid are searched: those whose grid cell meets the solid's box
grown by ``cap`` + :data:`FAR_MARGIN` + the largest leaf half edge; every other leaf is
farther than ``cap`` + :data:`FAR_MARGIN`. So a distance at most ``cap`` (the checker's
``influence``) is exact; a larger one is returned as a lower bound above ``cap``, as the
broad phase's bounds are (:class:`~adept_traj.collision.CollisionChecker`). A URDF
link's convex hull (``ConvexBase``) takes the same path, with the largest of its face
planes' signed distances as :math:`\varphi` (convex, never above its signed distance, so
:math:`\ell` is still a lower bound; the leaves' distances are still coal's); solids of
another kind (a triangle mesh) keep coal's octree distance.

:meth:`CloudCells.point_bound` is the broad phase's bound of a point's distance to the
leaves (level 5 of :mod:`adept_traj.collision.broad_phase`).
"""

from __future__ import annotations

from functools import cached_property, reduce
from typing import Any

import coal
import numpy as np

from adept_traj.scene.point_clouds import PointCloud, cube_field_step
from adept_traj.validation import DerivedData

__all__ = [
    "BUCKET_EDGE",
    "FAR_MARGIN",
    "TIE",
    "CloudCells",
    "CloudDistance",
    "cloud_cells",
    "hull_planes",
    "solid_distance_bound",
    "solid_half_sides",
    "supports_distance_bound",
]

#: Margin [m] beyond the cap of the leaves not gathered (their distance exceeds cap + it).
FAR_MARGIN = 1e-3

#: A leaf whose lower bound is within this [m] of the best value is not computed.
TIE = 1e-9

#: Edge of a bucket [edges of the largest leaf].
BUCKET_EDGE = 8.0


class CloudCells(DerivedData):
    """The occupied leaves of a coal ``OcTree`` grouped in buckets, in the cloud frame.

    Attributes
    ----------
    centre, half: (k, 3) leaf centres and (k,) half edges [m], sorted by bucket.
    start: (b + 1,) the leaves of bucket i are ``start[i]:start[i + 1]``.
    box_centre, box_half: (b, 3) centre and half sides [m] of each bucket's box (the
        smallest axis-aligned box holding its leaves).
    """

    def __init__(self, octree: coal.OcTree) -> None:
        boxes = np.asarray(octree.toBoxes(), dtype=float).reshape(-1, 6)
        centre, half = boxes[:, :3], 0.5 * boxes[:, 3]
        k = len(centre)
        lo = (centre - half[:, None]).min(axis=0)
        edge = BUCKET_EDGE * 2.0 * float(half.max())  # buckets of BUCKETBUCKET_EDGE leaves a side
        key = np.floor((centre - lo) / edge).astype(np.int64)
        dims = key.max(axis=0) + 1
        flat = (key[:, 0] * dims[1] + key[:, 1]) * dims[2] + key[:, 2]
        order = np.argsort(flat, kind="stable")
        flat = flat[order]
        self.centre = np.ascontiguousarray(centre[order])
        self.half = np.ascontiguousarray(half[order])
        cut = np.flatnonzero(np.diff(flat)) + 1
        #: the grid of buckets: origin (3,) [m], edge [m], cells per axis (3,), the flat
        #: key of each bucket (b,) (sorted), the largest leaf half edge [m]
        self.origin, self.edge, self.dims = lo, edge, dims
        self.keys = flat[np.concatenate([[0], cut])]
        self.hmax = float(half.max())
        self.start = np.concatenate([[0], cut, [k]]).astype(np.int64)
        low = np.minimum.reduceat(self.centre - self.half[:, None], self.start[:-1], axis=0)
        high = np.maximum.reduceat(self.centre + self.half[:, None], self.start[:-1], axis=0)
        self.box_centre = 0.5 * (low + high)
        self.box_half = 0.5 * (high - low)
        self._mid, self._spread = (
            0.5 * (low.min(axis=0) + high.max(axis=0)),
            0.5 * (high.max(axis=0) - low.min(axis=0)),
        )
        #: one coal box per leaf size (a few: pruned octree nodes are larger)
        self.sizes = {h: coal.Box(2 * h, 2 * h, 2 * h) for h in np.unique(self.half).tolist()}

    def point_bound(self, p: np.ndarray) -> np.ndarray:
        r"""Lower bounds (...) [m] of the distance of points ``p`` (..., 3) (cloud frame) to
        every leaf: the distance between the cube of the field grid holding the point and
        the nearest cube holding a leaf (``field``: cubes of edge ``h``, a power of 2 times
        the leaf edge, aligned with the octree's grid, so that every leaf fills whole
        cubes; that distance is the Euclidean distance transform of the occupied cubes
        dilated by one cube); outside the grid, that of its nearest grid point less the
        distance to it, or the distance to the leaves' box, the larger."""
        origin, h, field = self.field
        dims = field.shape
        cell = (p - origin) * (1.0 / h)  # grid coordinates (cubes of edge 1)
        grid = np.clip(cell, 0.0, np.array(dims) - 1e-9)  # the nearest point of the grid
        idx = grid.astype(np.int64)  # (≥ 0: the truncation is the floor)
        flat = (idx[..., 0] * dims[1] + idx[..., 1]) * dims[2] + idx[..., 2]
        value = field.ravel()[flat].astype(float) - 1e-6  # float32 rounding
        off = cell - grid
        out = np.einsum("...i,...i->...", off, off)
        away = out > 0.0  # outside the grid (rare): less the distance to it, or the box's
        if away.any():
            q = p[away]
            box = np.linalg.norm(np.maximum(np.abs(q - self._mid) - self._spread, 0.0), axis=-1)
            value[away] = np.maximum(value[away] - h * np.sqrt(out[away]), box - 1e-9)
        return value

    @cached_property
    def field(self) -> tuple[np.ndarray, float, np.ndarray]:
        """``(origin (3,), h, D (nx, ny, nz) float32)`` of :meth:`point_bound` (made on
        first use)."""
        from scipy.ndimage import binary_dilation, distance_transform_edt

        leaf = 2.0 * float(self.half.min())
        lo = self.centre.min(axis=0) - self.half.max()
        hi = self.centre.max(axis=0) + self.half.max()
        h, _ = cube_field_step(lo, hi, leaf)  # counted in the memory budget (point_clouds)
        origin = np.floor(lo / h) * h - h  # a multiple of h (leaves sit at multiples of
        dims = (np.ceil((hi - origin) / h) + 1).astype(np.int64)  # their edge), one spare
        occupied = np.zeros(tuple(dims.tolist()), dtype=bool)
        for half in np.unique(self.half).tolist():  # a leaf larger than h fills cubes
            sel = self.half == half
            n = max(1, round(2.0 * half / h))
            first = np.floor((self.centre[sel] - half - origin) / h + 0.5).astype(np.int64)
            if 2.0 * half <= h:  # the cube holding the leaf's centre holds the leaf
                first = np.floor((self.centre[sel] - origin) / h).astype(np.int64)
            for i, j, k in np.ndindex(n, n, n):
                occupied[first[:, 0] + i, first[:, 1] + j, first[:, 2] + k] = True
        grown = binary_dilation(occupied, np.ones((3, 3, 3), dtype=bool))
        distance = (distance_transform_edt(~grown) * h).astype(np.float32)
        return origin, h, distance


def cloud_cells(octree: coal.OcTree, cloud: PointCloud) -> CloudCells:
    """The :class:`CloudCells` of ``octree`` (``cloud``'s), made once per cloud and kept on
    it (:meth:`~adept_traj.scene.PointCloud.derived`)."""
    return cloud.derived("collision.cloud_distance.cells", lambda _: CloudCells(octree))


def supports_distance_bound(solid: coal.CollisionGeometry) -> bool:
    """Whether :func:`solid_distance_bound` bounds the distance to ``solid``."""
    return isinstance(solid, (coal.ConvexBase, coal.Sphere, coal.Capsule, coal.Box, coal.Cylinder))


def solid_distance_bound(
    solid: coal.CollisionGeometry, p: np.ndarray, planes: np.ndarray | None = None
) -> tuple[Any, Any] | None:
    r"""Signed distance (n,) [m] of points ``p`` (n, 3) in the frame of a coal ``Box``,
    ``Cylinder`` (axis z), ``Capsule`` (axis z) or ``Sphere``, and a subgradient (n, 3)
    of it (unit where the distance is positive); for a convex polytope (``ConvexBase``:
    a URDF link's hull) a convex function never above its signed distance,
    :math:`\max_i (n_i \cdot x - b_i)` over its face planes (exact inside; outside, the
    distance to the farthest supporting half-space), with the unit normal of that face
    as subgradient (``planes``: its :func:`hull_planes`, computed here if ``None``); None
    for another geometry."""
    if isinstance(solid, coal.ConvexBase):
        planes = hull_planes(solid) if planes is None else planes
        side = p @ planes[:, :3].T + planes[:, 3]  # (n, faces)
        face = side.argmax(axis=1)
        return side[np.arange(len(p)), face], planes[face, :3]
    if isinstance(solid, coal.Sphere):
        n = np.linalg.norm(p, axis=1)
        g = p / np.where(n > 0, n, 1.0)[:, None]
        g[n == 0] = (0.0, 0.0, 1.0)
        return n - solid.radius, g
    if isinstance(solid, coal.Capsule):
        axis = np.zeros_like(p)
        axis[:, 2] = np.clip(p[:, 2], -solid.halfLength, solid.halfLength)
        d = p - axis
        n = np.linalg.norm(d, axis=1)
        g = d / np.where(n > 0, n, 1.0)[:, None]
        g[n == 0] = (1.0, 0.0, 0.0)
        return n - solid.radius, g
    if isinstance(solid, coal.Box):
        return _box_sdf(p, np.asarray(solid.halfSide, dtype=float))
    if isinstance(solid, coal.Cylinder):
        rho = np.hypot(p[:, 0], p[:, 1])
        planar = np.column_stack([rho, p[:, 2]])
        d, g2 = _box_sdf(planar, np.array([solid.radius, solid.halfLength]), signed_axes=(1,))
        radial = np.column_stack([p[:, 0], p[:, 1]]) / np.where(rho > 0, rho, 1.0)[:, None]
        radial[rho == 0] = (1.0, 0.0)
        return d, np.column_stack([radial * g2[:, :1], g2[:, 1]])
    return None


def solid_half_sides(solid: coal.CollisionGeometry) -> np.ndarray | None:
    """Half sides (3,) [m] of the box about the origin holding a primitive solid (a coal
    ``Box``, ``Cylinder``, ``Capsule`` or ``Sphere``) or a convex polytope (its vertices'
    largest coordinates); None for another geometry."""
    if isinstance(solid, coal.Sphere):
        return np.full(3, solid.radius)
    if isinstance(solid, coal.ConvexBase):
        return np.abs(np.asarray(solid.points(), dtype=float)).max(axis=0)
    if isinstance(solid, coal.Box):
        return np.asarray(solid.halfSide, dtype=float).copy()
    if not isinstance(solid, (coal.Cylinder, coal.Capsule)):
        return None
    tip = solid.halfLength + (solid.radius if isinstance(solid, coal.Capsule) else 0.0)
    return np.array([solid.radius, solid.radius, tip])


def hull_planes(solid: coal.ConvexBase) -> np.ndarray:
    """The face planes (f, 4) of a convex polytope, ``(n, -b)`` with unit outward normals
    ``n`` (f, 3) and offsets ``b`` [m] (``n · x ≤ b`` inside; qhull through scipy)."""
    from scipy.spatial import ConvexHull

    equations = ConvexHull(np.asarray(solid.points(), dtype=float)).equations
    return np.ascontiguousarray(equations)


def _box_sdf(p: np.ndarray, h: np.ndarray, signed_axes: tuple[int, ...] | None = None):
    """Signed distance and subgradient of the box of half sides ``h`` at points ``p``
    (n, len(h)); for the cylinder's (radial ≥ 0, axial) plane only the axial sign matters."""
    q = np.abs(p) - h
    out = np.maximum(q, 0.0)
    n = np.sqrt(np.einsum("ij,ij->i", out, out))
    inner = reduce(np.maximum, q.T)  # column by column (faster than q.max(1))
    d = n + np.minimum(inner, 0.0)
    g = out / np.where(n > 0, n, 1.0)[:, None]  # (0 inside)
    inside = n == 0
    if inside.any():
        k = q[inside].argmax(axis=1)
        g[np.flatnonzero(inside), k] = 1.0
    return d, np.copysign(g, p)


class CloudDistance:
    """The distance of a primitive robot solid and a point cloud's octree (``key``: the
    :class:`~adept_traj.scene.PointCloud`), exact up to ``cap`` [m] (module docstring), as
    a coal functor ``(tf_solid, tf_cloud, request, result) -> distance`` [m]; ``result``
    then holds coal's witness points and normal of the nearest leaf (not above ``cap``)."""

    def __init__(
        self, solid: coal.CollisionGeometry, octree: coal.OcTree, key: PointCloud, cap: float
    ) -> None:
        self._solid = solid
        #: Distances above this [m] are returned as a lower bound above it.
        self.cap = float(cap)
        self._octree = octree  # coal's functors keep raw pointers: keep the objects alive
        self.cells = cloud_cells(octree, key)
        self._functors = {
            h: coal.ComputeDistance(solid, box) for h, box in self.cells.sizes.items()
        }
        self._half_local = solid_half_sides(solid)
        #: a convex polytope's box (centre (3,), half sides (3,)) [m], its frame: a cheap
        #: first bound of the leaves before the one over its faces
        self._hull_box = self._planes = None
        if isinstance(solid, coal.ConvexBase):
            self._planes = hull_planes(solid)
            v = np.asarray(solid.points(), dtype=float)
            self._hull_box = (0.5 * (v.min(0) + v.max(0)), 0.5 * (v.max(0) - v.min(0)))
        self._scratch = coal.DistanceResult()
        self._tf_leaf = coal.Transform3s()
        #: coal calls made by the last evaluation.
        self.last_calls = 0

    @property
    def solid(self) -> coal.CollisionGeometry:
        """The robot solid."""
        return self._solid

    def leaf_distance(self, half: float, tf_solid: Any, tf_leaf: Any, req: Any, out: Any) -> float:
        """coal's distance [m] of the solid and one leaf of half edge ``half`` [m] (a cube
        of the cloud's axes) at the poses ``tf_solid`` and ``tf_leaf`` (its centre)."""
        return self._functors[half](tf_solid, tf_leaf, req, out)

    def __call__(
        self,
        tf_solid: coal.Transform3s,
        tf_cloud: coal.Transform3s,
        request: coal.DistanceRequest,
        result: coal.DistanceResult,
        cap: float | None = None,
    ) -> float:
        """The distance [m] (exact up to :attr:`cap`, or up to ``cap`` [m] if smaller:
        a caller that only needs to know whether the distance is below a value passes
        it, and a larger distance comes back as a lower bound above it, for less work)."""
        rs, ts = np.asarray(tf_solid.getRotation()), np.asarray(tf_solid.getTranslation())
        ro, to = np.asarray(tf_cloud.getRotation()), np.asarray(tf_cloud.getTranslation())
        rot = ro.T @ rs  # solid frame -> cloud frame
        pos = ro.T @ (ts - to)
        cells = self.cells

        def bound(centre: np.ndarray, half: np.ndarray) -> np.ndarray:
            """ℓ (n,) of boxes of centres (n, 3) and half sides (n, 3) or half edges (n,)."""
            d, g = solid_distance_bound(self._solid, (centre - pos) @ rot, self._planes)  # type: ignore[misc]
            g = np.abs(g @ rot.T)  # the subgradient in the cloud frame
            return d - (np.einsum("ij,ij->i", g, half) if half.ndim == 2 else g.sum(1) * half)

        # the buckets whose grid cell meets the solid's box grown by cap + ε + the
        # largest leaf half edge: any other leaf is farther than cap + ε (module doc)
        cap = self.cap if cap is None else min(self.cap, float(cap))
        far = cap + FAR_MARGIN
        grow = self._half_local @ np.abs(rot.T) + far + cells.hmax
        k0 = np.floor((pos - grow - cells.origin) / cells.edge).astype(np.int64)
        k1 = np.floor((pos + grow - cells.origin) / cells.edge).astype(np.int64)
        k0, k1 = np.maximum(k0, 0), np.minimum(k1, cells.dims - 1)
        if (k1 < k0).any():
            result.min_distance = far
            self.last_calls = 0
            return far
        dy, dz = int(cells.dims[1]), int(cells.dims[2])
        grid = (
            (np.arange(k0[0], k1[0] + 1)[:, None, None] * dy
             + np.arange(k0[1], k1[1] + 1)[None, :, None]) * dz
            + np.arange(k0[2], k1[2] + 1)[None, None, :]
        ).ravel()  # fmt: skip
        at = np.minimum(np.searchsorted(cells.keys, grid), len(cells.keys) - 1)
        near = at[cells.keys[at] == grid]
        if not near.size:
            result.min_distance = far
            self.last_calls = 0
            return far
        box_lb = bound(cells.box_centre[near], cells.box_half[near])
        # every leaf of a bucket whose bound is above the cap is above it too: the leaves
        # of the other buckets, all at once (one bound call), in increasing bound order
        inner = box_lb <= cap
        low = min(float(box_lb[~inner].min(initial=np.inf)), far)  # the leaves not gathered
        picked = near[inner]
        counts = cells.start[picked + 1] - cells.start[picked]
        shift = np.repeat(cells.start[picked] - np.cumsum(counts) + counts, counts)
        leaves = np.arange(int(counts.sum())) + shift  # the leaves of the picked buckets
        if self._hull_box is not None:  # the polytope's box holds it: a lower bound first
            c, e = self._hull_box
            d, g = _box_sdf((cells.centre[leaves] - pos) @ rot - c, e)
            box_leaf = d - np.abs(g @ rot.T).sum(1) * cells.half[leaves]
            low = min(low, float(box_leaf[box_leaf > cap].min(initial=np.inf)))
            leaves = leaves[box_leaf <= cap]
        leaf_lb = bound(cells.centre[leaves], cells.half[leaves])
        keep = leaf_lb <= cap
        low = min(low, float(leaf_lb[~keep].min(initial=np.inf)))
        sort = np.argsort(leaf_lb[keep], kind="stable")
        leaf_lb, leaf_ix = leaf_lb[keep][sort].tolist(), leaves[keep][sort].tolist()
        best, best_leaf, calls = np.inf, -1, 0
        for lb, leaf in zip(leaf_lb, leaf_ix):
            if best < 0.0 or lb >= best - TIE:
                low = min(low, lb)  # every leaf not computed is at least this far
                break
            self._tf_leaf.setTransform(ro, to + ro @ cells.centre[leaf])
            self._scratch.clear()
            d = self._functors[float(cells.half[leaf])](
                tf_solid, self._tf_leaf, request, self._scratch
            )
            calls += 1
            if d < best:
                best, best_leaf = d, leaf
        self.last_calls = calls
        if best_leaf < 0:  # every leaf beyond the cap: that bound
            result.min_distance = low
            return float(low)
        self._tf_leaf.setTransform(ro, to + ro @ cells.centre[best_leaf])
        value = self._functors[float(cells.half[best_leaf])](
            tf_solid, self._tf_leaf, request, result
        )
        if 0.0 <= low < value:  # within TIE below the value, or beyond the cap
            result.min_distance = low
            return float(low)
        return float(value)
