r"""The point-cloud level of the broad phase (level 5 of
:mod:`adept_traj.collision.broad_phase`): bounds of a primitive solid's distance to a point
cloud from samples of its box and the cloud's point bound
(:meth:`~adept_traj.collision.cloud_distance.CloudCells.point_bound`), so that a solid
near a dense scan but not within ``influence`` of it needs no narrow-phase call."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import coal
import numpy as np

from adept_traj.collision.cloud_distance import cloud_cells, solid_half_sides
from adept_traj.scene.point_clouds import PointCloud

if TYPE_CHECKING:
    from adept_traj.collision.broad_phase import BroadPhase

__all__ = [
    "CLOUD_COARSE_STEP",
    "CLOUD_SAMPLE_STEP",
    "cloud_bound",
    "cloud_samples",
]

#: Largest side [m] of the cells whose centres sample a solid's box against a point cloud
#: (level 5a; each cut in 2 × 2 × 2 for the finer cells), and of the squares that sample
#: its faces (5b; each face of a finer cell cut in squares).
CLOUD_COARSE_STEP = 0.08
CLOUD_SAMPLE_STEP = 0.015


def cloud_bound(
    broad: BroadPhase,
    bound: np.ndarray,
    still: np.ndarray,
    frames: np.ndarray,
    idx: np.ndarray,
    po: np.ndarray,
    k: int,
    o: int,
) -> np.ndarray:
    """Level 5 of ``broad`` for a point cloud ``o`` and a primitive solid ``k`` at the
    samples ``idx[still]`` (bounds ``bound`` (R,), joint ``frames``, cloud poses ``po``),
    from the cloud's point bound ``b``
    (:meth:`~adept_traj.collision.cloud_distance.CloudCells.point_bound`, below the
    distance to the leaves everywhere) at samples of the solid's box, coarse to fine
    (:func:`cloud_samples`), each on the rows still within ``influence``:

    a. the box cut into cells of at most :data:`CLOUD_COARSE_STEP` a side, then each cell
       in 2 × 2 × 2: every point of a cell is within ``s`` (half its diagonal) of its
       centre ``g``, so the distance over the cell is at least :math:`b(g) - s`, and that
       of the box at least the smallest over its cells;
    b. where (a) is positive the box is clear of every leaf, so its distance is that of
       its surface: the same with each face of the finer cells cut into squares of at
       most :data:`CLOUD_SAMPLE_STEP` a side.

    A finer cell (a square) lies in its parent cell, so the parent's bound holds for it
    too: only the pieces whose parent's bound is at most ``influence`` are looked up (the
    others keep the parent's, above ``influence``), and each piece keeps the larger of
    its bound and its parent's. The solid is inside its box, so these bound its distance
    too; each row keeps the largest of its bounds (every one is valid)."""
    samples = broad.cloud_samples[k]
    if samples is None or not isinstance(broad.obstacle_shape[o], PointCloud):
        return bound
    cells = cloud_cells(broad.obstacle_geometry[o], broad.obstacle_shape[o])
    ps = broad.solid_poses(frames, idx[still], k)
    po = po if po.ndim == 2 else po[still]
    rot = np.swapaxes(po[..., :3, :3], -1, -2) @ ps[:, :3, :3]  # solid in cloud frame
    pos = np.einsum("...ji,...j->...i", po[..., :3, :3], ps[:, :3, 3] - po[..., :3, 3])
    lower = bound[still].copy()  # of the solid: the earlier levels' and these
    influence = broad.influence
    rows = np.arange(len(lower))  # the rows of ``values``
    values = np.empty((len(lower), 0))  # per row, the bounds of the pieces of a level
    for points, slack, surface, parent in samples:
        keep = lower[rows] <= influence
        if surface:  # (b) only where (a) proved the box clear of every leaf
            keep &= values.min(axis=1) > 0.0
        rows, values = rows[keep], values[keep]
        if not rows.size:
            break
        if parent is None:  # the first level: every piece
            local = points @ np.swapaxes(rot[rows], -1, -2) + pos[rows, None]
            values = cells.point_bound(local) - slack
        else:
            values = values[:, parent]  # the parent's bound, valid for the piece
            r, j = np.nonzero(values <= influence)
            local = np.einsum("kij,kj->ki", rot[rows[r]], points[j]) + pos[rows[r]]
            values[r, j] = np.maximum(values[r, j], cells.point_bound(local) - slack)
        lower[rows] = np.maximum(lower[rows], values.min(axis=1))
    bound = bound.copy()
    bound[still] = lower
    return bound


def cloud_samples(geometry: coal.CollisionGeometry) -> tuple[Any, ...] | None:
    """Samples of a primitive solid's box for level 5 (:func:`cloud_bound`), solid frame,
    coarse to fine, each as ``(points (m, 3) [m], half diagonal [m] of their pieces, on
    the surface, parent (m,) int or None)``: the centres of the cells of at most
    :data:`CLOUD_COARSE_STEP` a side tiling the box; those of the cells halving them
    (the parent: the coarse cell holding each); the centres of the squares of at most
    :data:`CLOUD_SAMPLE_STEP` a side tiling the faces of the finer cells on the box's
    faces (the parent: that finer cell). None for another geometry."""
    half = solid_half_sides(geometry)
    if half is None:
        return None
    n0 = np.maximum(np.ceil(2.0 * half / CLOUD_COARSE_STEP), 1).astype(int)
    n1 = 2 * n0
    out = []
    for n in (n0, n1):
        side = 2.0 * half / n
        axes = [-half[a] + side[a] * (np.arange(n[a]) + 0.5) for a in range(3)]
        centres = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        index = np.stack(np.meshgrid(*map(np.arange, n), indexing="ij"), -1).reshape(-1, 3)
        parent = None
        if n is n1:  # the coarse cell holding each finer one
            up = index // 2
            parent = (up[:, 0] * n0[1] + up[:, 1]) * n0[2] + up[:, 2]
        out.append((centres, 0.5 * float(np.linalg.norm(side)) + 1e-9, False, parent))
    side1 = 2.0 * half / n1
    cut = np.maximum(np.ceil(side1 / CLOUD_SAMPLE_STEP), 1).astype(int)  # squares a cell
    m = n1 * cut  # squares along each axis of the box
    square = 2.0 * half / m
    faces, parents, slack = [], [], 0.0
    for axis in range(3):
        others = [a for a in range(3) if a != axis]
        u, v = np.meshgrid(np.arange(m[others[0]]), np.arange(m[others[1]]), indexing="ij")
        u, v = u.ravel(), v.ravel()
        for end in (0, n1[axis] - 1):
            face = np.empty((u.size, 3))
            face[:, others[0]] = -half[others[0]] + square[others[0]] * (u + 0.5)
            face[:, others[1]] = -half[others[1]] + square[others[1]] * (v + 0.5)
            face[:, axis] = half[axis] if end else -half[axis]
            cell = np.empty((u.size, 3), dtype=int)
            cell[:, others[0]], cell[:, others[1]] = u // cut[others[0]], v // cut[others[1]]
            cell[:, axis] = end
            faces.append(face)
            parents.append((cell[:, 0] * n1[1] + cell[:, 1]) * n1[2] + cell[:, 2])
        slack = max(slack, 0.5 * float(np.linalg.norm(square[others])))
    out.append((np.concatenate(faces), slack + 1e-9, True, np.concatenate(parents)))
    return tuple(out)
