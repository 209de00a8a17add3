r"""The branch and bound of :meth:`CollisionChecker.min_distances`, batched over pairs.

For every (motion, obstacle) pair, the candidates are the (sample, solid) entries of the
motion; each has a broad-phase lower bound :math:`\ell_c` of its signed distance [m]
(:class:`~adept_traj.collision.BroadPhase`), exact for some. The smallest exact distance
over the candidates, where it is at most ``influence``, is found by computing candidates
(coal, or their exact bound) in increasing order of :math:`\ell_c` until the best exact
distance found, :math:`v`, is at most the next bound: every bound is a valid lower bound,
so no later candidate can be below :math:`v`.

:func:`search_pairs` runs every pair's search at once, in three steps that each handle
all pairs together:

1. the first candidate of each pair (the smallest bound, the first one on ties): its
   solid pose is formed for all pairs in one batch and coal is called once per pair;
2. the pairs with other candidates whose bound is below that first value and at most
   ``influence``: these candidates are sorted by bound (ties by index) for all pairs in one
   :func:`numpy.lexsort`, their solid poses formed in one batch; then each pair walks its
   sorted candidates until a bound reaches its best value (the only Python loop, over
   the candidates computed);
3. where the best value exceeds ``influence`` only a bound is known: the smallest of the
   value and the bounds above ``influence``.

The coal calls, their order within a pair and the results are those of the one-pair-at-a-
time search (each pair's sequence of candidates is the same).
"""

from __future__ import annotations

import numpy as np

from adept_traj.collision.cloud_search import SearchSamples, cloud_obstacles, search_clouds

__all__ = ["search_pairs"]


def search_pairs(
    samples: SearchSamples, lower: np.ndarray, known: np.ndarray
) -> tuple[np.ndarray, np.ndarray, int]:
    """Smallest distance of every (motion, obstacle) pair (module doc).

    Parameters
    ----------
    samples:
        The sampled motions (:class:`~adept_traj.collision.cloud_search.SearchSamples`).
    lower, known:
        (n_motions, n_t · n_solids, n_obstacles) lower bounds [m] (candidate index
        ``sample · n_solids + solid``) and whether each is exact.

    Returns
    -------
    best:
        (n_motions, n_obstacles) the smallest distance [m]: exact where at most
        ``influence``, else a lower bound above it.
    where:
        (n_motions, n_obstacles) int, the candidate of the smallest exact distance, -1
        where only a bound is known.
    calls:
        Number of coal calls made.
    """
    checker, n_t = samples.checker, samples.n_t
    ns, influence = checker.n_solids, checker.influence
    smallest = lower.argmin(axis=1)  # (n_motions, n_obs): where each smallest bound is
    best = np.take_along_axis(lower, smallest[:, None], axis=1)[:, 0]  # bound until improved
    where = np.full(best.shape, -1)
    closed = checker.broad_phase.closed_form.all(axis=0)  # (n_obs,): every close pair exact
    # Every pair within influence of such an obstacle is exact already: the argmin is
    # exact when at most influence; above, it may be a level-1 bound (then -1).
    is_exact = np.take_along_axis(known, smallest[:, None, :], axis=1)[:, 0]
    where[:, closed] = np.where(is_exact, smallest, -1)[:, closed]
    pm, po = np.nonzero((best <= influence) & ~closed)
    calls = 0
    cloudy = cloud_obstacles(checker)[po]  # the point clouds: all their pairs at once
    if cloudy.any():
        cm, co = pm[cloudy], po[cloudy]
        rows = lower[cm, :, co]
        value, found, calls = search_clouds(samples, rows, cm, co)
        best[cm, co], where[cm, co] = _floor(value, found, rows, influence)
        pm, po = pm[~cloudy], po[~cloudy]
    if len(pm) == 0:
        return best, where, calls
    rows = lower[pm, :, po]  # (n_pairs, n_t · n_solids)
    first = smallest[pm, po]  # = rows.argmin(axis=1)
    # 1. The first candidates, their poses (solid and obstacle) formed together.
    value = rows[np.arange(len(pm)), first]  # exact already where known
    todo = np.flatnonzero(~known[pm, first, po])
    calls += len(todo)
    value[todo] = _narrow_many(
        samples, pm[todo] * n_t + first[todo] // ns, first[todo] % ns, po[todo]
    )
    found = first.copy()
    # 2. The pairs with another candidate whose bound is below the first value and at most
    # influence (their second smallest bound is).
    mask = (rows <= influence) & (rows < value[:, None])
    mask[np.arange(len(pm)), first] = False  # the first candidate, done
    need = np.flatnonzero(mask.any(axis=1))
    if len(need):
        calls += _walk(samples, known, rows, mask, pm, po, need, value, found)
    best[pm, po], where[pm, po] = _floor(value, found, rows, influence)
    return best, where, calls


def _floor(
    value: np.ndarray, found: np.ndarray, rows: np.ndarray, influence: float
) -> tuple[np.ndarray, np.ndarray]:
    """Step 3 of the module doc: where ``value`` (P,) is above ``influence``, the smallest
    of it and the bounds of ``rows`` (P, n_candidates) above ``influence`` (those were not
    computed), with ``found`` (P,) set to -1 there; both returned (modified in place)."""
    over = np.flatnonzero(value > influence)
    if len(over):
        sub = rows[over]
        floor = np.where(sub > influence, sub, np.inf).min(axis=1)
        value[over] = np.minimum(value[over], floor)
        found[over] = -1
    return value, found


def _narrow_many(
    samples: SearchSamples, at: np.ndarray, solids: np.ndarray, obstacles: np.ndarray
) -> np.ndarray:
    """Exact distances (R,) [m] by coal of solid ``solids[i]`` at flat sample ``at[i]`` and
    obstacle ``obstacles[i]``, the solid poses formed in one batch."""
    checker = samples.checker
    poses = checker.broad_phase.solid_poses(samples.frames, at, solids)
    out = np.empty(len(at))
    for i, (n, s, o) in enumerate(zip(at.tolist(), solids.tolist(), obstacles.tolist())):
        out[i] = checker.narrow_distance(poses[i], samples.obstacle_pose(o, n), s, o)
    return out


def _walk(
    samples: SearchSamples,
    known: np.ndarray,
    rows: np.ndarray,
    mask: np.ndarray,
    pm: np.ndarray,
    po: np.ndarray,
    need: np.ndarray,
    value: np.ndarray,
    found: np.ndarray,
) -> int:
    """Step 2 of the module doc for the pairs ``need`` (``mask`` (n_pairs, n_candidates):
    the candidates left, bound at most ``influence`` and below the first value): updates
    ``value`` and ``found`` (candidate of the best value) in place; returns the number of
    coal calls."""
    checker = samples.checker
    ns, n_t = checker.n_solids, rows.shape[1] // checker.n_solids
    sub = rows[need]
    pair, cand = np.nonzero(mask[need])
    bound = sub[pair, cand]
    order = np.lexsort((cand, bound, pair))  # by pair, then bound, then index
    pair, cand, bound = pair[order], cand[order], bound[order]
    m, o = pm[need][pair], po[need][pair]
    exact = known[m, cand, o]
    flat, solids = m * n_t + cand // ns, cand % ns
    unknown = np.flatnonzero(~exact)
    poses = checker.broad_phase.solid_poses(samples.frames, flat[unknown], solids[unknown])
    slot = np.cumsum(~exact) - 1  # index into poses of each unknown candidate
    ends = np.searchsorted(pair, np.arange(len(need)), side="right").tolist()
    bound_l, exact_l, cand_l = bound.tolist(), exact.tolist(), cand.tolist()
    flat_l, solids_l, o_l, slot_l = flat.tolist(), solids.tolist(), o.tolist(), slot.tolist()
    calls, start = 0, 0
    for j, i in enumerate(need.tolist()):
        v, w = float(value[i]), int(found[i])
        for c in range(start, ends[j]):
            if bound_l[c] >= v:  # every bound is a valid lower bound: prune
                break
            if exact_l[c]:
                d = bound_l[c]
            else:
                pose_o = samples.obstacle_pose(o_l[c], flat_l[c])
                # only a distance below v matters: a larger one may come as a bound ≥ v
                d = checker.narrow_distance(poses[slot_l[c]], pose_o, solids_l[c], o_l[c], v)
                calls += 1
            if d < v:
                v, w = d, cand_l[c]
        value[i], found[i], start = v, w, ends[j]
    return calls
