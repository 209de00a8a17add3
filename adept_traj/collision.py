"""Signed distances between the robot's link solids and the scene's obstacles over time.

:class:`CollisionChecker` gives, for configurations ``q`` (..., n_t, nq) at times ``t``
(..., n_t) [s], the signed distance [m] between **every** robot solid and **every** obstacle
(moving obstacles at their pose at that time; negative = penetration depth), using coal.

Broad phase (conservative, numpy, batched): every robot solid is covered by a few spheres
(its local bounding box cut along its longest side); for each sphere centre ``c`` with radius
``r`` and each obstacle ``B`` the exact signed distance ``d(c, B)`` of a point to a box,
sphere, cylinder or capsule is computed in closed form, and

.. math:: d(\\text{solid}, B) \\ge \\min_i \\big(d(c_i, B) - r_i\\big) =: \\text{LB}.

Only pairs with LB ≤ ``influence`` go to coal (narrow phase, one call per close pair:
the only Python loop, over close pairs, never over all samples). The other entries hold LB,
a lower bound greater than ``influence``: every quantity built from distances below
``influence`` (the constraint, the clearance penalty) is therefore exact.

Also here: :func:`paper_penalty`, the paper's eqs. (13)–(16) (circumscribing spheres or
ellipsoids around obstacles, tool points), kept for comparison.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import coal
import numpy as np

from ._validation import as_finite_array
from .errors import InputShapeError, InvalidInputError
from .robot import Robot
from .scene import Scene
from .shapes import Box, Capsule, Cylinder, Sphere

__all__ = [
    "CollisionChecker",
    "MinDistances",
    "PairDistances",
    "paper_penalty",
    "point_signed_distance",
]


@dataclass(frozen=True)
class PairDistances:
    """Distances between robot solids and obstacles.

    Attributes
    ----------
    distance:
        (..., n_t, n_solids, n_obstacles) signed distance [m] where ``exact``, else a lower
        bound greater than the checker's ``influence``.
    exact:
        (..., n_t, n_solids, n_obstacles) bool, where coal computed the distance.
    n_narrow:
        Number of coal distance calls made.
    """

    distance: np.ndarray
    exact: np.ndarray
    n_narrow: int

    @property
    def min_distance(self) -> np.ndarray:
        """(..., n_t) smallest distance over all pairs [m] (exact when ≤ ``influence``)."""
        return self.distance.min(axis=(-2, -1))

    @property
    def per_obstacle(self) -> np.ndarray:
        """(..., n_obstacles) smallest distance over time and solids to each obstacle [m]."""
        return self.distance.min(axis=(-3, -2))


@dataclass(frozen=True)
class MinDistances:
    """Smallest distance to each obstacle over a whole motion.

    Attributes
    ----------
    distance:
        (..., n_obstacles) smallest signed distance [m] over the motion's samples and the
        robot solids; exact when ≤ ``influence``, else a lower bound greater than it.
    sample, solid:
        (..., n_obstacles) int, where the smallest exact distance was found (-1 if none).
    n_narrow:
        Number of coal distance calls made.
    """

    distance: np.ndarray
    sample: np.ndarray
    solid: np.ndarray
    n_narrow: int


def point_signed_distance(shape: object, p: np.ndarray) -> np.ndarray:
    """Exact signed distance [m] of points ``p`` (..., 3), in the shape's own frame, to a
    :class:`Box`, :class:`Sphere`, :class:`Cylinder` (axis z) or :class:`Capsule` (axis z);
    negative inside."""
    if isinstance(shape, Sphere):
        return np.linalg.norm(p, axis=-1) - shape.radius
    if isinstance(shape, Box):
        excess = np.abs(p) - 0.5 * np.asarray(shape.size)
        outside = np.linalg.norm(np.maximum(excess, 0.0), axis=-1)
        return outside + np.minimum(excess.max(axis=-1), 0.0)
    if isinstance(shape, Cylinder):
        radial = np.hypot(p[..., 0], p[..., 1]) - shape.radius
        axial = np.abs(p[..., 2]) - 0.5 * shape.length
        outside = np.hypot(np.maximum(radial, 0.0), np.maximum(axial, 0.0))
        return outside + np.minimum(np.maximum(radial, axial), 0.0)
    if isinstance(shape, Capsule):
        half = 0.5 * shape.length
        closest = np.clip(p[..., 2], -half, half)
        return np.hypot(np.hypot(p[..., 0], p[..., 1]), p[..., 2] - closest) - shape.radius
    raise InvalidInputError(f"no point distance for obstacle shape {type(shape).__name__}")


def _covering_spheres(geometry: coal.CollisionGeometry) -> tuple[np.ndarray, np.ndarray]:
    """Centres (k, 3) in the geometry frame and radii (k,) of spheres covering its local
    bounding box, cut into k near-cubic pieces along its longest side."""
    geometry.computeLocalAABB()
    lo = np.array(geometry.aabb_local.min_)
    hi = np.array(geometry.aabb_local.max_)
    extent = hi - lo
    axis = int(np.argmax(extent))
    others = np.delete(extent, axis)
    k = max(1, int(np.ceil(extent[axis] / max(others.max(), 1e-9))))
    piece = extent.copy()
    piece[axis] /= k
    centres = np.tile(0.5 * (lo + hi), (k, 1))
    centres[:, axis] = lo[axis] + piece[axis] * (np.arange(k) + 0.5)
    return centres, np.full(k, 0.5 * np.linalg.norm(piece))


class CollisionChecker:
    """Distances between a robot's collision solids and a scene's obstacles (see module doc).

    Parameters
    ----------
    robot:
        The robot; its :attr:`~adept_traj.robot.Robot.collision_model` gives the solids.
    scene:
        The obstacles and the robot base pose in the world.
    influence:
        Distance [m] below which distances are computed exactly (default 0.05 m). Must be
        ≥ 0; it should be at least the safety margin used with the distances.
    """

    def __init__(self, robot: Robot, scene: Scene, influence: float = 0.05) -> None:
        if not (np.isfinite(influence) and influence >= 0):
            raise InvalidInputError(f"influence must be a finite distance ≥ 0 [m]; got {influence}")
        self.robot, self.scene, self.influence = robot, scene, float(influence)
        objects = robot.collision_model.geometryObjects
        self.solid_names = tuple(g.name for g in objects)
        self.obstacle_names = tuple(ob.name for ob in scene.obstacles)
        centres, radii, owner = [], [], []
        for k, g in enumerate(objects):
            c, r = _covering_spheres(g.geometry)
            centres.append(c)
            radii.append(r)
            owner += [k] * len(r)
        self._sphere_centres = np.vstack(centres)  # (n_spheres, 3) in the solids' frames
        self._sphere_radii = np.concatenate(radii)
        self._sphere_owner = np.array(owner)
        self._robot_geoms = [g.geometry for g in objects]
        self._obstacle_geoms = [ob.shape.to_coal() for ob in scene.obstacles]
        self._functors = [
            [coal.ComputeDistance(g, o) for o in self._obstacle_geoms] for g in self._robot_geoms
        ]
        self._request = coal.DistanceRequest()
        self._result = coal.DistanceResult()
        self._tf = (coal.Transform3s(), coal.Transform3s())

    @property
    def n_solids(self) -> int:
        """Number of robot solids."""
        return len(self.solid_names)

    @property
    def n_obstacles(self) -> int:
        """Number of obstacles."""
        return len(self.obstacle_names)

    def distances(self, q: Any, t: Any, *, exact: bool = False) -> PairDistances:
        """Solid–obstacle distances for configurations ``q`` (..., n_t, nq) [rad | m] at
        times ``t`` (..., n_t) [s] (broadcast against q's leading axes).

        With ``exact=True`` every pair is computed by coal (for verification).
        """
        qa, ta = self._check(q, t)
        return self._distances(qa, ta, exact)

    def _check(self, q: Any, t: Any) -> tuple[np.ndarray, np.ndarray]:
        qa = as_finite_array(q, "q")
        ta = as_finite_array(t, "t")
        if qa.ndim < 2 or qa.shape[-1] != self.robot.nq:
            raise InputShapeError(
                f"q must have shape (..., n_t, {self.robot.nq}); got shape {qa.shape}"
            )
        try:
            ta = np.broadcast_to(ta, qa.shape[:-1])
        except ValueError:
            raise InputShapeError(
                f"t must broadcast to q's leading shape {qa.shape[:-1]}; got shape {ta.shape}"
            ) from None
        return qa, ta

    def min_distances(self, q: Any, t: Any) -> MinDistances:
        """Per motion and obstacle, the smallest solid–obstacle distance over all samples.

        ``q`` (..., n_t, nq) [rad | m] and ``t`` (..., n_t) [s]: the leading axes ``...``
        are motions (e.g. the population). Branch and bound: candidates (sample, solid)
        are computed by coal in increasing order of their broad-phase lower bound until the
        best exact distance is below the next bound, so the result is the exact minimum
        (when ≤ ``influence``) with few coal calls. A positive broad-phase bound is a true
        lower bound; candidates with a bound ≤ 0 (possible penetration) are always computed,
        so penetration depths are exact too.
        """
        qa, ta = self._check(q, t)
        return self._min_distances(qa, ta)

    # ------------------------------------------------------------------ private hooks
    def _obstacle_poses(self, t: np.ndarray) -> np.ndarray:
        """(n_obs, ..., 4, 4) obstacle poses in the robot base frame."""
        if self.n_obstacles == 0:
            return np.empty((0, *t.shape, 4, 4))
        return self.scene.obstacle_poses(t, in_base_frame=True)

    def _lower_bounds(self, solid_poses: np.ndarray, obstacle_poses: np.ndarray) -> np.ndarray:
        """(..., n_solids, n_obs) broad-phase lower bounds [m]."""
        rot = solid_poses[..., self._sphere_owner, :3, :3]
        centres = np.einsum("...ij,...j->...i", rot, self._sphere_centres)
        centres += solid_poses[..., :3, 3][..., self._sphere_owner, :]  # (..., n_spheres, 3)
        batch = solid_poses.shape[:-3]
        lower = np.empty((*batch, self.n_solids, self.n_obstacles))
        for o, ob in enumerate(self.scene.obstacles):
            pose = obstacle_poses[o][..., None, :, :]  # (..., 1, 4, 4)
            local = np.einsum("...ji,...j->...i", pose[..., :3, :3], centres - pose[..., :3, 3])
            bound = point_signed_distance(ob.shape, local) - self._sphere_radii
            per_solid = np.full((*batch, self.n_solids), np.inf)
            np.minimum.at(
                per_solid.reshape(-1, self.n_solids),
                (slice(None), self._sphere_owner),
                bound.reshape(-1, bound.shape[-1]),
            )
            lower[..., o] = per_solid
        return lower

    def _narrow(self, solid_pose: np.ndarray, obstacle_pose: np.ndarray, s: int, o: int) -> float:
        """Exact signed distance [m] of solid ``s`` and obstacle ``o`` at the given poses."""
        tf_solid, tf_obstacle = self._tf
        tf_solid.setRotation(solid_pose[:3, :3])
        tf_solid.setTranslation(solid_pose[:3, 3])
        tf_obstacle.setRotation(obstacle_pose[:3, :3])
        tf_obstacle.setTranslation(obstacle_pose[:3, 3])
        self._result.clear()
        return self._functors[s][o](tf_solid, tf_obstacle, self._request, self._result)

    def _min_distances(self, q: np.ndarray, t: np.ndarray) -> MinDistances:
        batch, n_t = q.shape[:-2], q.shape[-2]
        solid_poses = self.robot.geometry_poses(q)  # (..., n_t, n_solids, 4, 4)
        obstacle_poses = self._obstacle_poses(t)  # (n_obs, ..., n_t, 4, 4)
        lower = self._lower_bounds(solid_poses, obstacle_poses)
        n_motions = int(np.prod(batch))
        lower = lower.reshape(n_motions, n_t * self.n_solids, self.n_obstacles)
        flat_s = solid_poses.reshape(n_motions * n_t, self.n_solids, 4, 4)
        flat_o = obstacle_poses.reshape(self.n_obstacles, n_motions * n_t, 4, 4)
        best = lower.min(axis=1)  # (n_motions, n_obs): a bound until improved below
        where = np.full(best.shape, -1)
        calls = 0
        for m, o in zip(*np.nonzero(best <= self.influence)):
            bounds = lower[m, :, o]
            order = np.argsort(bounds, kind="stable")
            value = np.inf
            for c in order[bounds[order] <= self.influence]:
                # A positive bound is a true lower bound (the solids are apart by at least
                # that much); a bound ≤ 0 says nothing about the penetration depth.
                if bounds[c] > 0.0 and bounds[c] >= value:
                    break
                k, s = divmod(int(c), self.n_solids)
                d = self._narrow(flat_s[m * n_t + k, s], flat_o[o, m * n_t + k], s, o)
                calls += 1
                if d < value:
                    value, where[m, o] = d, c
            best[m, o] = value if np.isfinite(value) else best[m, o]
        sample = np.where(where >= 0, where // self.n_solids, -1)
        solid = np.where(where >= 0, where % self.n_solids, -1)
        shape = (*batch, self.n_obstacles)
        return MinDistances(
            distance=best.reshape(shape),
            sample=sample.reshape(shape),
            solid=solid.reshape(shape),
            n_narrow=calls,
        )

    def _distances(self, q: np.ndarray, t: np.ndarray, exact: bool) -> PairDistances:
        solid_poses = self.robot.geometry_poses(q)  # (..., n_t, n_solids, 4, 4)
        obstacle_poses = self._obstacle_poses(t)  # (n_obs, ..., n_t, 4, 4)
        distance = self._lower_bounds(solid_poses, obstacle_poses)
        todo = np.ones(distance.shape, bool) if exact else distance <= self.influence
        flat_d = distance.reshape(-1, self.n_solids, self.n_obstacles)
        flat_s = solid_poses.reshape(-1, self.n_solids, 4, 4)
        flat_o = obstacle_poses.reshape(self.n_obstacles, -1, 4, 4)
        samples, solids, obstacles = np.nonzero(todo.reshape(flat_d.shape))
        for n, s, o in zip(samples.tolist(), solids.tolist(), obstacles.tolist()):
            flat_d[n, s, o] = self._narrow(flat_s[n, s], flat_o[o, n], s, o)
        return PairDistances(distance=distance, exact=todo, n_narrow=len(samples))


def paper_penalty(
    points: Any,
    centres: Any,
    semi_axes: Any,
) -> np.ndarray:
    r"""The paper's collision penalty :math:`f_{dis}` (eqs. 13–16), batched.

    Each obstacle is replaced by a circumscribing sphere (``semi_axes`` all equal to
    :math:`r_0`) or axis-aligned ellipsoid (semi-axes a, b, c); a trajectory point inside
    it penalises the motion:

    .. math::
        r_e = \sum_k \frac{(x_k - x_{0,k})^2}{a_k^2}, \qquad
        f_{dis} = \sum_{o:\ \min_t r_{e,o} \le 1} \frac{1}{(\min_t r_{e,o})^2}

    (for a sphere :math:`r_e = (r_t / r_0)^2`; eq. 14 divides by :math:`(\min r_t)^2`
    instead, which differs from eq. 16 only by the constant :math:`r_0^{-2}` per obstacle;
    we use eq. 16's normalised form for both).

    Parameters
    ----------
    points:
        (..., n_t, 3) trajectory points (the tool) [m].
    centres:
        (n_obs, ..., n_t, 3) obstacle centres at the same times [m] (broadcastable).
    semi_axes:
        (n_obs, 3) semi-axes [m].

    Returns
    -------
    numpy.ndarray
        (...) penalty [-], 0 when no point enters any circumscribing volume.
    """
    p = as_finite_array(points, "points")
    c = as_finite_array(centres, "centres")
    ax = as_finite_array(semi_axes, "semi_axes")
    if ax.ndim != 2 or ax.shape[1] != 3 or (ax <= 0).any():
        raise InvalidInputError(f"semi_axes must be (n_obs, 3) positive [m]; got {ax.shape}")
    if p.shape[-1] != 3 or c.shape[-1] != 3 or c.shape[0] != ax.shape[0]:
        raise InputShapeError(
            f"points (..., n_t, 3) and centres (n_obs, ..., n_t, 3) expected; got {p.shape}, "
            f"{c.shape} with {ax.shape[0]} obstacles"
        )
    scaled = (p[None] - c) / ax.reshape(ax.shape[0], *([1] * (c.ndim - 2)), 3)
    r_e = np.min(np.sum(scaled**2, axis=-1), axis=-1)  # (n_obs, ...)
    inside = r_e <= 1.0
    return np.sum(np.where(inside, 1.0 / np.maximum(r_e, 1e-12) ** 2, 0.0), axis=0)
