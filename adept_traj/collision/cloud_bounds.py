r"""The point-cloud level of the broad phase (level 5 of
:mod:`adept_traj.collision.broad_phase`): bounds of a primitive solid's distance to a point
cloud from samples of its box and the cloud's point bound
(:meth:`~adept_traj.collision.cloud_distance.CloudCells.point_bound`), so that a solid
near a dense scan but not within ``influence`` of it needs no narrow-phase call."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import coal
import numpy as np

from adept_traj.collision.cloud_distance import CloudCells, cloud_cells, solid_half_sides
from adept_traj.scene.point_clouds import PointCloud

if TYPE_CHECKING:
    from adept_traj.collision.broad_phase import BroadPhase

__all__ = [
    "CLOUD_COARSE_STEP",
    "CLOUD_SAMPLE_STEP",
    "cloud_bound",
    "cloud_samples",
    "sampled_bound",
]

#: Largest side [m] of the cells whose centres sample a solid's box against a point cloud
#: (level 5a), and of the squares that sample its faces (5b).
CLOUD_COARSE_STEP = 0.04
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
    from the cloud's
    point bound ``b`` (:meth:`~adept_traj.collision.cloud_distance.CloudCells.point_bound`,
    1-Lipschitz below the distance to the leaves) at samples of the solid's box:

    a. the box cut into cells of at most :data:`CLOUD_COARSE_STEP` a side: every point
       of the box is within ``s`` (half a cell diagonal) of a cell centre ``g``, so
       :math:`d \\ge \\min_g b(g) - s`;
    b. where (a) is positive the box is clear of every leaf, so its distance is that of
       its surface: the same with the faces cut into squares of at most
       :data:`CLOUD_SAMPLE_STEP` a side (the rows still within ``influence``).

    The solid is inside its box, so these bound its distance too."""
    samples = broad.cloud_samples[k]
    if samples is None or not isinstance(broad.obstacle_shape[o], PointCloud):
        return bound
    cells = cloud_cells(broad.obstacle_geometry[o], broad.obstacle_shape[o])
    ps = broad.solid_poses(frames, idx[still], k)
    po = po if po.ndim == 2 else po[still]
    rot = np.swapaxes(po[..., :3, :3], -1, -2) @ ps[:, :3, :3]  # solid in cloud frame
    pos = np.einsum("...ji,...j->...i", po[..., :3, :3], ps[:, :3, 3] - po[..., :3, 3])
    (coarse, s_coarse), (surface, s_surface) = samples
    lower = sampled_bound(cells, coarse, s_coarse, rot, pos)
    rows = np.flatnonzero((lower > 0.0) & (lower <= broad.influence))
    if rows.size:  # the box is clear of every leaf there: its faces bound it
        lower[rows] = np.maximum(
            lower[rows], sampled_bound(cells, surface, s_surface, rot[rows], pos[rows])
        )
    bound = bound.copy()
    bound[still] = np.maximum(bound[still], lower)
    return bound


def sampled_bound(
    cells: CloudCells, points: np.ndarray, slack: float, rot: np.ndarray, pos: np.ndarray
) -> np.ndarray:
    """:math:`\\min_g b(g) - s` (R,) over ``points`` (m, 3) of the solid frame placed by
    ``rot`` (R, 3, 3) and ``pos`` (R, 3) in the cloud frame."""
    out = np.empty(len(rot))
    step = max(1, 200_000 // len(points))  # about 5 MB of points at a time
    for a in range(0, len(rot), step):
        local = points @ np.swapaxes(rot[a : a + step], -1, -2) + pos[a : a + step, None]
        out[a : a + step] = cells.point_bound(local).min(axis=1)
    return out - slack


def cloud_samples(geometry: coal.CollisionGeometry) -> tuple[Any, ...] | None:
    """Samples of a primitive solid's box for level 5, solid frame: the centres (m, 3)
    [m] of cells of at most :data:`CLOUD_COARSE_STEP` a side tiling the box and their
    half diagonal [m]; the centres of squares of at most
    :data:`CLOUD_SAMPLE_STEP` a side tiling its faces and their half diagonal; None for
    another geometry."""
    half = solid_half_sides(geometry)
    if half is None:
        return None

    def cells(step: float, axes: tuple[int, ...]) -> tuple[list[np.ndarray], np.ndarray]:
        n = np.maximum(np.ceil(2.0 * half / step), 1).astype(int)
        side = 2.0 * half / n
        return [-half[a] + side[a] * (np.arange(n[a]) + 0.5) for a in axes], side[list(axes)]

    out = []
    for step in (CLOUD_COARSE_STEP,):
        grid, side = cells(step, (0, 1, 2))
        centres = np.stack(np.meshgrid(*grid, indexing="ij"), axis=-1).reshape(-1, 3)
        out.append((centres, 0.5 * float(np.linalg.norm(side)) + 1e-9))
    for step in (CLOUD_SAMPLE_STEP,):
        faces, slack = [], 0.0
        for axis in range(3):
            others = tuple(a for a in range(3) if a != axis)
            grid, side_f = cells(step, others)
            u, v = np.meshgrid(*grid, indexing="ij")
            for sign in (-1.0, 1.0):
                face = np.zeros((u.size, 3))
                face[:, others[0]], face[:, others[1]] = u.ravel(), v.ravel()
                face[:, axis] = sign * half[axis]
                faces.append(face)
            slack = max(slack, 0.5 * float(np.linalg.norm(side_f)))
        out.append((np.concatenate(faces), slack + 1e-9))
    return tuple(out)
