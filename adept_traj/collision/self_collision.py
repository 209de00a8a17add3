"""Self-collision: signed distances between the robot's own links, batched over configurations.

:class:`SelfCollision` checks every pair of collision solids except

- solids on the same joint body or on **adjacent** bodies (one joint's parent is the
  other's: they touch at the joint by design);
- the link pairs listed in an SRDF's ``<disable_collisions link1=… link2=…/>`` (the MoveIt
  convention; e.g. ``srdf/ur5.srdf`` of example-robot-data) or given as ``disabled``.

Meshes are the convex hulls of :mod:`adept_traj.robot.collision_meshes`, so a reported
distance is never larger than the true one (and at most the two hulls' gaps smaller).
Distances above ``influence`` may be reported as a lower bound (the distance between the
solids' enclosing balls), which keeps coal calls to the pairs that are close.

Scope: this is a query (:meth:`SelfCollision.distances`, :meth:`SelfCollision.min_distance`)
for checking configurations and motions; the planner's constraints and the certificate do
not include self-collision yet (docs/your-robot.md).
"""

from __future__ import annotations

from collections.abc import Iterable

import coal
import numpy as np

from adept_traj.collision.primitives import distance_request, enclosing_ball
from adept_traj.errors import RobotModelError
from adept_traj.robot import Robot
from adept_traj.validation import as_batch, as_scalar

__all__ = ["SelfCollision"]


class SelfCollision:
    """Distances between the non-adjacent, not disabled link solids of a robot.

    Parameters
    ----------
    robot:
        The robot (its collision model gives the solids).
    disabled:
        More ``(link1, link2)`` pairs to exclude (link names of the URDF) besides the
        robot's SRDF pairs (:attr:`~adept_traj.robot.Robot.disabled_pairs`, from
        ``Robot.from_urdf(..., srdf=...)``).
    influence:
        Distance [m] below which every distance is exact (default 0.05 m, ≥ 0).

    Raises
    ------
    RobotModelError
        A ``disabled`` pair naming a link without a collision solid (the message lists
        those with one).
    """

    def __init__(
        self,
        robot: Robot,
        disabled: Iterable[tuple[str, str]] = (),
        influence: float = 0.05,
    ) -> None:
        self.robot = robot
        self.influence = as_scalar(influence, "influence", "[m]", minimum=0.0)
        objects = robot.collision_model.geometryObjects
        model = robot.model
        self.links = tuple(model.frames[g.parentFrame].name for g in objects)
        given = [tuple(p) for p in disabled]
        pairs = given + list(robot.disabled_pairs)
        known = set(self.links)
        unknown = sorted({n for pair in given for n in pair if n not in known})
        if unknown:  # (an SRDF may name links without solids: those pairs are moot)
            raise RobotModelError(
                f"robot '{robot.name}': disabled pair link(s) {unknown} have no collision "
                f"solid; links with solids are {sorted(known)}"
            )
        off = {frozenset(p) for p in pairs}
        joints = [g.parentJoint for g in objects]
        parent = model.parents
        chosen = []
        for a in range(len(objects)):
            for b in range(a + 1, len(objects)):
                ja, jb = joints[a], joints[b]
                if ja == jb or parent[ja] == jb or parent[jb] == ja:
                    continue
                if frozenset((self.links[a], self.links[b])) in off:
                    continue
                chosen.append((a, b))
        #: (n_pairs, 2) indices of the checked solid pairs.
        self.pairs = np.array(chosen, dtype=int).reshape(-1, 2)
        self.solid_names = tuple(g.name for g in objects)
        self._geoms = [g.geometry for g in objects]
        balls = [enclosing_ball(g) for g in self._geoms]
        self._centres = np.array([c for c, _ in balls]).reshape(-1, 3)
        self._radii = np.array([r for _, r in balls])
        self._request = distance_request()

    @property
    def pair_names(self) -> tuple[tuple[str, str], ...]:
        """``(solid a, solid b)`` names of the checked pairs."""
        return tuple((self.solid_names[a], self.solid_names[b]) for a, b in self.pairs)

    def distances(self, q: object) -> np.ndarray:
        """Signed distances (..., n_pairs) [m] of the checked pairs for configurations
        ``q`` (..., nq) [rad | m]: exact (coal, negative = penetration depth) where at most
        :attr:`influence`, else a lower bound greater than it."""
        qa = as_batch(q, "q", self.robot.nq, "[rad | m]")
        return self._distances(qa)

    def min_distance(self, q: object) -> np.ndarray:
        """Smallest self-distance (...) [m] over the checked pairs (``inf`` when none)."""
        d = self.distances(q)
        return d.min(axis=-1, initial=np.inf)

    def _distances(self, q: np.ndarray) -> np.ndarray:
        poses = self.robot.geometry_poses(q).reshape(-1, len(self.solid_names), 4, 4)
        n, k = poses.shape[0], len(self.pairs)
        out = np.empty((n, k))
        if k == 0:
            return out.reshape(*q.shape[:-1], 0)
        a, b = self.pairs[:, 0], self.pairs[:, 1]
        centres = np.einsum("nsij,sj->nsi", poses[..., :3, :3], self._centres) + poses[..., :3, 3]
        gap = np.linalg.norm(centres[:, a] - centres[:, b], axis=-1)
        out[:] = gap - self._radii[a] - self._radii[b]  # a lower bound (balls contain solids)
        result = coal.DistanceResult()
        tf_a, tf_b = coal.Transform3s(), coal.Transform3s()
        for i, p in zip(*np.nonzero(out <= self.influence)):
            sa, sb = self.pairs[p]
            tf_a.setRotation(poses[i, sa, :3, :3])
            tf_a.setTranslation(poses[i, sa, :3, 3])
            tf_b.setRotation(poses[i, sb, :3, :3])
            tf_b.setTranslation(poses[i, sb, :3, 3])
            result.clear()
            out[i, p] = coal.distance(
                self._geoms[sa], tf_a, self._geoms[sb], tf_b, self._request, result
            )
        return out.reshape(*q.shape[:-1], k)
