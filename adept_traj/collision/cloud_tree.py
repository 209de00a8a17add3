r"""A hierarchy of a point cloud's octree leaves and its batched descent for many solid poses.

:class:`CloudTree` groups the occupied leaves of
:class:`~adept_traj.collision.cloud_distance.CloudCells` in nested nodes: the cubes of
edge :math:`2^L` leaf edges (:math:`L = 1, 2, \dots`) of a grid aligned with the leaves'
box, up to the first level of at most :data:`TOP_NODES` nodes. Each node keeps the
smallest axis-aligned box holding its leaves (tighter than its cube for a thin scan), a
representative leaf (the one nearest that box's centre) and a *slab* holding its leaf
cubes, :math:`a \le n \cdot x \le b` along the direction :math:`n` of their centres' least
spread (a thin one for a piece of a scanned surface, whatever its orientation, where the
box of a tilted piece is thick).

:func:`descend` takes R poses of one robot solid (queries, each in a *group*: the pairs of
the branch and bound) and walks the levels breadth-first, every (query, node) of a level in
one batch. For each it forms a lower bound of the solid's distance to every leaf in the
node: the larger of the gap between the solid's and the slab's projections on :math:`n`
(where positive: the support function of the solid, closed form) and, for nodes of at most
:data:`FINE_EDGE`, the bound :math:`\ell` of :mod:`~adept_traj.collision.cloud_distance`
(the solid's signed distance at the box centre less its subgradient's reach over the box),
for larger ones the gap between the node's box and the box holding the solid on the
cloud's axes (cheaper, as useful there); and, at the nodes of at most :data:`FINE_EDGE`
with the least bound of their group, for a solid whose signed distance is exact (a box,
cylinder, capsule or sphere), an **upper bound** of the group's smallest distance: the
signed distance :math:`\varphi(x)` of the solid at the representative leaf's corner
:math:`x` facing the solid (a point of that leaf, so the leaf is at most
:math:`\max(\varphi(x), 0)` away; a leaf meeting the solid has a distance ≤ 0). Only the
(query, node) whose bound is at most the group's cap — the smaller of ``cap`` and the
best upper bound so far — are refined into their children: a node above it holds no leaf
nearer than the group's smallest distance (or than ``cap``). What is left at the leaves
are the (query, leaf) candidates of the exact step
(:mod:`~adept_traj.collision.cloud_search`), with their :math:`\ell` (within a fraction of
a millimetre of coal's distance for a leaf a few centimetres away).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import coal
import numpy as np

from adept_traj.collision.cloud_distance import (
    TIE,
    CloudCells,
    solid_distance_bound,
    solid_half_sides,
)

__all__ = ["TOP_NODES", "CloudTree", "Descent", "cloud_tree", "descend", "exact_signed_distance"]

#: Most nodes of the coarsest level (every query is bounded against each of them).
TOP_NODES = 16

#: Nodes of cubes larger than this [m] are bounded by the gaps between their box and the
#: solid's box (on the cloud's axes) and their slab only: a cheap first cut of far nodes.
FINE_EDGE = 0.08

#: Subtracted from a slab gap, which can equal the distance: a lower bound under rounding.
ROUNDING = 1e-9


@dataclass(frozen=True)
class Level:
    """The nodes of one level: box centres and half sides (n, 3) [m], representative leaf
    (n,) int, ``first`` (n + 1,) int: the children of node i are the nodes
    ``first[i]:first[i + 1]`` of the next (finer) level (unused at the leaves); and the
    slab holding each node's leaves, ``low ≤ normal · x ≤ high`` (normal (n, 3) unit,
    low, high (n,) [m]; None at the leaves); ``coarse``: cubes of an edge above
    :data:`FINE_EDGE`."""

    centre: np.ndarray
    half: np.ndarray
    rep: np.ndarray
    first: np.ndarray
    normal: np.ndarray | None = None
    low: np.ndarray | None = None
    high: np.ndarray | None = None
    coarse: bool = False


class CloudTree:
    """The nodes of every level of a cloud's leaves, coarse to fine (module doc).

    Attributes
    ----------
    levels: the :class:`Level` objects, the coarsest first and the leaves last.
    leaf_centre, leaf_half: (k, 3) leaf centres and (k,) half edges [m] (cloud frame), in
        the order of the last level.
    """

    def __init__(self, cells: CloudCells) -> None:
        centre, half = cells.centre, cells.half
        leaf = 2.0 * float(half.min())
        lo = (centre - half[:, None]).min(axis=0)
        keys, edge = [], leaf
        while True:  # the grid keys of each level, finest first
            edge *= 2.0
            key = np.floor((centre - lo) / edge).astype(np.int64)
            dims = key.max(axis=0) + 1
            keys.append((key[:, 0] * dims[1] + key[:, 1]) * dims[2] + key[:, 2])
            if len(np.unique(keys[-1])) <= TOP_NODES or (dims == 1).all():
                break
        order = np.lexsort(keys)  # by the coarsest key, then the next finer, …
        self.leaf_centre = np.ascontiguousarray(centre[order])
        self.leaf_half = np.ascontiguousarray(half[order])
        k = len(order)
        low = self.leaf_centre - self.leaf_half[:, None]
        high = self.leaf_centre + self.leaf_half[:, None]
        starts = []
        for key in reversed(keys):  # coarse to fine: where each node's leaves start
            flat = key[order]
            starts.append(np.concatenate([[0], np.flatnonzero(np.diff(flat)) + 1, [k]]))
        starts.append(np.arange(k + 1))
        levels = []
        for j, start in enumerate(starts):
            lo_n = np.minimum.reduceat(low, start[:-1], axis=0)
            hi_n = np.maximum.reduceat(high, start[:-1], axis=0)
            mid, spread = 0.5 * (lo_n + hi_n), 0.5 * (hi_n - lo_n)
            node = np.repeat(np.arange(len(start) - 1), np.diff(start))
            off = self.leaf_centre - mid[node]
            near = np.lexsort((np.einsum("ij,ij->i", off, off), node))
            rep = near[start[:-1]]  # the leaf nearest each box's centre
            nxt = starts[j + 1] if j + 1 < len(starts) else start
            first = np.searchsorted(nxt, start)
            slab = _slabs(self.leaf_centre, self.leaf_half, start) if j < len(keys) else ()
            coarse = j < len(keys) and leaf * 2.0 ** (len(keys) - j) > FINE_EDGE
            levels.append(Level(mid, spread, rep, first, *slab, coarse=coarse))
        self.levels = tuple(levels)


def _slabs(centre: np.ndarray, half: np.ndarray, start: np.ndarray) -> tuple[np.ndarray, ...]:
    r"""Per node (leaves ``start[i]:start[i + 1]`` of ``centre`` (k, 3), ``half`` (k,)):
    the unit normal (n, 3) of the leaf centres' least spread (their covariance's smallest
    eigenvector) and the slab ``low``, ``high`` (n,) [m] along it holding every leaf cube
    (a cube's reach along a unit n is its half edge times :math:`\|n\|_1`)."""
    count = np.diff(start)[:, None]
    mean = np.add.reduceat(centre, start[:-1], axis=0) / count
    node = np.repeat(np.arange(len(count)), count[:, 0])
    off = centre - mean[node]
    cov = np.add.reduceat(off[:, :, None] * off[:, None, :], start[:-1], axis=0)
    normal = np.linalg.eigh(cov)[1][:, :, 0]  # eigenvalues ascending
    along = np.einsum("ij,ij->i", centre, normal[node])
    reach = half * np.abs(normal[node]).sum(axis=1)
    low = np.minimum.reduceat(along - reach, start[:-1])
    high = np.maximum.reduceat(along + reach, start[:-1])
    return normal, low, high


def solid_support(solid: coal.CollisionGeometry, u: np.ndarray) -> np.ndarray | None:
    r"""The support function :math:`\max_{x \in S} u \cdot x` (m,) [m] of a coal ``Box``,
    ``Sphere``, ``Capsule`` or ``Cylinder`` (axis z; all centred at their frame's origin)
    for unit directions ``u`` (m, 3) in its frame; None for another geometry."""
    if isinstance(solid, coal.Box):
        return np.abs(u) @ np.asarray(solid.halfSide, dtype=float)
    if isinstance(solid, coal.Sphere):
        return np.full(len(u), float(solid.radius))
    if isinstance(solid, coal.Capsule):
        return solid.radius + solid.halfLength * np.abs(u[:, 2])
    if isinstance(solid, coal.Cylinder):
        return solid.radius * np.hypot(u[:, 0], u[:, 1]) + solid.halfLength * np.abs(u[:, 2])
    return None


def cloud_tree(cells: CloudCells) -> CloudTree:
    """The :class:`CloudTree` of ``cells``, made once and kept on them
    (:meth:`~adept_traj.collision.cloud_distance.CloudCells.derived`)."""
    return cells.derived("collision.cloud_tree", CloudTree)


def exact_signed_distance(solid: coal.CollisionGeometry) -> bool:
    """Whether :func:`~adept_traj.collision.cloud_distance.solid_distance_bound` is the
    solid's exact signed distance (a box, cylinder, capsule or sphere; not a convex hull's
    face-plane bound), so that it gives upper bounds too."""
    return isinstance(solid, (coal.Box, coal.Cylinder, coal.Capsule, coal.Sphere))


@dataclass(frozen=True)
class Descent:
    """What :func:`descend` leaves: the (query, leaf) candidates ``query``, ``leaf`` (m,)
    int with their lower bounds ``bound`` (m,) [m], each at most its group's cap; per group
    ``floor`` (G,) the smallest bound [m] of what was left out (inf: nothing), and
    ``upper`` (G,) the best upper bound [m] of its smallest distance (inf: none)."""

    query: np.ndarray
    leaf: np.ndarray
    bound: np.ndarray
    floor: np.ndarray
    upper: np.ndarray


def descend(
    tree: CloudTree,
    solid: coal.CollisionGeometry,
    rot: np.ndarray,
    pos: np.ndarray,
    group: np.ndarray,
    cap: np.ndarray,
    upper: np.ndarray,
) -> Descent:
    """The breadth-first descent of the module doc for R poses of ``solid`` in the cloud
    frame (rotations ``rot`` (R, 3, 3), positions ``pos`` (R, 3) [m]) in groups ``group``
    (R,) int < G.

    Parameters
    ----------
    cap:
        (G,) [m] per group: leaves farther than this need not be found (the influence).
    upper:
        (G,) [m] per group an upper bound of its smallest distance already known (inf:
        none); lowered here as better ones are found.
    """
    n_groups = len(cap)
    upper = upper.copy()
    floor = np.full(n_groups, np.inf)
    exact = exact_signed_distance(solid)
    slab = solid_support(solid, np.zeros((1, 3))) is not None
    q = np.repeat(np.arange(len(rot)), len(tree.levels[0].rep))
    n = np.tile(np.arange(len(tree.levels[0].rep)), len(rot))
    bound = np.empty(0)
    last = len(tree.levels) - 1
    reach = np.abs(rot) @ solid_half_sides(solid)  # (R, 3) half sides of the solids' boxes
    for j, level in enumerate(tree.levels):
        r, p, gq = rot[q], pos[q], group[q]
        if level.coarse:  # the gap between the boxes on the cloud's axes
            off = np.abs(p - level.centre[n]) - reach[q] - level.half[n]
            bound = functools.reduce(np.maximum, off.T) - ROUNDING
        else:  # ℓ
            local = np.einsum("mji,mj->mi", r, level.centre[n] - p)  # solid frame
            d, g = solid_distance_bound(solid, local)  # type: ignore[misc]
            g = np.einsum("mij,mj->mi", r, g)  # the subgradient, cloud frame
            bound = d - np.einsum("mi,mi->m", np.abs(g), level.half[n])
        if level.normal is not None and slab:  # the gap to the node's slab, where positive
            nrm = level.normal[n]
            h = solid_support(solid, np.einsum("mji,mj->mi", r, nrm))
            at = np.einsum("mi,mi->m", nrm, p)
            gap = np.maximum(level.low[n] - at - h, at - h - level.high[n]) - ROUNDING
            np.maximum(bound, gap, out=bound, where=gap > 0.0)
        keep = bound <= np.minimum(cap, upper)[gq] + TIE  # (an upper bound may equal ℓ)
        if exact and not level.coarse:  # the representative leaf's corner facing the
            # solid: an upper bound
            least = np.full(n_groups, np.inf)  # (of the nodes of each group's least bound)
            np.minimum.at(least, gq, bound)
            k = np.flatnonzero(keep & (bound <= least[gq]))
            rep = level.rep[n[k]]
            corner = tree.leaf_centre[rep] - np.copysign(tree.leaf_half[rep][:, None], g[k])
            u, _ = solid_distance_bound(solid, np.einsum("mji,mj->mi", r[k], corner - p[k]))  # type: ignore[misc]
            np.minimum.at(upper, gq[k], np.maximum(u, 0.0))
            keep[k] = bound[k] <= np.minimum(cap, upper)[gq[k]] + TIE
        if not keep.all():
            np.minimum.at(floor, gq[~keep], bound[~keep])
        q, n, bound = q[keep], n[keep], bound[keep]
        if j == last or not len(q):
            break
        first = level.first
        counts = first[n + 1] - first[n]
        n = np.repeat(first[n] - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())
        q = np.repeat(q, counts)
    if j < last:  # every query left out before the leaves
        q, n, bound = q[:0], n[:0], bound[:0]
    return Descent(q, n, bound, floor, upper)
