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
        (..., n_t, n_solids, n_obstacles) bool, where the distance is exact (computed by
        coal, or in closed form for a sphere obstacle).
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


#: Subtracted from the separating-axis bound, which can equal the exact distance: keeps it
#: a lower bound under rounding (coal's own results are exact to about 1e-15 m here).
_ROUNDING = 1e-9


def _half_extent(kind: str, dims: np.ndarray, n_local: np.ndarray) -> np.ndarray:
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


def _coal_kind(geometry: coal.CollisionGeometry) -> tuple[str, np.ndarray] | None:
    """(kind, dims) of a coal primitive for :func:`_half_extent`, or None (no bound)."""
    if isinstance(geometry, coal.Box):
        return "box", np.array(geometry.halfSide)
    if isinstance(geometry, coal.Cylinder):
        return "cylinder", np.array([geometry.radius, geometry.halfLength])
    if isinstance(geometry, coal.Capsule):
        return "capsule", np.array([geometry.radius, geometry.halfLength])
    if isinstance(geometry, coal.Sphere):
        return "sphere", np.array([geometry.radius])
    return None


def _shape_of(kind: tuple[str, np.ndarray] | None) -> object | None:
    """The :mod:`adept_traj.shapes` shape of a coal primitive (for point distances)."""
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


def _enclosing_ball(geometry: coal.CollisionGeometry) -> tuple[np.ndarray, float]:
    """Centre (3,) in the geometry frame and radius of a ball containing the geometry (the
    ball around its local bounding box)."""
    geometry.computeLocalAABB()
    lo = np.array(geometry.aabb_local.min_)
    hi = np.array(geometry.aabb_local.max_)
    return 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo))


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
        covers = [_covering_spheres(g.geometry) for g in objects]
        self._sphere_local = [c for c, _ in covers]  # per solid: (k, 3) in the solid's frame
        self._sphere_radii = [r for _, r in covers]  # per solid: (k,)
        balls = [_enclosing_ball(g.geometry) for g in objects]
        self._ball_centre = np.array([c for c, _ in balls])  # (n_solids, 3)
        self._ball_radius = np.array([r for _, r in balls])  # (n_solids,)
        self._solid_kind = [_coal_kind(g.geometry) for g in objects]
        self._solid_shape = [_shape_of(kind) for kind in self._solid_kind]
        #: Sphere obstacles: exact distance to any primitive solid in closed form (numpy).
        self._closed_form = np.array(
            [
                [isinstance(ob.shape, Sphere) and shape is not None for ob in scene.obstacles]
                for shape in self._solid_shape
            ],
            dtype=bool,
        ).reshape(len(objects), len(scene.obstacles))
        self._robot_geoms = [g.geometry for g in objects]
        self._obstacle_geoms = [ob.shape.to_coal() for ob in scene.obstacles]
        self._obstacle_kind = [_coal_kind(geom) for geom in self._obstacle_geoms]
        self._functors = [
            [coal.ComputeDistance(g, o) for o in self._obstacle_geoms] for g in self._robot_geoms
        ]
        self._request = coal.DistanceRequest()
        self._result = coal.DistanceResult()
        self._tf = (coal.Transform3s(), coal.Transform3s())

    @property
    def solid_shapes(self) -> tuple[object | None, ...]:
        """The robot solids as :mod:`adept_traj.shapes` objects (``None`` if not a primitive)."""
        return tuple(self._solid_shape)

    @property
    def closed_form(self) -> np.ndarray:
        """(n_solids, n_obstacles) bool: pairs whose distance is computed in closed form
        (a sphere obstacle and a primitive solid) instead of by coal."""
        return self._closed_form.copy()

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

    def min_distances(self, q: Any, t: Any, solid_poses: np.ndarray | None = None) -> MinDistances:
        """Per motion and obstacle, the smallest solid–obstacle distance over all samples.

        ``q`` (..., n_t, nq) [rad | m] and ``t`` (..., n_t) [s]: the leading axes ``...``
        are motions (e.g. the population). Branch and bound: candidates (sample, solid)
        are computed by coal in increasing order of their broad-phase lower bound until the
        best exact distance is below the next bound, so the result is the exact minimum
        (when ≤ ``influence``, penetration depths included) with few coal calls.
        ``solid_poses`` (..., n_t, n_solids, 4, 4) may pass the robot's
        :meth:`~adept_traj.robot.Robot.geometry_poses` if already computed.
        """
        qa, ta = self._check(q, t)
        if solid_poses is None:
            solid_poses = self.robot.geometry_poses(qa)
        return self._min_distances(qa, ta, solid_poses)

    # ------------------------------------------------------------------ private hooks
    def _obstacle_poses(self, t: np.ndarray) -> list[np.ndarray]:
        """Obstacle poses in the robot base frame at the flattened times ``t``: per obstacle
        one (4, 4) pose if it is fixed, else (N, 4, 4) with N = ``t.size``."""
        to_base = self.scene.base_from_world
        flat_t = t.reshape(-1)
        return [
            to_base @ ob.pose(0.0) if not ob.is_moving else to_base @ ob.pose(flat_t)
            for ob in self.scene.obstacles
        ]

    def _lower_bounds(self, solid_poses: np.ndarray, obstacle_poses: list[np.ndarray]):
        """(N, n_solids, n_obs) broad-phase lower bounds [m], valid in every case, for the
        flattened solid poses (N, n_solids, 4, 4).

        Level 1: the ball enclosing each solid gives :math:`d(c, B) - R`, a lower bound of
        the signed distance even under penetration. Level 2, only where level 1 is within
        ``influence``: the covering spheres give a tighter bound, used when positive (a
        positive bound proves separation by at least that much).
        """
        balls = (solid_poses[..., :3, :3] @ self._ball_centre[..., None])[..., 0]
        balls += solid_poses[..., :3, 3]  # (N, n_solids, 3)
        lower = np.empty((solid_poses.shape[0], self.n_solids, self.n_obstacles))
        closed_all = self._closed_form.all(axis=0)
        for o, ob in enumerate(self.scene.obstacles):
            if closed_all[o]:
                continue  # exact values follow (_sphere_obstacle_distances)
            pose = obstacle_poses[o]  # (4, 4) or (N, 4, 4)
            # Row-vector form of R^T (c - t): (c - t) R; one product for a fixed obstacle.
            local = (balls - pose[..., None, :3, 3]) @ pose[..., :3, :3]
            lower[..., o] = point_signed_distance(ob.shape, local) - self._ball_radius
        self._sphere_obstacle_distances(lower, solid_poses, obstacle_poses)
        close = (lower <= self.influence) & ~self._closed_form
        for k, centres in enumerate(self._sphere_local):
            if len(centres) == 1:
                continue  # the covering sphere is the enclosing ball
            for o, ob in enumerate(self.scene.obstacles):
                idx = np.flatnonzero(close[:, k, o])
                if idx.size == 0:
                    continue
                ps = solid_poses[idx, k]
                po = obstacle_poses[o] if obstacle_poses[o].ndim == 2 else obstacle_poses[o][idx]
                world = np.swapaxes(ps[:, :3, :3] @ centres.T, -1, -2) + ps[:, None, :3, 3]
                local = (world - po[..., None, :3, 3]) @ po[..., :3, :3]
                cover = (point_signed_distance(ob.shape, local) - self._sphere_radii[k]).min(-1)
                lower[idx, k, o] = np.where(cover > 0.0, np.maximum(cover, lower[idx, k, o]),
                                            lower[idx, k, o])  # fmt: skip
        self._separating_axis_bounds(lower, solid_poses, obstacle_poses)
        return lower

    def _sphere_obstacle_distances(
        self, lower: np.ndarray, solid_poses: np.ndarray, obstacle_poses: list[np.ndarray]
    ) -> None:
        """In place: the exact signed distance between a primitive solid A and a sphere
        obstacle (centre c, radius r), :math:`d(c, A) - r`, for every sample (closed form;
        it also avoids coal 3.0.3's wrong sphere–cylinder penetration depth near a cap)."""
        for o, ob in enumerate(self.scene.obstacles):
            if not isinstance(ob.shape, Sphere):
                continue
            centre = obstacle_poses[o][..., :3, 3]  # (3,) or (N, 3)
            for k, shape in enumerate(self._solid_shape):
                if shape is None:
                    continue
                ps = solid_poses[:, k]
                local = ((centre - ps[:, :3, 3])[:, None, :] @ ps[:, :3, :3])[:, 0]
                lower[:, k, o] = point_signed_distance(shape, local) - ob.shape.radius

    def _separating_axis_bounds(
        self, lower: np.ndarray, solid_poses: np.ndarray, obstacle_poses: list[np.ndarray]
    ) -> None:
        """Level 3, in place, where ``lower`` is still within ``influence``: the gap between
        the projections of solid and obstacle on the obstacle's axes and on the line joining
        their centres. A positive gap along any unit axis is a lower bound of the distance;
        for a SCARA solid hovering over a box it is the exact distance."""
        close = (lower <= self.influence) & ~self._closed_form
        for k, kind_s in enumerate(self._solid_kind):
            for o, kind_o in enumerate(self._obstacle_kind):
                idx = np.flatnonzero(close[:, k, o])
                if idx.size == 0 or kind_s is None or kind_o is None:
                    continue
                ps = solid_poses[idx, k]
                po = obstacle_poses[o] if obstacle_poses[o].ndim == 2 else obstacle_poses[o][idx]
                rot_o = np.broadcast_to(po[..., :3, :3], (idx.size, 3, 3))
                delta = ps[:, :3, 3] - po[..., :3, 3]
                norm = np.linalg.norm(delta, axis=-1, keepdims=True)
                towards = np.divide(delta, norm, out=np.zeros_like(delta), where=norm > 0)
                axes = np.concatenate([np.swapaxes(rot_o, -1, -2), towards[:, None]], axis=1)
                n_s = axes @ ps[:, :3, :3]  # rows: axes in the solid frame (…, 4, 3)
                n_o = axes @ rot_o  # axes in the obstacle frame
                gap = (
                    np.abs(np.einsum("nai,ni->na", axes, delta))
                    - _ROUNDING
                    - _half_extent(*kind_s, n_s)
                    - _half_extent(*kind_o, n_o)
                ).max(axis=-1)
                lower[idx, k, o] = np.where(gap > 0.0, np.maximum(gap, lower[idx, k, o]),
                                            lower[idx, k, o])  # fmt: skip

    @staticmethod
    def _pose_at(poses: np.ndarray, n: int) -> np.ndarray:
        return poses if poses.ndim == 2 else poses[n]

    def _narrow(self, solid_pose: np.ndarray, obstacle_pose: np.ndarray, s: int, o: int) -> float:
        """Exact signed distance [m] of solid ``s`` and obstacle ``o`` at the given poses."""
        tf_solid, tf_obstacle = self._tf
        tf_solid.setRotation(solid_pose[:3, :3])
        tf_solid.setTranslation(solid_pose[:3, 3])
        tf_obstacle.setRotation(obstacle_pose[:3, :3])
        tf_obstacle.setTranslation(obstacle_pose[:3, 3])
        self._result.clear()
        return self._functors[s][o](tf_solid, tf_obstacle, self._request, self._result)

    def _min_distances(self, q: np.ndarray, t: np.ndarray, solid_poses: np.ndarray) -> MinDistances:
        batch, n_t = q.shape[:-2], q.shape[-2]
        n_motions = int(np.prod(batch))
        flat_s = solid_poses.reshape(n_motions * n_t, self.n_solids, 4, 4)
        obstacle_poses = self._obstacle_poses(t)
        lower = self._lower_bounds(flat_s, obstacle_poses)
        lower = lower.reshape(n_motions, n_t * self.n_solids, self.n_obstacles)
        best = lower.min(axis=1)  # (n_motions, n_obs): a bound until improved below
        where = np.full(best.shape, -1)
        closed = self._closed_form.all(axis=0)  # (n_obs,): every pair exact already
        where[:, closed] = lower[:, :, closed].argmin(axis=1)
        calls = 0
        for m, o in zip(*np.nonzero((best <= self.influence) & ~closed)):
            bounds = lower[m, :, o]
            near = np.flatnonzero(bounds <= self.influence)
            value = np.inf
            for c in near[np.argsort(bounds[near], kind="stable")]:
                if bounds[c] >= value:  # every bound is a valid lower bound: prune the rest
                    break
                k, s = divmod(int(c), self.n_solids)
                n = m * n_t + k
                if self._closed_form[s, o]:
                    d = float(bounds[c])  # exact already
                else:
                    d = self._narrow(flat_s[n, s], self._pose_at(obstacle_poses[o], n), s, o)
                    calls += 1
                if d < value:
                    value, where[m, o] = d, c
            if value > self.influence:
                # Not exact: candidates with a bound in (influence, value) were not computed;
                # the smallest of value and those bounds is a lower bound above influence.
                value = min(value, bounds.min(initial=np.inf, where=bounds > self.influence))
            best[m, o] = value
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
        obstacle_poses = self._obstacle_poses(t)
        flat_s = solid_poses.reshape(-1, self.n_solids, 4, 4)
        flat_d = self._lower_bounds(flat_s, obstacle_poses)
        todo = np.ones(flat_d.shape, bool) if exact else flat_d <= self.influence
        todo &= ~self._closed_form  # sphere obstacles: exact in closed form already
        samples, solids, obstacles = np.nonzero(todo)
        for n, s, o in zip(samples.tolist(), solids.tolist(), obstacles.tolist()):
            flat_d[n, s, o] = self._narrow(flat_s[n, s], self._pose_at(obstacle_poses[o], n), s, o)
        shape = (*solid_poses.shape[:-2], self.n_obstacles)
        known = todo | self._closed_form
        distance, known = flat_d.reshape(shape), known.reshape(shape)
        return PairDistances(distance=distance, exact=known, n_narrow=len(samples))


def paper_penalty(
    points: Any,
    centres: Any,
    semi_axes: Any,
    *,
    rotations: Any = None,
    equation: int = 16,
) -> np.ndarray:
    r"""The paper's collision penalty :math:`f_{dis}` (eqs. 13–16), batched.

    Each obstacle is replaced by a circumscribing sphere of radius :math:`r_0` or an
    ellipsoid with semi-axes a, b, c (in the obstacle's own axes); a trajectory point inside
    it penalises the motion. Eq. 14 (spheres, ``equation=14``; the semi-axes must be equal):

    .. math::
        r_t = \lVert x - x_0 \rVert, \qquad
        f_{dis} = \sum_{o:\ \min_t r_{t,o} \le r_{0,o}} \frac{1}{(\min_t r_{t,o})^2}

    Eq. 16 (ellipsoids, ``equation=16``), with :math:`u = R_o^\top (x - x_0)` the point in
    the obstacle's axes:

    .. math::
        r_e = \sum_k \frac{u_k^2}{a_k^2}, \qquad
        f_{dis} = \sum_{o:\ \min_t r_{e,o} \le 1} \frac{1}{(\min_t r_{e,o})^2}

    Parameters
    ----------
    points:
        (..., n_t, 3) trajectory points (the tool) [m].
    centres:
        (n_obs, ..., n_t, 3) obstacle centres at the same times [m] (broadcastable).
    semi_axes:
        (n_obs, 3) semi-axes [m] (:math:`r_0` three times for a sphere).
    rotations:
        (n_obs, ..., n_t, 3, 3) obstacle orientations (columns: the obstacle's axes in the
        points' frame), aligned like ``centres``; ``None``: axis-aligned.
    equation:
        14 or 16 (see above).

    Returns
    -------
    numpy.ndarray
        (...) penalty [m⁻² for eq. 14, dimensionless for eq. 16], 0 when no point enters any
        circumscribing volume.
    """
    p = as_finite_array(points, "points")
    c = as_finite_array(centres, "centres")
    ax = as_finite_array(semi_axes, "semi_axes")
    if equation not in (14, 16):
        raise InvalidInputError(f"equation must be 14 (spheres) or 16 (ellipsoids); got {equation}")
    if ax.ndim != 2 or ax.shape[1] != 3 or (ax <= 0).any():
        raise InvalidInputError(f"semi_axes must be (n_obs, 3) positive [m]; got {ax.shape}")
    if equation == 14 and not np.allclose(ax, ax[:, :1]):
        raise InvalidInputError("equation 14 needs spheres: equal semi-axes per obstacle")
    if p.ndim < 2 or p.shape[-1] != 3 or c.ndim < 2 or c.shape[-1] != 3:
        raise InputShapeError(
            f"points must be (..., n_t, 3) and centres (n_obs, ..., n_t, 3) [m]; got "
            f"{p.shape} and {c.shape}"
        )
    if c.shape[0] != ax.shape[0]:
        raise InputShapeError(f"centres has {c.shape[0]} obstacles but semi_axes has {ax.shape[0]}")
    # Align the centres' (..., n_t) with the points' from the right, after the obstacle axis.
    missing = p.ndim - (c.ndim - 1)
    if missing < 0:
        raise InputShapeError(
            f"centres {c.shape} has more batch axes than points {p.shape} (n_obs first)"
        )
    c = c.reshape(c.shape[0], *([1] * missing), *c.shape[1:])
    try:
        np.broadcast_shapes(p.shape, c.shape[1:])
    except ValueError:
        raise InputShapeError(
            f"centres (n_obs, ..., n_t, 3) must broadcast with points (..., n_t, 3); got "
            f"{c.shape} and {p.shape}"
        ) from None
    d = p[None] - c  # (n_obs, ..., n_t, 3)
    if rotations is not None:
        rot = as_finite_array(rotations, "rotations")
        if rot.shape[:1] != c.shape[:1] or rot.shape[-2:] != (3, 3):
            raise InputShapeError(
                f"rotations must be (n_obs, ..., n_t, 3, 3) like centres; got {rot.shape}"
            )
        rot = rot.reshape(rot.shape[0], *([1] * missing), *rot.shape[1:])
        d = (d[..., None, :] @ rot)[..., 0, :]  # R^T d as a row vector
    if equation == 14:
        r_t = np.min(np.linalg.norm(d, axis=-1), axis=-1)  # (n_obs, ...)
        inside = r_t <= ax[:, 0].reshape(-1, *([1] * (r_t.ndim - 1)))
        return np.sum(np.where(inside, 1.0 / np.maximum(r_t, 1e-12) ** 2, 0.0), axis=0)
    scaled = d / ax.reshape(ax.shape[0], *([1] * (c.ndim - 2)), 3)
    r_e = np.min(np.sum(scaled**2, axis=-1), axis=-1)  # (n_obs, ...)
    inside = r_e <= 1.0
    return np.sum(np.where(inside, 1.0 / np.maximum(r_e, 1e-12) ** 2, 0.0), axis=0)
