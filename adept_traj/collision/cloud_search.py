r"""The branch and bound of (motion, point cloud) pairs, every pair at once.

For a pair, the candidates are the (sample, solid) entries of the motion whose broad-phase
bound is at most ``influence``; its smallest distance is the smallest coal distance
between a candidate's solid and a leaf of the cloud's octree
(:class:`~adept_traj.collision.cloud_distance.CloudDistance` computes the same quantity
one candidate at a time). :func:`search_clouds` finds it for all pairs together:

1. :func:`~adept_traj.collision.cloud_tree.descend`, per robot solid, over the candidates
   of every pair: the (candidate, leaf) pairs whose lower bound :math:`\ell` is at most the
   pair's cap (the influence, or the best upper bound of the pair's distance found on the
   way), each pair's upper bound carried from one solid to the next. The candidates go in
   rounds by increasing broad-phase bound (:data:`ROUNDS`: each pair's first 2, the next
   6, the rest), a round's only where that bound is at most the pair's upper bound left by
   the rounds before: the later, larger rounds descend with a cap near the pair's
   distance;
2. per pair, coal's distance of these (candidate, leaf) pairs in increasing order of
   :math:`\ell` until the next bound is at least the best value :math:`v` (less
   :data:`~adept_traj.collision.cloud_distance.TIE`), or :math:`v` is negative (a
   penetration: that leaf's depth, as coal's octree reports one leaf's) — the only Python
   loop, over the coal calls.

Every (candidate, leaf) left out has a bound above the pair's cap, so :math:`v` is the
pair's smallest distance where it is at most ``influence``; above it, the smallest of
:math:`v` and the bounds left out is returned, a lower bound above ``influence``. Pairs
whose robot has a solid other than a box, cylinder, capsule or sphere keep the
one-candidate-at-a-time search (:func:`cloud_obstacles`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import coal
import numpy as np

from adept_traj.collision.cloud_distance import TIE, CloudDistance
from adept_traj.collision.cloud_tree import cloud_tree, descend, exact_signed_distance
from adept_traj.collision.primitives import distance_request

if TYPE_CHECKING:
    from adept_traj.collision.checker import CollisionChecker

__all__ = ["ROUNDS", "SearchSamples", "cloud_obstacles", "search_clouds"]

#: The first rank (by bound, in its pair) of each round of candidates.
ROUNDS = (0, 2, 8)


@dataclass(frozen=True)
class SearchSamples:
    """The sampled motions both levels of the branch and bound search (the pairs',
    :func:`~adept_traj.collision.branch_and_bound.search_pairs`, and the clouds',
    :func:`search_clouds`).

    Attributes
    ----------
    checker: the checker whose coal functors, solids, broad phase and ``influence`` are used.
    frames: (njoints, 3, 4, N) joint frames (component-major), N = n_motions · ``n_t``.
    obstacle_poses: per obstacle its pose (4, 4) or poses (N, 4, 4) in the base frame.
    n_t: samples per motion.
    """

    checker: CollisionChecker
    frames: np.ndarray
    obstacle_poses: list[np.ndarray]
    n_t: int

    def obstacle_pose(self, obstacle: int, sample: np.ndarray | int) -> np.ndarray:
        """(..., 4, 4) the pose of ``obstacle`` at the flat samples ``sample`` (a fixed
        obstacle's one pose (4, 4) whatever the samples)."""
        pose = self.obstacle_poses[obstacle]
        return pose if pose.ndim == 2 else pose[sample]


def cloud_obstacles(checker: CollisionChecker) -> np.ndarray:
    """(n_obstacles,) bool: the point clouds searched here, those whose every robot solid's
    functor is a :class:`~adept_traj.collision.cloud_distance.CloudDistance` of a solid
    with an exact signed distance (a box, cylinder, capsule or sphere: its upper bounds
    prune the search; a URDF link's hull keeps the search one candidate at a time, where
    the broad phase's cloud level bounds it more cheaply)."""
    rows = checker.functors
    clouds = [
        all(isinstance(f, CloudDistance) and exact_signed_distance(f.solid) for f in column)
        for column in zip(*rows)
    ]
    return np.array(clouds, dtype=bool).reshape(checker.n_obstacles) & (checker.n_solids > 0)


def search_clouds(
    samples: SearchSamples, rows: np.ndarray, pm: np.ndarray, po: np.ndarray
) -> tuple[np.ndarray, np.ndarray, int]:
    """Smallest distance of (motion ``pm``, cloud ``po``) pairs (module doc).

    Parameters
    ----------
    samples:
        The sampled motions.
    rows:
        (P, n_t · n_solids) the broad-phase bounds [m] of each pair's candidates
        (candidate index ``sample · n_solids + solid``).
    pm, po:
        (P,) int the motion and obstacle of each pair (fixed clouds and moving ones).

    Returns
    -------
    value:
        (P,) the smallest distance [m]: exact where at most ``influence``, else a lower
        bound above it (not counting the candidates above ``influence``).
    found:
        (P,) int, the candidate of the smallest exact distance, -1 where only a bound.
    calls:
        Number of coal calls made.
    """
    checker, n_t = samples.checker, samples.n_t
    ns, influence = checker.n_solids, checker.influence
    value = np.full(len(pm), np.inf)
    found = np.full(len(pm), -1)
    pair, cand = np.nonzero(rows <= influence)
    if not len(pair):
        return value, found, 0
    sample, solid, obstacle = pm[pair] * n_t + cand // ns, cand % ns, po[pair]
    cap = np.full(len(pm), influence)
    state = {"upper": np.full(len(pm), np.inf), "floor": np.full(len(pm), np.inf)}
    poses = np.empty((len(pair), 4, 4))  # of each candidate's solid, base frame
    for s in np.unique(solid).tolist():
        sel = np.flatnonzero(solid == s)
        poses[sel] = checker.broad_phase.solid_poses(samples.frames, sample[sel], s)
    candidates = _Candidates(samples, pair, cand, sample, solid, obstacle, poses)
    # in rounds of each pair's candidates by increasing bound (ROUNDS), each round's only
    # where the bound is at most the pair's upper bound then known
    bound = rows[pair, cand]
    order = np.lexsort((bound, pair))
    rank = np.empty(len(pair), dtype=int)
    starts = np.flatnonzero(np.diff(pair[order], prepend=-1))
    rank[order] = np.arange(len(pair)) - np.repeat(starts, np.diff(np.append(starts, len(pair))))
    parts = []
    for lo, hi in zip(ROUNDS, (*ROUNDS[1:], np.inf)):
        todo = (rank >= lo) & (rank < hi) & (bound <= np.minimum(cap, state["upper"])[pair] + TIE)
        parts.append(candidates.descend(np.flatnonzero(todo), cap, state))
    upper, floor = state["upper"], state["floor"]
    entry, leaf, bound = (np.concatenate([p[i] for p in parts]) for i in range(3))
    keep = bound <= np.minimum(cap, upper)[pair[entry]] + TIE  # caps lowered by later solids
    if not keep.all():
        np.minimum.at(floor, pair[entry[~keep]], bound[~keep])
    order = np.lexsort((bound[keep], pair[entry[keep]]))
    entry, leaf, bound = entry[keep][order], leaf[keep][order], bound[keep][order]
    calls = candidates.exact(entry, leaf, bound, value, found)
    over = value > influence
    value[over] = np.minimum(value[over], floor[over])
    found[over] = -1
    return value, found, calls


@dataclass(frozen=True)
class _Candidates:
    """The candidates of :func:`search_clouds`' pairs: per candidate its pair, index in the
    pair, flat sample, solid, obstacle and solid pose (4, 4) in the base frame."""

    samples: SearchSamples
    pair: np.ndarray
    cand: np.ndarray
    sample: np.ndarray
    solid: np.ndarray
    obstacle: np.ndarray
    poses: np.ndarray

    def descend(
        self, entries: np.ndarray, cap: np.ndarray, state: dict[str, np.ndarray]
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Step 1 of the module doc for the candidates ``entries``, one descent per (solid,
        cloud); ``state`` holds each pair's upper bound and floor, updated. Returns the
        (entry, leaf, bound) left."""
        pair, sample, solid, obstacle = self.pair, self.sample, self.solid, self.obstacle
        parts = []
        for s in np.unique(solid[entries]).tolist():
            sel = entries[solid[entries] == s]
            for o in np.unique(obstacle[sel]).tolist():
                sub = sel[obstacle[sel] == o]
                functor = self.samples.checker.functors[s][o]
                pose = self.samples.obstacle_pose(o, sample[sub])
                back = np.swapaxes(pose[..., :3, :3], -1, -2)
                rot = back @ self.poses[sub, :3, :3]  # solid in the cloud frame
                pos = np.einsum("...ij,...j->...i", back, self.poses[sub, :3, 3] - pose[..., :3, 3])
                tree = cloud_tree(functor.cells)
                got = descend(tree, functor.solid, rot, pos, pair[sub], cap, state["upper"])
                state["upper"], state["floor"] = got.upper, np.minimum(state["floor"], got.floor)
                parts.append((sub[got.query], got.leaf, got.bound))
        if not parts:
            return np.zeros(0, dtype=int), np.zeros(0, dtype=int), np.zeros(0)
        entry, leaf, bound = (np.concatenate([p[i] for p in parts]) for i in range(3))
        return entry, leaf, bound

    def exact(
        self,
        entry: np.ndarray,
        leaf: np.ndarray,
        bound: np.ndarray,
        value: np.ndarray,
        found: np.ndarray,
    ) -> int:
        """Step 2 of the module doc on the (candidate ``entry``, ``leaf``) pairs, sorted by
        pair then ``bound``: updates ``value`` and ``found`` in place; returns the number
        of coal calls."""
        if not len(entry):
            return 0
        group = self.pair[entry]
        cut = (np.flatnonzero(np.diff(group)) + 1).tolist()
        starts, stops = [0, *cut], [*cut, len(group)]
        entry_l, leaf_l, bound_l = entry.tolist(), leaf.tolist(), bound.tolist()
        tf_solid, tf_leaf = coal.Transform3s(), coal.Transform3s()
        request, result = distance_request(), coal.DistanceResult()
        calls = 0
        for a, b in zip(starts, stops):
            v, w = np.inf, -1
            for c in range(a, b):
                if v < 0.0 or bound_l[c] >= v - TIE:
                    break
                e = entry_l[c]
                s, o = int(self.solid[e]), int(self.obstacle[e])
                pose = self.samples.obstacle_pose(o, self.sample[e])
                functor = self.samples.checker.functors[s][o]
                tree = cloud_tree(functor.cells)
                tf_solid.setTransform(self.poses[e, :3, :3], self.poses[e, :3, 3])
                centre = pose[:3, :3] @ tree.leaf_centre[leaf_l[c]] + pose[:3, 3]
                tf_leaf.setTransform(pose[:3, :3], centre)
                result.clear()
                half = float(tree.leaf_half[leaf_l[c]])
                d = functor.leaf_distance(half, tf_solid, tf_leaf, request, result)
                calls += 1
                if d < v:
                    v, w = d, int(self.cand[e])
            value[int(group[a])], found[int(group[a])] = v, w
        return calls
