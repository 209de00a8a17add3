"""The broad phase: conservative lower bounds of solid–obstacle signed distances, batched.

:class:`BroadPhase` turns joint frames (njoints, 3, 4, N) (component-major, from
:meth:`~adept_traj.robot.kinematics.BatchKinematics.joint_frames`) and obstacle poses into an
(N, n_solids, n_obstacles) array of **lower bounds** of the signed distance [m] (negative =
penetration depth), valid in every case, exact where it says so. The narrow phase
(:class:`~adept_traj.collision.CollisionChecker`, coal) only needs the pairs whose bound is
within ``influence``.

Levels, each on the rows the previous one left within ``influence``:

0. **Static pairs** — a solid fixed to the base (the SCARA's column) and a fixed obstacle:
   the distance never changes; it is computed once (coal, or the closed form below) and
   is exact everywhere. A solid moved by **one joint only** (its parent joint hangs from
   the base: the SCARA's inner arm) and a fixed obstacle: a
   :class:`~adept_traj.collision.DistanceTable` of exact distances over that joint's
   range bounds the distance to within about 0.6 mm (when the configurations ``q`` are
   given); level 1 is then skipped for the pair, except at samples outside the table's
   grid. (Not for joints with an infinite or very long range, nor for sphere shapes, nor
   for obstacles farther than ``influence`` +
   :data:`~adept_traj.collision.joint_tables.TABLE_REACH` from the solid's sweep:
   :mod:`adept_traj.collision.joint_tables`.)
1. **Enclosing ball** of each solid (centre ``c``, radius ``R``), from the joint poses
   directly (no solid pose is formed for far samples):

   .. math:: d(\\text{solid}, B) \\ge d(c, B) - R

   with :func:`point_signed_distance` the exact signed distance of a point to a box,
   sphere, cylinder or capsule (a lower bound even under penetration).
2. **Sphere obstacles** (the pendulum's bob) against a primitive solid: the exact signed
   distance :math:`d(c_B, \\text{solid}) - r_B` in closed form (this also avoids coal 3.0.3's
   wrong sphere–cylinder penetration depth near a cap).
3. **Covering spheres**: the solid's bounding box cut into near-cubic pieces along its
   longest side, :math:`\\min_i d(c_i, B) - r_i`, kept where positive (a positive value
   proves separation by at least that much).
4. **Separating axes**: the gap between the projections of solid and obstacle on the
   obstacle's axes and on the line joining their centres; for a SCARA solid hovering over
   a box it is the exact distance. It is a lower bound under penetration too: the
   penetration depth of two convex shapes is the smallest overlap of their projections
   over all directions, so it is at most the overlap on any one axis,
   :math:`d \\ge \\max_u \\text{gap}_u` (this bounds deep candidates tightly, and the
   branch and bound computes few of them).
5. **Point clouds** (not 4): :mod:`adept_traj.collision.cloud_bounds` (or not: ``cloud_level``).

Everything is numpy on whole arrays; the Python loops run over solids and obstacles
(7 × 4 for the AdeptOne XL scene), never over samples. That is why it is kept rather than
coal's own broad phase (one configuration per call): on the 2 101 samples of a paper move
(58 828 pairs), ``CollisionChecker.distances`` with this broad phase makes 1 428 coal
calls, against one for every pair by coal (``exact=True``).
The closed-form point distances live in :mod:`adept_traj.collision.point_distance`, the
primitives' kinds, balls and projections in :mod:`adept_traj.collision.primitives`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import coal
import numpy as np

from adept_traj.collision.cloud_bounds import cloud_bound, cloud_samples
from adept_traj.collision.distance_table import DistanceTable, table_bounds
from adept_traj.collision.joint_tables import joint_tables
from adept_traj.collision.mesh_distance import distance_functor
from adept_traj.collision.point_distance import (
    obstacle_signed_distance,
    point_signed_distance,
    points_in_joint,
)
from adept_traj.collision.primitives import (
    coal_kind,
    covering_spheres,
    distance_request,
    enclosing_ball,
    half_extent,
    shape_of,
)
from adept_traj.errors import InvalidInputError
from adept_traj.robot.kinematics import compose, stack_times
from adept_traj.robot.robot import Robot, solid_frames
from adept_traj.scene.point_clouds import PointCloud
from adept_traj.scene.scene import Scene
from adept_traj.scene.shapes import Sphere

__all__ = ["Bounds", "BroadPhase"]

#: Subtracted from the separating-axis bound, which can equal the exact distance: keeps it
#: a lower bound under rounding (coal's own results are exact to about 1e-15 m here).
_ROUNDING = 1e-9


@dataclass(frozen=True)
class Bounds:
    """Broad-phase result for N samples.

    Attributes
    ----------
    lower:
        (N, n_solids, n_obstacles) lower bound of the signed distance [m]; the exact
        distance where ``exact``.
    exact:
        (N, n_solids, n_obstacles) bool: exact already (static pair, or a sphere obstacle in
        closed form); these need no coal call.
    """

    lower: np.ndarray
    exact: np.ndarray


class BroadPhase:
    """Lower bounds of every solid–obstacle distance (see the module docstring).

    Parameters
    ----------
    robot, scene:
        The robot's collision solids and the obstacles.
    influence:
        Distance [m] above which a bound needs no refinement (≥ 0).
    tables:
        Single-joint distance tables already made for this robot and these obstacles, by
        (solid, obstacle) index (e.g. another checker's,
        :func:`~adept_traj.collision.joint_tables.kept_tables`): each is taken instead of
        computed where this broad phase tabulates the pair over the same
        joint (their values depend on the solid, the obstacle and the base pose alone).
    """

    def __init__(
        self,
        robot: Robot,
        scene: Scene,
        influence: float,
        tables: Mapping[tuple[int, int], DistanceTable] | None = None,
    ) -> None:
        self.influence = float(influence)
        objects = robot.collision_model.geometryObjects
        self.n_solids, self.n_obstacles = len(objects), len(scene.obstacles)
        self.nq = robot.nq
        #: Parent joint of each solid (n_solids,) and its placement there (n_solids, 4, 4).
        self.parents, self.local = solid_frames(robot.collision_model)
        covers = [covering_spheres(g.geometry) for g in objects]
        #: Samples of each primitive solid's box for the point-cloud level (None: other
        #: geometry, or a scene without point clouds).
        has_clouds = any(isinstance(ob.shape, PointCloud) for ob in scene.obstacles)
        self.cloud_samples = [cloud_samples(g.geometry) if has_clouds else None for g in objects]
        self._cover_centres = [c for c, _ in covers]  # per solid: (k, 3), solid frame
        self._cover_radii = [r for _, r in covers]
        balls = [enclosing_ball(g.geometry) for g in objects]
        local_ball = np.array([c for c, _ in balls]).reshape(-1, 3)
        # Ball centres in the parent joint frame: one affine map per sample, no solid pose.
        self._ball_in_joint = (
            np.einsum("kij,kj->ki", self.local[:, :3, :3], local_ball) + self.local[:, :3, 3]
        )
        self._ball_radius = np.array([r for _, r in balls])
        #: Covering-sphere centres of each solid in its parent joint frame (k, 3).
        self._cover_in_joint = [
            c @ self.local[k, :3, :3].T + self.local[k, :3, 3]
            for k, c in enumerate(self._cover_centres)
        ]
        self._by_parent = [
            (int(p), np.flatnonzero(self.parents == p)) for p in np.unique(self.parents)
        ]
        self.solid_kind = [coal_kind(g.geometry) for g in objects]
        self.solid_shape = [shape_of(kind) for kind in self.solid_kind]
        self.obstacle_shape = [ob.shape for ob in scene.obstacles]
        self.obstacle_geometry = [ob.shape.to_coal() for ob in scene.obstacles]
        self.obstacle_kind = [coal_kind(g) for g in self.obstacle_geometry]
        self.moving = np.array([ob.is_moving for ob in scene.obstacles], dtype=bool)
        #: (n_solids, n_obstacles): sphere obstacle and primitive solid (closed form).
        self.closed_form = np.array(
            [
                [isinstance(shape, Sphere) and s is not None for shape in self.obstacle_shape]
                for s in self.solid_shape
            ],
            dtype=bool,
        ).reshape(self.n_solids, self.n_obstacles)
        #: (n_solids, n_obstacles): solid fixed to the base and fixed obstacle.
        self.static = (self.parents[:, None] == 0) & ~self.moving[None, :]
        self.static_distance = np.full((self.n_solids, self.n_obstacles), np.nan)
        to_base = scene.base_from_world
        for k, o in zip(*np.nonzero(self.static)):
            pose_o = to_base @ scene.obstacles[o].pose(0.0)
            self.static_distance[k, o] = self.exact_distance(
                self.local[k], pose_o, int(k), int(o), objects[int(k)].geometry
            )
        #: Single-joint distance tables by (solid, obstacle) (level 0).
        self.tables: dict[tuple[int, int], DistanceTable] = joint_tables(
            self, robot, scene, [g.geometry for g in objects], tables or {}
        )

    @property
    def ball_radius(self) -> np.ndarray:
        """(n_solids,) radii [m] of the solids' enclosing balls."""
        return self._ball_radius

    @property
    def ball_in_joint(self) -> np.ndarray:
        """(n_solids, 3) centres [m] of the solids' enclosing balls in their parent joint's
        frame."""
        return self._ball_in_joint

    def ball_centres(self, frames: np.ndarray) -> np.ndarray:
        """(3, n_solids, N) centres [m] of the solids' enclosing balls in the base frame,
        for joint frames (njoints, 3, 4, N) (component-major)."""
        balls = np.empty((3, self.n_solids, frames.shape[-1]))
        for p, ks in self._by_parent:
            run = ks[-1] - ks[0] == len(ks) - 1  # a run of solids: written in place
            out = balls[:, ks[0] : ks[-1] + 1] if run else None
            got = points_in_joint(frames[p].reshape(12, -1), self._ball_in_joint[ks], out=out)
            if not run:
                balls[:, ks] = got
        return balls

    # ------------------------------------------------------------------ exact pieces
    def closed_form_distance(
        self, solid_poses: np.ndarray, obstacle_poses: np.ndarray, k: int, o: int
    ) -> np.ndarray:
        """Exact signed distance (R,) [m] of primitive solid ``k`` (poses (R, 4, 4)) and
        sphere obstacle ``o`` (poses (4, 4) or (R, 4, 4)): :math:`d(c_B, A) - r_B`."""
        centre = obstacle_poses[..., :3, 3]
        delta = centre - solid_poses[:, :3, 3]  # (R, 3)
        local = np.einsum("ni,nij->nj", delta, solid_poses[:, :3, :3])  # R^T delta
        return point_signed_distance(self.solid_shape[k], local) - self.obstacle_shape[o].radius

    def exact_distance(
        self,
        solid_pose: np.ndarray,
        obstacle_pose: np.ndarray,
        k: int,
        o: int,
        geometry: coal.CollisionGeometry,
    ) -> float:
        """Exact signed distance [m] of one solid–obstacle pair (closed form or coal)."""
        if self.closed_form[k, o]:
            return float(self.closed_form_distance(solid_pose[None], obstacle_pose, k, o)[0])
        functor = distance_functor(
            geometry, self.obstacle_geometry[o], self.obstacle_shape[o], self.influence
        )
        tf_s = coal.Transform3s(solid_pose[:3, :3], solid_pose[:3, 3])
        tf_o = coal.Transform3s(obstacle_pose[:3, :3], obstacle_pose[:3, 3])
        return float(functor(tf_s, tf_o, distance_request(), coal.DistanceResult()))

    def solid_poses(self, frames: np.ndarray, rows: np.ndarray, k: int | np.ndarray) -> np.ndarray:
        """Poses (R, 4, 4) at the samples ``rows`` (R,) of the joint frames ``frames``
        (njoints, 3, 4, N) of solid ``k``, or of solid ``k[i]`` at ``rows[i]`` for ``k`` (R,)
        (formed in one batch per solid)."""
        pose = np.empty((len(rows), 4, 4))
        pose[..., 3, :] = (0.0, 0.0, 0.0, 1.0)
        solids = np.unique(k).tolist() if np.ndim(k) else [k]
        for s in solids:  # each solid's rows straight into their slots
            sel = np.flatnonzero(k == s) if np.ndim(k) else slice(None)
            top = compose(frames[self.parents[s]][..., rows[sel]], self.local[s])
            pose[sel, :3] = top.transpose(2, 0, 1)
        return pose

    # ------------------------------------------------------------------ bounds
    def bounds(
        self,
        frames: np.ndarray,
        obstacle_poses: list[np.ndarray],
        q: np.ndarray | None = None,
        centres: np.ndarray | None = None,
        cloud_level: bool | np.ndarray = True,
    ) -> Bounds:
        """Lower bounds for joint frames (njoints, 3, 4, N) (component-major) and obstacle
        poses in the base frame (per obstacle (4, 4) if fixed, else (N, 4, 4)); with the
        configurations ``q`` (N, nq) [rad | m], the single-joint tables are used too.
        ``centres`` (3, n_solids, N) [m] may pass the enclosing-ball centres if already
        computed (:meth:`ball_centres` of the same ``frames``). ``cloud_level`` (n_obstacles,)
        bool: the clouds given level 5 (the others: :mod:`~adept_traj.collision.cloud_search`)."""
        n = frames.shape[-1]
        for name, value, shape in (
            ("q", q, (n, self.nq)),
            ("centres", centres, (3, self.n_solids, n)),
        ):
            if value is not None and np.shape(value) != shape:
                raise InvalidInputError(f"{name} must have shape {shape}; got {np.shape(value)}")
        # Internally (n_solids, n_obstacles, N): samples innermost, for fast elementwise
        # work; ``exact`` (few entries) is written in the layout of the result directly.
        lower = np.empty((self.n_solids, self.n_obstacles, n))
        exact = np.zeros((n, self.n_solids, self.n_obstacles), dtype=bool)
        level5 = np.broadcast_to(cloud_level, (self.n_obstacles,))
        if self.n_obstacles and n:
            rows = {p: frames[p].reshape(12, n) for p, _ in self._by_parent}
            # Level 0 first; level 1 only for the pairs (and samples) it leaves open.
            static = self.static  # (n_solids, n_obstacles)
            lower[static] = self.static_distance[static][:, None]
            exact[:, static] = True
            done = static.copy()
            if q is not None:
                for (k, o), bound in table_bounds(self.tables, q).items():
                    lower[k, o] = bound
                    done[k, o] = True
            balls = self.ball_centres(frames) if centres is None else centres
            self._ball_bounds(lower, balls, obstacle_poses, done)
            close = lower <= self.influence
            close[static] = False
            for k, o in zip(*np.nonzero(close.any(axis=-1))):
                idx = np.flatnonzero(close[k, o])
                pose_o = obstacle_poses[o]
                po = pose_o if pose_o.ndim == 2 else pose_o[idx]
                if self.closed_form[k, o]:
                    ps = self.solid_poses(frames, idx, k)
                    lower[k, o, idx] = self.closed_form_distance(ps, po, k, o)
                    exact[idx, k, o] = True
                else:
                    sub, low = rows[self.parents[k]][:, idx], lower[k, o]
                    low[idx] = self._refine(low[idx], sub, frames, idx, po, k, o, level5[o])
        # (n_solids · n_obstacles, N) → (N, n_solids, n_obstacles): a 2-D transpose copies
        # about twice as fast as the 3-D one with few obstacles (as fast with many)
        flat = lower.reshape(self.n_solids * self.n_obstacles, n)
        return Bounds(flat.T.copy().reshape(n, self.n_solids, self.n_obstacles), exact)

    def _ball_bounds(
        self,
        lower: np.ndarray,
        balls: np.ndarray,
        obstacle_poses: list[np.ndarray],
        done: np.ndarray,
    ) -> None:
        """Level 1 in place (``lower`` (n_solids, n_obstacles, N)): enclosing balls (centres
        ``balls`` (3, n_solids, N)) against every obstacle, for the pairs not ``done``
        (n_solids, n_obstacles) by level 0 and for the samples where a table gave no bound
        (``-inf``: outside its grid)."""
        radius = self._ball_radius[:, None]
        for o, shape in enumerate(self.obstacle_shape):
            ks = np.flatnonzero(~done[:, o])
            if len(ks):
                # A contiguous run of solids is a view (no gather), the subtraction is in
                # place on the fresh distances, then one write into ``lower``.
                run = slice(ks[0], ks[-1] + 1) if ks[-1] - ks[0] == len(ks) - 1 else ks
                d = obstacle_signed_distance(shape, balls[:, run], obstacle_poses[o])
                d -= radius[run]
                lower[run, o] = d
            for k in np.flatnonzero(done[:, o] & ~self.static[:, o]):
                gap = np.flatnonzero(np.isneginf(lower[k, o]))
                if len(gap):
                    pose_o = obstacle_poses[o]  # fixed: tables are for fixed obstacles only
                    lower[k, o, gap] = (
                        obstacle_signed_distance(shape, balls[:, [k]][:, :, gap], pose_o)[0]
                        - radius[k]
                    )

    def _refine(
        self,
        bound: np.ndarray,
        rows: np.ndarray,
        frames: np.ndarray,
        idx: np.ndarray,
        po: np.ndarray,
        k: int,
        o: int,
        cloud_level: bool = True,
    ) -> np.ndarray:
        """Levels 3 and 4 (or 5) for solid ``k`` at the samples ``idx`` (its parent joint's frame
        as ``rows`` (12, R); all joint ``frames`` (njoints, 3, 4, N)) and obstacle ``o``
        (``po`` (4, 4) or (R, 4, 4)), from ``bound`` (R,)."""
        centres = self._cover_in_joint[k]
        if len(centres) > 1:
            points = points_in_joint(rows, centres)
            cover = obstacle_signed_distance(self.obstacle_shape[o], points, po).min(axis=0)
            cover -= self._cover_radii[k][0]  # equal radii
            bound = np.where(cover > 0.0, np.maximum(cover, bound), bound)
        kind_s, kind_o = self.solid_kind[k], self.obstacle_kind[o]
        still = np.flatnonzero(bound <= self.influence)
        if still.size and kind_o is None:  # a point cloud: level 5 (a mesh: as it is)
            return cloud_bound(self, bound, still, frames, idx, po, k, o) if cloud_level else bound
        if still.size == 0 or kind_s is None or kind_o is None:
            return bound
        ps = self.solid_poses(frames, idx[still], k)
        po = po if po.ndim == 2 else po[still]
        delta = ps[:, :3, 3] - po[..., :3, 3]
        norm = np.sqrt(np.einsum("ni,ni->n", delta, delta))[:, None]
        axes = np.zeros((still.size, 4, 3))  # the obstacle's axes, then the centre line
        axes[:, :3] = np.swapaxes(po[..., :3, :3], -1, -2)
        np.divide(delta, norm, out=axes[:, 3], where=norm > 0)
        n_s = axes @ ps[:, :3, :3]  # rows: axes in the solid frame (R, 4, 3)
        n_o = stack_times(axes, po[:3, :3]) if po.ndim == 2 else axes @ po[:, :3, :3]
        gaps = (
            np.abs(np.einsum("nai,ni->na", axes, delta))
            - _ROUNDING
            - half_extent(*kind_s, n_s)
            - half_extent(*kind_o, n_o)
        )
        gaps[norm[:, 0] == 0.0, 3] = -np.inf  # coincident centres: no centre line, no axis
        # The largest of the 4 gaps, column by column (a reduction over a trailing axis of
        # length 4 is several times slower).
        gap = np.maximum(gaps[:, 0], gaps[:, 1])
        np.maximum(gap, gaps[:, 2], out=gap)
        np.maximum(gap, gaps[:, 3], out=gap)
        if "sphere" in (kind_s[0], kind_o[0]):
            # coal 3.0.3 overstates some sphere penetration depths (sphere–cylinder near a
            # cap): a true bound could exceed coal's value, so overlaps are not used here.
            gap = np.where(gap > 0.0, gap, -np.inf)
        bound = bound.copy()
        bound[still] = np.maximum(gap, bound[still])  # valid for overlaps too (module doc)
        return bound
