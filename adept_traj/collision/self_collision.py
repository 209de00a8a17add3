r"""Self-collision: signed distances between the robot's own links, batched over configurations.

:class:`SelfCollision` checks every pair of collision solids except

- solids on the same joint body or on **adjacent** bodies: one body is the other's nearest
  ancestor that carries a solid (bodies without a solid are skipped, as MoveIt's collision
  matrix does: the AdeptOne XL's quill, on the body after the solid-less ``link3``, runs
  through its outer arm by design);
- the link pairs listed in an SRDF's ``<disable_collisions link1=… link2=…/>`` (the MoveIt
  convention; e.g. ``srdf/ur5.srdf`` of example-robot-data) or given as ``disabled``.

Meshes are the convex hulls of :mod:`adept_traj.robot.collision_meshes`, so a reported
distance is never larger than the true one (and at most the two hulls' gaps smaller).

Distances above ``influence`` may be reported as a lower bound greater than it. The broad
phase (numpy, batched) bounds each pair from the solids' enclosing balls, then, where that
bound is at most ``influence``, from their covering spheres
(:func:`~adept_traj.collision.primitives.covering_spheres`); only the pairs still within
``influence`` go to coal (one call per close pair and sample: the only Python loop), the
closest first: an exact distance :math:`d_{ab}(q_c)` lifts the bound of the pair's other
samples to :math:`d_{ab}(q_c) - \sum_j \rho_{abj} |q_j - q_{c,j}|`
(:func:`~adept_traj.collision.pair_lever_arms`), and a sample lifted above ``influence``
needs no call. :meth:`SelfCollision.min_distances` finds the smallest distance over a
whole motion by branch and bound, as
:meth:`~adept_traj.collision.CollisionChecker.min_distances` does for obstacles. The
planner's distance constraint and the certificate use them when self-collision is on
(:class:`~adept_traj.problem.ProblemSettings`, ``docs/problem.md``).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import coal
import numpy as np

from adept_traj.collision.capsules import enclosing_capsule, segment_distance
from adept_traj.collision.lever_arms import pair_lever_arms
from adept_traj.collision.point_distance import points_in_joint
from adept_traj.collision.primitives import distance_request, enclosing_ball
from adept_traj.errors import InputShapeError, InvalidInputError, RobotModelError
from adept_traj.robot import Robot, solid_frames
from adept_traj.validation import as_batch, as_integer, as_scalar

__all__ = ["SelfCollision", "SelfDistances"]


@dataclass(frozen=True)
class SelfDistances:
    """Smallest self-distance over each motion (:meth:`SelfCollision.min_distances`).

    Attributes
    ----------
    distance:
        (...) smallest signed distance [m] over the motion's samples and the checked pairs;
        exact when ≤ ``influence``, else a lower bound greater than it (``inf``: no pair).
    sample, pair:
        (...) int, the sample and the pair index where the smallest exact distance was found
        (-1 if the distance is only a lower bound above ``influence``).
    n_narrow:
        Number of coal distance calls made.
    """

    distance: np.ndarray
    sample: np.ndarray
    pair: np.ndarray
    n_narrow: int


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
    robot_pairs:
        Leave out the robot's own disabled pairs (SRDF, parameter file; default) —
        ``False``: only adjacent pairs and ``disabled`` (a collision matrix is made so).

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
        *,
        robot_pairs: bool = True,
    ) -> None:
        self.robot = robot
        self.influence = as_scalar(influence, "influence", "[m]", minimum=0.0)
        objects = robot.collision_model.geometryObjects
        model = robot.model
        self.links = tuple(model.frames[g.parentFrame].name for g in objects)
        given = [tuple(p) for p in disabled]
        known = set(self.links)
        unknown = sorted({n for pair in given for n in pair if n not in known})
        if unknown:  # (an SRDF may name links without solids: those pairs are moot)
            raise RobotModelError(
                f"robot '{robot.name}': disabled pair link(s) {unknown} have no collision "
                f"solid; links with solids are {sorted(known)}"
            )
        off = {frozenset(p) for p in given + list(robot.disabled_pairs if robot_pairs else ())}
        #: The disabled ``(link1, link2)`` pairs that name two links with solids (sorted).
        self.disabled = tuple(
            sorted(tuple(sorted(p)) for p in off if len(p) == 2 and p <= known)  # type: ignore[misc]
        )
        self._parents, self._local = solid_frames(robot.collision_model)
        self._by_parent = [
            (int(p), np.flatnonzero(self._parents == p)) for p in np.unique(self._parents)
        ]
        near = _solid_parents(model.parents, set(self._parents.tolist()))
        chosen, adjacent = [], set()
        for a in range(len(objects)):
            for b in range(a + 1, len(objects)):
                ja, jb = int(self._parents[a]), int(self._parents[b])
                if ja == jb or near[ja] == jb or near[jb] == ja:
                    if self.links[a] != self.links[b]:
                        adjacent.add(tuple(sorted((self.links[a], self.links[b]))))
                    continue
                if frozenset((self.links[a], self.links[b])) in off:
                    continue
                chosen.append((a, b))
        #: (n_pairs, 2) indices of the checked solid pairs.
        self.pairs = np.array(chosen, dtype=int).reshape(-1, 2)
        #: The ``(link1, link2)`` pairs left out as adjacent (or on one joint body), sorted.
        self.adjacent = tuple(sorted(adjacent))
        self.solid_names = tuple(g.name for g in objects)
        self._geoms = [g.geometry for g in objects]
        rot, shift = self._local[:, :3, :3], self._local[:, :3, 3]
        #: Radii (n_solids,) [m] of the balls around the solids' local bounding boxes, centred
        #: at the middle of their capsules (:mod:`adept_traj.collision.capsules`).
        self._radii = np.array([enclosing_ball(g)[1] for g in self._geoms])
        capsules = [enclosing_capsule(g) for g in self._geoms]
        ends = np.array([[c[0], c[1]] for c in capsules]).reshape(-1, 2, 3)
        #: Capsule ends (n_solids, 2, 3) in the parent joint frames and radii (n_solids,).
        self._capsule_in_joint = np.einsum("kij,kej->kei", rot, ends) + shift[:, None]
        self._capsule_radii = np.array([c[2] for c in capsules])
        self._request = distance_request()
        #: (n_pairs, nq) joint-space Lipschitz factors of each pair's distance.
        self._rho = pair_lever_arms(robot, self.pairs)

    @property
    def n_pairs(self) -> int:
        """Number of checked pairs."""
        return len(self.pairs)

    @property
    def lever_arms(self) -> np.ndarray:
        """(n_pairs, nq) factors :math:`\\rho_{abj}` of the checked pairs
        (:func:`~adept_traj.collision.pair_lever_arms`): a pair's distance changes at most
        at :math:`\\sum_j \\rho_{abj} |\\dot q_j|` [m/s]."""
        return self._rho.copy()

    @property
    def link_pairs(self) -> tuple[tuple[str, str], ...]:
        """The checked ``(link1, link2)`` pairs (each once, sorted)."""
        found = {tuple(sorted((self.links[a], self.links[b]))) for a, b in self.pairs.tolist()}
        return tuple(sorted(found))  # type: ignore[arg-type]

    @property
    def pair_names(self) -> tuple[tuple[str, str], ...]:
        """``(solid a, solid b)`` names of the checked pairs."""
        return tuple((self.solid_names[a], self.solid_names[b]) for a, b in self.pairs)

    def distances(
        self, q: object, *, exact: bool = False, exact_below: float | None = None
    ) -> np.ndarray:
        """Signed distances (..., n_pairs) [m] of the checked pairs for configurations
        ``q`` (..., nq) [rad | m] within the joint limits: exact (coal, negative =
        penetration depth) where at most ``exact_below`` [m] (default :attr:`influence`;
        everywhere with ``exact=True``), else a lower bound greater than it."""
        qa = as_batch(q, "q", self.robot.nq, "[rad | m]")
        below = self.influence if exact_below is None else as_scalar(exact_below, "exact_below")
        frames = self.robot.kinematics.joint_frames(qa)
        flat = qa.reshape(-1, qa.shape[-1])
        out = self._distances(frames, flat, np.inf if exact else below)
        return out.reshape(*qa.shape[:-1], self.n_pairs)

    def pair_distance(self, q: object, pair: int) -> np.ndarray:
        """Exact signed distances (...) [m] (coal) of checked pair ``pair`` (an index of
        :attr:`pairs`) at configurations ``q`` (..., nq) [rad | m]."""
        qa = as_batch(q, "q", self.robot.nq, "[rad | m]")
        p = as_integer(pair, "pair", minimum=0, maximum=self.n_pairs - 1)
        frames = self.robot.kinematics.joint_frames(qa)
        out = [self._narrow(frames, n, p) for n in range(frames.shape[-1])]
        return np.array(out).reshape(qa.shape[:-1])

    def min_distance(self, q: object) -> np.ndarray:
        """Smallest self-distance (...) [m] over the checked pairs (``inf`` when none)."""
        d = self.distances(q)
        return d.min(axis=-1, initial=np.inf)

    def min_distances(
        self, q: object, joint_frames: np.ndarray | None = None, below: object = None
    ) -> SelfDistances:
        """Per motion, the smallest self-distance over all samples and pairs.

        ``q`` (..., n_t, nq) [rad | m]: the leading axes ``...`` are motions. Candidates
        (sample, pair) within ``below`` (...) [m] (default :attr:`influence`; at most it)
        are computed by coal in increasing order of their broad-phase bound until the best
        exact distance is below the next bound: the result is exact where at most
        ``below``, else a lower bound above it (the planner passes the motion's obstacle
        distance: a self-distance above it does not change the constraint).
        ``joint_frames`` (njoints, 3, 4, N), N = ∏ q.shape[:-1], may pass the robot's joint
        frames (:attr:`~adept_traj.robot.ForwardKinematics.joint_frames`) if computed.
        """
        qa = as_batch(q, "q", self.robot.nq, "[rad | m]")
        if qa.ndim < 2:
            raise InputShapeError(f"q must have shape (..., n_t, {self.robot.nq}); got {qa.shape}")
        if joint_frames is None:
            joint_frames = self.robot.kinematics.joint_frames(qa)
        expected = (self.robot.model.njoints, 3, 4, int(np.prod(qa.shape[:-1])))
        if np.shape(joint_frames) != expected:
            raise InputShapeError(
                f"joint_frames must have shape {expected} for q of shape {qa.shape}; "
                f"got {np.shape(joint_frames)}"
            )
        batch, n_t = qa.shape[:-2], qa.shape[-2]
        limit = np.full(batch, self.influence) if below is None else np.asarray(below, float)
        if np.isnan(limit).any():  # (+inf: no obstacle; the influence distance applies)
            raise InvalidInputError(f"below must hold numbers or +inf [m]; got {below!r}")
        try:
            limit = np.minimum(np.broadcast_to(limit, batch), self.influence).reshape(-1)
        except ValueError:
            raise InputShapeError(f"below must broadcast to {batch}; got {limit.shape}") from None
        found = self._min_distances(joint_frames, qa.reshape(-1, n_t, qa.shape[-1]), limit)
        return SelfDistances(
            distance=found.distance.reshape(batch),
            sample=found.sample.reshape(batch),
            pair=found.pair.reshape(batch),
            n_narrow=found.n_narrow,
        )

    # ------------------------------------------------------------------ private hooks
    def _bounds(self, frames: np.ndarray) -> np.ndarray:
        """Lower bounds (N, n_pairs) [m] for joint frames (njoints, 3, 4, N): enclosing
        balls, then enclosing capsules where those are at most :attr:`influence`."""
        n, k = frames.shape[-1], self.n_pairs
        out = np.empty((n, k))
        if not k:
            return out
        flat = frames.reshape(frames.shape[0], 12, n)
        ends = np.empty((3, len(self._radii), 2, n))  # capsule ends; their middle: ball centre
        for p, ks in self._by_parent:
            points = points_in_joint(flat[p], self._capsule_in_joint[ks].reshape(-1, 3))
            ends[:, ks] = points.reshape(3, len(ks), 2, n)
        for p, (sa, sb) in enumerate(self.pairs.tolist()):
            gap = 0.5 * (ends[:, sa, 0] + ends[:, sa, 1] - ends[:, sb, 0] - ends[:, sb, 1])
            out[:, p] = np.sqrt((gap * gap).sum(axis=0)) - (self._radii[sa] + self._radii[sb])
            close = out[:, p] <= self.influence
            rows = np.flatnonzero(close) if close.mean() < 0.5 else slice(None)  # (no copy)
            if close.any():
                a, b = ends[:, sa][..., rows], ends[:, sb][..., rows]
                gap = segment_distance(a[:, 0], a[:, 1], b[:, 0], b[:, 1])
                bound = gap - (self._capsule_radii[sa] + self._capsule_radii[sb])
                out[rows, p] = np.maximum(out[rows, p], bound)
        return out

    def _pose(self, frames: np.ndarray, n: int, s: int) -> coal.Transform3s:
        """Pose of solid ``s`` at flat sample ``n`` of the joint frames (njoints, 3, 4, N)."""
        top = frames[self._parents[s], :, :, n] @ self._local[s]
        return coal.Transform3s(top[:, :3], top[:, 3])

    def _narrow(self, frames: np.ndarray, n: int, p: int) -> float:
        """Exact signed distance [m] of pair ``p`` at flat sample ``n`` (coal)."""
        sa, sb = self.pairs[p]
        return coal.distance(
            self._geoms[sa],
            self._pose(frames, n, sa),
            self._geoms[sb],
            self._pose(frames, n, sb),
            self._request,
            coal.DistanceResult(),
        )

    def _distances(self, frames: np.ndarray, q: np.ndarray, below: float) -> np.ndarray:
        """Distances (N, n_pairs) [m] at the flat samples of ``q`` (N, nq): coal for every
        pair (``below = inf``) or, per pair, for the closest candidate at most ``below``
        first, whose exact value lifts the other candidates' bounds by the joint-space
        Lipschitz bound of :mod:`adept_traj.collision.lever_arms` (a candidate lifted above
        ``below`` keeps that bound)."""
        out = self._bounds(frames)
        if below == np.inf:
            for n, p in np.ndindex(out.shape):
                out[n, p] = self._narrow(frames, n, p)
            return out
        for p in range(self.n_pairs):
            todo = np.flatnonzero(out[:, p] <= below)
            while len(todo):
                c = int(todo[np.argmin(out[todo, p])])
                out[c, p] = d = self._narrow(frames, c, p)
                todo = todo[todo != c]
                lift = d - np.abs(q[todo] - q[c]) @ self._rho[p]
                out[todo, p] = np.maximum(out[todo, p], lift)
                todo = todo[out[todo, p] <= below]
        return out

    def _min_distances(self, frames: np.ndarray, q: np.ndarray, below: np.ndarray) -> SelfDistances:
        """Branch and bound of :meth:`min_distances` for ``q`` (n_motions, n_t, nq) and
        ``below`` (n_motions,) [m]."""
        (n_motions, n_t, _), k = q.shape, self.n_pairs
        bounds = self._bounds(frames).reshape(n_motions, n_t * k)
        best = bounds.min(axis=1, initial=np.inf)
        where = np.full(n_motions, -1)
        calls = 0
        for m in np.flatnonzero(best <= below).tolist():
            row, limit = bounds[m], below[m]
            cand = np.flatnonzero(row <= limit)
            low = row[cand]
            value, floor = np.inf, row.min(initial=np.inf, where=row > limit)
            while len(cand):
                i = int(np.argmin(low))
                if low[i] >= value:  # every bound is a valid lower bound: prune
                    break
                c = int(cand[i])
                d = self._narrow(frames, m * n_t + c // k, c % k)
                calls += 1
                if d < value:
                    value, where[m] = d, c
                keep = np.arange(len(cand)) != i
                cand, low = cand[keep], low[keep]
                same = np.flatnonzero(cand % k == c % k)
                gap = np.abs(q[m, cand[same] // k] - q[m, c // k]) @ self._rho[c % k]
                low[same] = np.maximum(low[same], d - gap)
                far = low > limit
                floor = min(floor, low.min(initial=np.inf, where=far))
                cand, low = cand[~far], low[~far]
            if value > limit:  # only a lower bound above the limit is known
                value, where[m] = min(value, floor), -1
            best[m] = value
        return SelfDistances(
            distance=best,
            sample=np.where(where >= 0, where // max(k, 1), -1),
            pair=np.where(where >= 0, where % max(k, 1), -1),
            n_narrow=calls,
        )


def _solid_parents(parents: list[int], with_solids: set[int]) -> list[int]:
    """Per joint (njoints,), its nearest strict ancestor joint carrying a solid (0: the
    base, also when no ancestor has one)."""
    out = [0] * len(parents)
    for j in range(1, len(parents)):
        a = int(parents[j])
        while a > 0 and a not in with_solids:
            a = int(parents[a])
        out[j] = a
    return out
