"""Signed distances between the robot's link solids and the scene's obstacles over time.

:class:`CollisionChecker` gives, for configurations ``q`` (..., n_t, nq) at times ``t``
(..., n_t) [s], the signed distance [m] between **every** robot solid and **every** obstacle
(moving obstacles at their pose at that time; negative = penetration depth), using coal.

The broad phase (:mod:`adept_traj.collision.broad_phase`, numpy, batched) gives a lower bound of
every distance, exact for sphere obstacles (closed form) and static pairs. Only pairs whose
bound is ≤ ``influence`` go to coal (narrow phase, one call per close pair: the only Python
loop, over close pairs, never over all samples). The other entries hold a lower bound
greater than ``influence``: every quantity built from distances below ``influence`` (the
constraint, the clearance penalty) is therefore exact.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import coal
import numpy as np

from adept_traj.collision.branch_and_bound import search_pairs
from adept_traj.collision.broad_phase import BroadPhase
from adept_traj.collision.cloud_distance import CloudDistance
from adept_traj.collision.cloud_search import SearchSamples, cloud_obstacles
from adept_traj.collision.distance_table import DistanceTable
from adept_traj.collision.exact_distances import exact_distances
from adept_traj.collision.mesh_distance import distance_functor
from adept_traj.collision.primitives import distance_request
from adept_traj.collision.pruning import ObstaclePruning, restrict_checker
from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.robot.kinematics import stack_times
from adept_traj.robot.robot import Robot
from adept_traj.scene.scene import Scene
from adept_traj.validation import as_finite_array

__all__ = ["CollisionChecker", "MinDistances", "PairDistances"]


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
        (..., n_obstacles) int, where the smallest exact distance was found (-1 if the
        distance is only a lower bound above ``influence``).
    n_narrow:
        Number of coal distance calls made.
    """

    distance: np.ndarray
    sample: np.ndarray
    solid: np.ndarray
    n_narrow: int


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
    start_time:
        Scene time t0 [s] of the motion's time 0 (default 0): the obstacles are placed at
        scene time :math:`t_0 + t` for the times ``t`` the methods are given (finite, ≥ 0).
    tables:
        Single-joint distance tables already made for this robot and scene, taken instead
        of computed (:func:`~adept_traj.collision.joint_tables.kept_tables`).
    """

    def __init__(
        self,
        robot: Robot,
        scene: Scene,
        influence: float = 0.05,
        start_time: float = 0.0,
        tables: Mapping[tuple[int, int], DistanceTable] | None = None,
    ) -> None:
        if not (np.isfinite(influence) and influence >= 0):
            raise InvalidInputError(f"influence must be a finite distance ≥ 0 [m]; got {influence}")
        if not (np.isfinite(start_time) and start_time >= 0):
            raise InvalidInputError(
                f"start_time must be a finite scene time ≥ 0 [s]; got {start_time}"
            )
        self.robot, self.scene, self.influence = robot, scene, float(influence)
        #: Scene time [s] of the motion's time 0.
        self.start_time = float(start_time)
        objects = robot.collision_model.geometryObjects
        self.solid_names = tuple(g.name for g in objects)
        self.obstacle_names = tuple(ob.name for ob in scene.obstacles)
        #: The :class:`~adept_traj.collision.broad_phase.BroadPhase`: the solids' and
        #: obstacles' conservative bounds (read by the branch and bound and the gradients).
        self.broad_phase = BroadPhase(robot, scene, self.influence, tables)
        # Allowed contacts (scene.allowed_contacts: link, obstacle): never checked.
        links = [robot.model.frames[g.parentFrame].name for g in objects]
        pairs = [
            (link, ob) in scene.allowed_contacts for link in links for ob in self.obstacle_names
        ]
        self.allowed = np.array(pairs, dtype=bool).reshape(len(objects), len(self.obstacle_names))
        self._robot_geoms = [g.geometry for g in objects]
        shapes = self.broad_phase.obstacle_shape  # a closed mesh's functor tests the inside too
        #: coal's distance functors, ``functors[s][o]`` for solid s and obstacle o.
        self.functors = [
            [
                distance_functor(g, o, sh, self.influence)
                for o, sh in zip(self.broad_phase.obstacle_geometry, shapes)
            ]
            for g in self._robot_geoms
        ]
        self._request = distance_request()
        self._result = coal.DistanceResult()
        self._tf = (coal.Transform3s(), coal.Transform3s())
        self._pruning = ObstaclePruning(scene, self.influence)
        #: The base pose of each fixed obstacle (None: moving), formed once.
        self._to_base = to_base = scene.base_from_world
        self._fixed_poses = [
            None if ob.is_moving else to_base @ ob.pose(0.0) for ob in scene.obstacles
        ]
        self._law_of = shared_motion_laws(scene)
        self._views: dict[tuple[int, ...], CollisionChecker] = {}  # by obstacles kept

    @property
    def solid_shapes(self) -> tuple[object | None, ...]:
        """The robot solids as :mod:`adept_traj.scene.shapes` objects (``None``: not a
        primitive)."""
        return tuple(self.broad_phase.solid_shape)

    @property
    def closed_form(self) -> np.ndarray:
        """(n_solids, n_obstacles) bool: pairs whose distance is computed in closed form
        (a sphere obstacle and a primitive solid) instead of by coal."""
        return self.broad_phase.closed_form.copy()

    @property
    def static_pairs(self) -> np.ndarray:
        """(n_solids, n_obstacles) bool: pairs of a solid fixed to the base and a fixed
        obstacle, whose constant distance is computed once (at construction)."""
        return self.broad_phase.static.copy()

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

        With ``exact=True`` every pair is computed exactly: by coal, in closed form for a
        sphere obstacle, once for a static pair (for verification).
        """
        qa, ta = self.checked_motion(q, t)
        return self._distances(qa, ta, exact)

    def checked_motion(self, q: Any, t: Any) -> tuple[np.ndarray, np.ndarray]:
        """``q`` (..., n_t, nq) [rad | m] and ``t`` [s] as float arrays, ``t`` broadcast to
        q's leading shape (..., n_t); :class:`~adept_traj.errors.InputShapeError` names a
        shape that does not fit."""
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

    def min_distances(self, q: Any, t: Any, joint_frames: np.ndarray | None = None) -> MinDistances:
        """Per motion and obstacle, the smallest solid–obstacle distance over all samples.

        ``q`` (..., n_t, nq) [rad | m] and ``t`` (..., n_t) [s]: the leading axes ``...``
        are motions (e.g. the population). Branch and bound: candidates (sample, solid)
        are computed by coal in increasing order of their broad-phase lower bound until the
        best exact distance is below the next bound, so the result is the exact minimum
        (when ≤ ``influence``, penetration depths included) with few coal calls.
        ``joint_frames`` (njoints, 3, 4, N), N = ∏ q.shape[:-1], may pass the robot's joint
        frames (:attr:`~adept_traj.robot.ForwardKinematics.joint_frames`) if already
        computed.
        """
        qa, ta = self.checked_motion(q, t)
        if joint_frames is None:
            joint_frames = self.robot.kinematics.joint_frames(qa)
        expected = (self.robot.model.njoints, 3, 4, ta.size)
        if np.shape(joint_frames) != expected:
            raise InputShapeError(
                f"joint_frames must have shape {expected} for q of shape {qa.shape}; "
                f"got {np.shape(joint_frames)}"
            )
        return self._min_distances(qa, ta, joint_frames)

    def scene_time(self, t: Any) -> np.ndarray:
        """Scene times :math:`t_0 + t` [s] of the motion's times ``t`` [s] (any shape; ``t``
        itself when :attr:`start_time` is 0)."""
        ta = np.asarray(t, dtype=float)
        return ta if self.start_time == 0.0 else ta + self.start_time

    # ------------------------------ parts the branch and bound and the distance gradients use
    def obstacle_poses(self, t: np.ndarray) -> list[np.ndarray]:
        """Obstacle poses in the robot base frame at the flattened motion times ``t`` (scene
        times :meth:`scene_time`): per obstacle one (4, 4) pose if it is fixed, else
        (N, 4, 4) with N = ``t.size``."""
        to_base = self._to_base
        flat_t = self.scene_time(t).reshape(-1)
        laws: dict[int, np.ndarray] = {}  # by the first obstacle of each motion law
        poses = []
        for ob, fixed, key in zip(self.scene.obstacles, self._fixed_poses, self._law_of):
            if fixed is not None:
                poses.append(fixed)
                continue
            if key not in laws:  # contiguous once, not in each product below
                laws[key] = np.ascontiguousarray(
                    _left(to_base, ob.motion.pose(flat_t).reshape(-1, 4, 4))
                )
            poses.append(stack_times(laws[key], ob.offset))  # = to_base @ ob.pose(t)
        return poses

    @staticmethod
    def pose_at(poses: np.ndarray, n: int) -> np.ndarray:
        """The (4, 4) pose at flat sample ``n`` of an :meth:`obstacle_poses` entry."""
        return poses if poses.ndim == 2 else poses[n]

    def narrow_distance(
        self,
        solid_pose: np.ndarray,
        obstacle_pose: np.ndarray,
        s: int,
        o: int,
        below: float | None = None,
    ) -> float:
        """Exact signed distance [m] of solid ``s`` and obstacle ``o`` at the given poses;
        with ``below`` [m], a distance not below it may come back as a lower bound ≥ it (a
        point cloud's narrow phase then does less work)."""
        tf_solid, tf_obstacle = self._tf
        tf_solid.setTransform(solid_pose[:3, :3], solid_pose[:3, 3])  # one call, not two
        tf_obstacle.setTransform(obstacle_pose[:3, :3], obstacle_pose[:3, 3])
        self._result.clear()
        functor = self.functors[s][o]
        if below is not None and isinstance(functor, CloudDistance):
            return functor(tf_solid, tf_obstacle, self._request, self._result, below)
        return functor(tf_solid, tf_obstacle, self._request, self._result)

    def _min_distances(self, q: np.ndarray, t: np.ndarray, frames: np.ndarray) -> MinDistances:
        """Leave out the fixed obstacles that no motion comes within ``influence`` of
        (:mod:`adept_traj.collision.pruning`: their distance is reported as the bound that
        proves it), then search the others (:meth:`_search`)."""
        n_motions = int(np.prod(q.shape[:-2]))
        centres = self.broad_phase.ball_centres(frames)  # for the pruning and the broad phase
        far = self._pruning.lower_bounds(centres, self.broad_phase.ball_radius, n_motions)
        keep = self._pruning.kept(far)
        part = self._restricted(keep)._search(q, t, frames, centres)
        out = [far.copy(), np.full(far.shape, -1), np.full(far.shape, -1)]
        near = far[:, keep] <= self.influence  # else the motion's own bound, as if pruned
        for full, kept in zip(out, (part.distance, part.sample, part.solid)):
            full[:, keep] = np.where(near, kept.reshape(len(far), -1), full[:, keep])
        shape = (*q.shape[:-2], self.n_obstacles)
        return MinDistances(*(a.reshape(shape) for a in out), n_narrow=part.n_narrow)

    def _restricted(self, keep: np.ndarray) -> CollisionChecker:
        """This checker on the obstacles of index ``keep`` only (the last 32 sets kept)."""
        key = tuple(keep.tolist())
        if len(key) == self.n_obstacles:
            return self
        view = self._views.get(key)
        if view is None:
            if len(self._views) >= 32:  # a batch of motions usually meets the same few
                self._views.clear()
            view = self._views[key] = restrict_checker(self, keep)
        return view

    def _search(self, q: np.ndarray, t: np.ndarray, frames: np.ndarray, balls: Any = None) -> Any:
        """The branch and bound of :meth:`min_distances` over every obstacle
        (:func:`~adept_traj.collision.branch_and_bound.search_pairs`; ``balls``:
        :meth:`BroadPhase.ball_centres` of ``frames``, or None); a :class:`MinDistances`."""
        batch, n_t = q.shape[:-2], q.shape[-2]
        n_motions = int(np.prod(batch))
        obstacle_poses = self.obstacle_poses(t)
        q_flat = q.reshape(-1, q.shape[-1])
        searched = cloud_obstacles(self)  # their leaves bounded by the search, not level 5
        bounds = self.broad_phase.bounds(frames, obstacle_poses, q_flat, balls, ~searched)
        lower, known = bounds.lower, bounds.exact
        if self.allowed.any():  # else no pass over the whole arrays
            lower, known = np.where(self.allowed, np.inf, lower), known | self.allowed
        flat = (n_motions, n_t * self.n_solids, self.n_obstacles)
        lower, known = lower.reshape(flat), known.reshape(flat)
        samples = SearchSamples(self, frames, obstacle_poses, n_t)
        best, where, calls = search_pairs(samples, lower, known)
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
        frames = self.robot.kinematics.joint_frames(q)  # (njoints, 3, 4, N)
        obstacle_poses = self.obstacle_poses(t)
        broad = self.broad_phase
        if exact:
            flat_d = exact_distances(self, frames, obstacle_poses)
            shape = (*q.shape[:-1], self.n_solids, self.n_obstacles)
            n_coal = int((~(broad.static | broad.closed_form | self.allowed)).sum())
            return PairDistances(
                distance=flat_d.reshape(shape),
                exact=np.ones(shape, dtype=bool),
                n_narrow=n_coal * frames.shape[-1],
            )
        bounds = broad.bounds(frames, obstacle_poses, q.reshape(-1, q.shape[-1]))
        flat_d, known = bounds.lower, bounds.exact | self.allowed
        todo = (flat_d <= self.influence) & ~known
        flat_d[:, self.allowed] = np.inf
        samples, solids, obstacles = np.nonzero(todo)
        for c in range(0, len(samples), 8192):  # solid poses in batches (1 MB), not per call
            cut = [a[c : c + 8192] for a in (samples, solids, obstacles)]
            poses = self.broad_phase.solid_poses(frames, cut[0], cut[1])
            for pose, n, s, o in zip(poses, *(a.tolist() for a in cut)):
                flat_d[n, s, o] = self.narrow_distance(
                    pose, self.pose_at(obstacle_poses[o], n), s, o
                )
        known |= todo
        shape = (*q.shape[:-1], self.n_solids, self.n_obstacles)
        return PairDistances(
            distance=flat_d.reshape(shape), exact=known.reshape(shape), n_narrow=len(samples)
        )


def _left(a: np.ndarray, poses: np.ndarray) -> np.ndarray:
    """``a @ poses`` for a constant (4, 4) ``a`` and poses (N, 4, 4), as one GEMM (numpy's
    stacked product of small matrices is several times slower)."""
    return (poses.transpose(0, 2, 1).reshape(-1, 4) @ a.T).reshape(-1, 4, 4).transpose(0, 2, 1)


def shared_motion_laws(scene: Scene) -> tuple[int, ...]:
    """Per obstacle of ``scene``, the index of the first obstacle with an equal motion law
    (a pendulum's rod and bob share one): the poses of each law are computed once per call.

    Parameters
    ----------
    scene:
        The (frozen) scene.

    Returns
    -------
    tuple of int
        (n_obstacles,): its own index for a fixed obstacle and for the first obstacle of
        each law.
    """
    first: dict[Any, int] = {}
    out = []
    for i, ob in enumerate(scene.obstacles):
        try:
            out.append(first.setdefault(ob.motion, i) if ob.is_moving else i)
        except TypeError:  # a law that cannot be hashed: its own
            out.append(i)
    return tuple(out)
