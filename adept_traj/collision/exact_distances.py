"""Every solid–obstacle pair's exact signed distance at every sample: the distances of the
certificate (:meth:`~adept_traj.collision.CollisionChecker.distances` with ``exact=True``),
where no broad-phase bound stands in for a distance.

A static pair keeps the distance computed once at construction, a sphere obstacle its
closed form, every other pair is computed by coal at every sample. coal's transform of each
solid at a sample is formed once and used against every obstacle; that of a moving obstacle
once per sample for every solid, that of a fixed obstacle once. Setting a transform costs
about as much as coal's distance between two primitives, so forming each one once is what
makes the loop fast. The samples go in chunks of :data:`CHUNK` (bounded memory).
"""

from __future__ import annotations

from itertools import repeat
from typing import TYPE_CHECKING

import coal
import numpy as np

from adept_traj.collision.primitives import distance_request
from adept_traj.scene.shapes import coal_transform

if TYPE_CHECKING:  # the checker imports this module
    from adept_traj.collision.checker import CollisionChecker

__all__ = ["CHUNK", "exact_distances"]

#: Samples whose coal transforms are held at once (about 0.2 kB each per solid).
CHUNK = 8192


def exact_distances(
    checker: CollisionChecker, frames: np.ndarray, obstacle_poses: list[np.ndarray]
) -> np.ndarray:
    """The exact signed distance of every solid and obstacle of ``checker`` at every sample.

    Parameters
    ----------
    checker:
        The :class:`~adept_traj.collision.CollisionChecker` (its broad phase, functors and
        allowed contacts).
    frames:
        (njoints, 3, 4, N) the robot's joint frames at the N samples
        (:attr:`~adept_traj.robot.ForwardKinematics.joint_frames`).
    obstacle_poses:
        Per obstacle its pose in the robot base frame: (4, 4) if fixed, (N, 4, 4) if moving
        (:meth:`~adept_traj.collision.CollisionChecker.obstacle_poses`).

    Returns
    -------
    numpy.ndarray
        (N, n_solids, n_obstacles) [m], negative in penetration; ``inf`` for an allowed
        contact (never checked).
    """
    broad = checker.broad_phase
    n = frames.shape[-1]
    out = np.empty((n, checker.n_solids, checker.n_obstacles))
    by_coal = ~(broad.static | broad.closed_form | checker.allowed)
    request, result = distance_request(), coal.DistanceResult()
    fixed = [coal_transform(p) if p.ndim == 2 else None for p in obstacle_poses]
    for start in range(0, n, CHUNK):
        rows = np.arange(start, min(start + CHUNK, n))
        moving: dict[int, list[coal.Transform3s]] = {}  # formed once for every solid
        for k in range(checker.n_solids):
            poses = broad.solid_poses(frames, rows, k)
            solid: list[coal.Transform3s] | None = None
            for o, pose_o in enumerate(obstacle_poses):
                if broad.static[k, o]:
                    out[rows, k, o] = broad.static_distance[k, o]
                    continue
                if broad.closed_form[k, o]:
                    at = pose_o if pose_o.ndim == 2 else pose_o[rows]
                    out[rows, k, o] = broad.closed_form_distance(poses, at, k, o)
                    continue
                if not by_coal[k, o]:
                    continue  # an allowed contact: inf below
                if solid is None:
                    solid = _transforms(poses)
                if fixed[o] is None and o not in moving:
                    moving[o] = _transforms(pose_o[rows])
                functor, values = checker.functors[k][o], []
                at_o = repeat(fixed[o]) if fixed[o] is not None else moving[o]
                for tf_s, tf_o in zip(solid, at_o):
                    result.clear()
                    values.append(functor(tf_s, tf_o, request, result))
                out[rows, k, o] = values
    out[:, checker.allowed] = np.inf
    return out


def _transforms(poses: np.ndarray) -> list[coal.Transform3s]:
    """coal transforms of poses (R, 4, 4)."""
    rotations = np.ascontiguousarray(poses[:, :3, :3])
    translations = np.ascontiguousarray(poses[:, :3, 3])
    return list(map(coal.Transform3s, rotations, translations))
