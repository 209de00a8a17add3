r"""Timed edges over joint space × scene time: a wait, then a straight joint-space move,
checked against the moving obstacles at the scene times it passes them; the edges'
timing and the shortcut of a timed path (:mod:`~adept_traj.optimise.local.timed_roadmap`).

An edge from :math:`(q_a, t_a)` waits ``wait`` [s] at :math:`q_a`, then moves linearly to
:math:`q_b` in ``move`` [s]. :func:`edges_clear` checks many edges at once at
:data:`EDGE_SAMPLES` instants spread evenly over each (one batched call of the problem's
checker for the obstacle distances at those scene times, and of its self-collision check).
The time of a move is set by :func:`characteristic_speed` (the time-optimal moves of a
robot limited by acceleration and jerk stay well below :math:`v_{\max}`), a factor of
:data:`SPEEDS` and :func:`rest_ramp` for each end at rest.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = [
    "EDGE_SAMPLES",
    "MIN_TRAVEL",
    "SPEEDS",
    "characteristic_speed",
    "clearance",
    "edges_clear",
    "rest_ramp",
    "shortcut",
]

#: Speed factors f of an edge's move (of the characteristic speed).
SPEEDS: tuple[float, ...] = (1.0, 1.5, 2.0)

#: Instants checked per edge, its later end included.
EDGE_SAMPLES = 12

#: Least travel of a joint in :func:`characteristic_speed`, a fraction of its range.
MIN_TRAVEL = 0.05


def characteristic_speed(problem: Any) -> np.ndarray:
    r"""(nq,) the characteristic joint speeds :math:`v_c` [rad/s | m/s] of the edges: the
    mean speed of a rest-to-rest bang-bang move at the acceleration limit over the joint's
    travel :math:`D` (at least :data:`MIN_TRAVEL` of its range),
    :math:`\min(v_{\max},\ \frac12 \sqrt{a_{\max} D})`."""
    lim = problem.robot.limits
    travel = np.maximum(
        np.abs(np.asarray(problem.goal) - np.asarray(problem.start)),
        MIN_TRAVEL * (lim.upper - lim.lower),
    )
    return np.minimum(lim.velocity, 0.5 * np.sqrt(lim.acceleration * travel))


def rest_ramp(problem: Any) -> float:
    r"""The rest ramp :math:`\rho` [s], added to a move for each end at rest:
    :math:`\max_i v_{c,i} / (2 a_{\max,i})`, the lag of a start at the acceleration limit
    behind a start at the characteristic speed."""
    return float(np.max(0.5 * characteristic_speed(problem) / problem.robot.limits.acceleration))


def clearance(problem: Any, q: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(n,) the smallest obstacle or self-distance [m] of each of the motions ``q``
    (n, k, nq) at times ``t`` (n, k) [s]: one batched call of the problem's checker."""
    frames = problem.robot.kinematics.joint_frames(q)
    d = problem.checker.min_distances(q, t, joint_frames=frames).distance.min(
        axis=-1, initial=np.inf
    )
    if problem.self_check is not None:
        d = np.minimum(d, problem.self_check.min_distances(q, frames, below=d).distance)
    return d


def shortcut(problem: Any, q: Any, t: Any) -> tuple[np.ndarray, np.ndarray]:
    """The timed path ``q`` (m, nq) [rad | m] at times ``t`` (m,) [s] with the fewest
    states: every pair of states is joined by a straight move over their whole time
    interval where that is fast enough (at most the fastest of :data:`SPEEDS`) and clear
    (one batched check of all pairs), and the path of fewest such edges is kept (the kept
    states keep their times: the phase at each of them is unchanged)."""
    q, t = np.asarray(q, dtype=float), np.asarray(t, dtype=float)
    m = len(t)
    i, j = np.triu_indices(m, k=2)
    fast = np.max(np.abs(q[j] - q[i]) / characteristic_speed(problem), axis=1) / max(SPEEDS)
    ok = np.zeros((m, m), dtype=bool)
    ok[np.arange(m - 1), np.arange(1, m)] = True
    try_ = np.flatnonzero(t[j] - t[i] >= fast)
    ok[i[try_], j[try_]] = edges_clear(
        problem, q[i[try_]], q[j[try_]], t[i[try_]], np.zeros(len(try_)), t[j[try_]] - t[i[try_]]
    )
    hops, prev = np.full(m, m), np.zeros(m, dtype=int)
    hops[0] = 0
    for b in range(1, m):  # fewest edges (states in time order: a DAG)
        a = np.flatnonzero(ok[:b, b])
        k = a[np.argmin(hops[a])]
        hops[b], prev[b] = hops[k] + 1, k
    keep, n = [m - 1], m - 1
    while n > 0:
        n = int(prev[n])
        keep.append(n)
    keep = keep[::-1]
    return q[keep], t[keep]


def edges_clear(
    problem: Any,
    qa: np.ndarray,
    qb: np.ndarray,
    ta: np.ndarray,
    wait: np.ndarray,
    move: np.ndarray,
) -> np.ndarray:
    """(n,) whether each edge (a wait of ``wait`` [s] at ``qa`` (n, nq) from time ``ta``
    (n,) [s], then a straight move to ``qb`` in ``move`` [s]) keeps every distance ≥
    the problem's margin at its :data:`EDGE_SAMPLES` instants (its later end
    included)."""
    if not len(qa):
        return np.zeros(0, dtype=bool)
    tau = (wait + move)[:, None] * (np.arange(1, EDGE_SAMPLES + 1) / EDGE_SAMPLES)[None]
    w = np.clip((tau - wait[:, None]) / np.maximum(move, 1e-12)[:, None], 0.0, 1.0)
    q = qa[:, None] + w[..., None] * (qb - qa)[:, None]  # (n, k, nq)
    return clearance(problem, q, ta[:, None] + tau) >= problem.settings.margin
