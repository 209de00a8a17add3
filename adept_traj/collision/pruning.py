r"""Obstacle pruning: the fixed obstacles a batch of motions never comes near.

A work cell has dozens to hundreds of fixed obstacles, most of them far from any given
motion. Before the broad phase, :class:`ObstaclePruning` bounds, for a batch of motions,
the distance of every fixed obstacle to everything the robot's solids sweep:

- each solid's enclosing ball (centre :math:`c_k(t)`, radius :math:`R_k`) stays, over the
  samples of motion m, inside the axis-aligned box
  :math:`A_{mk} = [\min_t c_k - R_k,\ \max_t c_k + R_k]` (base frame);
- each fixed obstacle lies inside its bounding sphere (centre :math:`o`, radius
  :math:`r_o`, :attr:`~adept_traj.scene.shapes.Shape.bounding_radius` about the origin
  of its own frame);

so every solid–obstacle distance over motion m is at least

.. math:: b_{mo} = \min_k\ d(o, A_{mk}) - r_o ,

:math:`d(o, A)` the Euclidean distance of a point to a box (0 inside). Where
:math:`b_{mo} >` ``influence`` the obstacle cannot change any quantity built from
distances below ``influence``: the checker reports :math:`b_{mo}` as its (lower-bound)
distance for that motion, and leaves the obstacle out of the broad phase, the branch and
bound and coal when that holds for every motion of the batch (the arrays of the broad
phase stay dense). The result of a motion does not depend on the batch it is in. Moving
obstacles are never pruned. The test is one array operation of (motions, solids,
obstacles) entries.

:func:`sweep_clearance` serves the same purpose at construction: a lower bound of the
distance between an obstacle and a solid turned through a full revolution of one joint
(its enclosing ball sweeps a circle about the axis), which lets the broad phase skip the
single-joint :class:`~adept_traj.collision.DistanceTable` of an obstacle that the solid
never comes near (most of the construction time of a 200-box cell).
"""

from __future__ import annotations

import copy
from typing import TYPE_CHECKING

import numpy as np

from adept_traj.scene.scene import Scene

if TYPE_CHECKING:
    from adept_traj.collision.broad_phase import BroadPhase
    from adept_traj.collision.checker import CollisionChecker

__all__ = ["ObstaclePruning", "restrict_broad_phase", "restrict_checker", "sweep_clearance"]


class ObstaclePruning:
    """Bounding spheres of a scene's fixed obstacles, and the pruning test (module doc).

    Parameters
    ----------
    scene:
        The obstacles and the robot base pose.
    influence:
        Distance [m] beyond which an obstacle is pruned (≥ 0).
    """

    def __init__(self, scene: Scene, influence: float) -> None:
        self.influence = float(influence)
        to_base = scene.base_from_world
        n = len(scene.obstacles)
        #: (n_obstacles,) bool: the obstacle may be pruned (it is fixed).
        self.fixed = np.array([not ob.is_moving for ob in scene.obstacles], dtype=bool)
        #: (n_obstacles, 3) bounding-sphere centres in the base frame [m] (fixed ones).
        self.centres = np.zeros((n, 3))
        #: (n_obstacles,) bounding-sphere radii [m].
        self.radii = np.array([ob.shape.bounding_radius for ob in scene.obstacles]).reshape(n)
        for o, ob in enumerate(scene.obstacles):
            if not ob.is_moving:
                self.centres[o] = (to_base @ ob.pose(0.0))[:3, 3]

    def lower_bounds(self, balls: np.ndarray, radius: np.ndarray, n_motions: int) -> np.ndarray:
        r"""(n_motions, n_obstacles) lower bound [m] of every solid–obstacle distance over
        each motion: :math:`\min_k d(o, A_{mk}) - r_o` (module doc) for fixed obstacles,
        ``-inf`` for moving ones.

        Parameters
        ----------
        balls:
            (3, n_solids, N) enclosing-ball centres of the solids [m], base frame,
            component-major; the N samples are ``n_motions`` motions of equal length, in
            order.
        radius:
            (n_solids,) enclosing-ball radii [m].
        n_motions:
            Number of motions (N must be a multiple of it).
        """
        out = np.full((n_motions, len(self.fixed)), -np.inf)
        if not self.fixed.any() or balls.shape[-1] == 0:
            return out
        per = balls.reshape(3, balls.shape[1], n_motions, -1)
        lo = per.min(axis=-1) - radius[None, :, None]  # (3, n_solids, n_motions)
        hi = per.max(axis=-1) + radius[None, :, None]
        c = self.centres[self.fixed].T[:, None, None, :]  # (3, 1, 1, n_fixed)
        gap = np.maximum(lo[..., None] - c, 0.0) + np.maximum(c - hi[..., None], 0.0)
        dist = np.sqrt(np.einsum("i...,i...->...", gap, gap))  # (n_solids, n_motions, n_fixed)
        out[:, self.fixed] = dist.min(axis=0) - self.radii[self.fixed]
        return out

    def kept(self, bounds: np.ndarray) -> np.ndarray:
        """Indices of the obstacles to keep, for the ``bounds`` (n_motions, n_obstacles) of
        :meth:`lower_bounds`: those within ``influence`` of some motion (every moving
        obstacle)."""
        return np.flatnonzero((~(bounds > self.influence)).any(axis=0))


def restrict_broad_phase(broad: BroadPhase, obstacles: np.ndarray) -> BroadPhase:
    """A view of ``broad`` on the obstacles of index ``obstacles`` (n,) only, in that order
    (its solids, tables and static distances shared, nothing recomputed)."""
    keep = np.asarray(obstacles, dtype=int)
    view = copy.copy(broad)
    view.n_obstacles = len(keep)
    for name in ("obstacle_shape", "obstacle_geometry", "obstacle_kind"):
        setattr(view, name, [getattr(broad, name)[o] for o in keep])
    view.moving = broad.moving[keep]
    view.closed_form = broad.closed_form[:, keep]
    view.static = broad.static[:, keep]
    view.static_distance = broad.static_distance[:, keep]
    new = {int(o): i for i, o in enumerate(keep)}
    view.tables = {(k, new[o]): t for (k, o), t in broad.tables.items() if o in new}
    return view


def restrict_checker(checker: CollisionChecker, obstacles: np.ndarray) -> CollisionChecker:
    """A view of ``checker`` on the obstacles of index ``obstacles`` (n,) only: its broad
    phase (:func:`restrict_broad_phase`), coal functors, names, scene and allowed contacts
    restricted to them, nothing recomputed."""
    keep = [int(o) for o in obstacles]
    view = copy.copy(checker)
    view.broad_phase = restrict_broad_phase(checker.broad_phase, np.asarray(keep))
    view.functors = [[row[o] for o in keep] for row in checker.functors]
    view.obstacle_names = tuple(checker.obstacle_names[o] for o in keep)
    contacts = tuple(c for c in checker.scene.allowed_contacts if c[1] in view.obstacle_names)
    view.scene = Scene(
        tuple(checker.scene.obstacles[o] for o in keep),
        robot_base=checker.scene.robot_base,
        name=checker.scene.name,
        allowed_contacts=contacts,
    )
    view.allowed = checker.allowed[:, keep]
    view._fixed_poses = [checker._fixed_poses[o] for o in keep]
    view._law_of = tuple(checker._law_of[o] for o in keep)  # still one key per motion law
    view._views = {}
    return view


def sweep_clearance(
    origin: np.ndarray,
    axis: np.ndarray,
    centre: np.ndarray,
    ball_radius: float,
    point: np.ndarray,
    point_radius: float,
) -> float:
    """Lower bound [m] of the distance between a ball (``centre`` (3,), ``ball_radius``)
    turned through a full revolution about the line through ``origin`` (3,) along the unit
    ``axis`` (3,), and a ball (``point`` (3,), ``point_radius``): the distance from
    ``point`` to the circle the centre sweeps, minus both radii.

    .. math::
        \\sqrt{(a_p - a_c)^2 + (\\rho_p - \\rho_c)^2} - R - r ,

    with :math:`a` the coordinate along the axis and :math:`\\rho` the distance from it.
    """
    c, p = centre - origin, point - origin
    a_c, a_p = float(c @ axis), float(p @ axis)
    rho_c = float(np.linalg.norm(c - a_c * axis))
    rho_p = float(np.linalg.norm(p - a_p * axis))
    return float(np.hypot(a_p - a_c, rho_p - rho_c)) - ball_radius - point_radius
