r"""The global stage against moving obstacles: trees over joint space × scene time, then a
smooth fit of their fastest paths into the problem's B-spline decision vector.

A fast move past a swinging load must be in the right place at the right time; starts made
of a path at a chosen speed (:mod:`~adept_traj.optimise.via_points`, the relaxed optimum
stretched) are blind to the phase. :func:`timed_paths` grows two trees of **timed
states** :math:`(q, t)` (a bidirectional RRT in joint space × scene time): one forward in
time from :math:`(q_s, 0)`, one backward in time from the goal held at :data:`ROOTS`
arrival times between the kinematic lower bound and the largest T (those where the goal
pose is clear). An edge between an earlier state :math:`(q_a, t_a)` and a later one
:math:`(q_b, t_b)` waits at :math:`q_a`, then moves in a straight joint-space line in

.. math::
    	au = \max_i rac{|q_{b,i} - q_{a,i}|}{f\, v_{c,i}}
           + 
ho\,[	ext{start at rest}] + 
ho\,[	ext{end at rest}],

:math:`f \in` :data:`SPEEDS`, :math:`v_c` the characteristic speed
(:func:`characteristic_speed`: the time-optimal moves of a robot limited by acceleration
and jerk stay well below :math:`v_{\max}`) and :math:`
ho` the rest ramp
(:func:`rest_ramp`) for an end after a wait, at the start or at the goal. Each round
draws :data:`BATCH` targets per tree (near a guide move's configurations with probability
:data:`GUIDE_BIAS`, else uniform inside the joint limits shrunk by
:data:`~adept_traj.optimise.LIMIT_INSET`), extends the nearest node of each (in time at
:math:`v_c`, plus :data:`EARLY` × its time or arrival: a bias toward early arrival) by at
most :data:`STEP` [s] at :math:`v_c`, after a wait (with probability :data:`WAIT_SHARE`,
up to :data:`MAX_WAIT`), and tries to join every new node to its :data:`JOINS` nearest
nodes of the other tree that it can reach in time. Every edge is checked at
:data:`EDGE_SAMPLES` instants spread evenly over its time with the problem's own checker
(one batched call per tree and round: obstacle distances at those scene times,
self-distances) and kept where every distance is at least the problem's margin +
:data:`CLEARANCE`. Once the trees are joined, nodes later than the earliest arrival are
not extended; the search stops after :data:`ROUNDS` rounds, or :data:`ROUNDS_AFTER`
rounds after the first join.

:func:`timed_roadmap_starts` fits each of the earliest arrivals' paths, held at the goal
up to :data:`HOLDS` × its arrival time (the phase of the way is kept: the rest is a wait
at the goal), into the decision vector by least squares on the free control points at
:data:`FIT_SAMPLES` instants (:func:`fit_timed_path`), evaluates the fits with the
problem's evaluator and returns the feasible ones first (fastest first), then the least
infeasible: starts for :func:`~adept_traj.optimise.refine_minimum_time`. Everything is
drawn from a generator seeded by ``seed``: the same problem and seed give the same starts.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.via_points import LIMIT_INSET
from adept_traj.validation import as_integer

__all__ = [
    "BACKWARD_WAIT_SHARE",
    "BATCH",
    "CLEARANCE",
    "DISTANCE_WEIGHT",
    "EARLY",
    "EDGE_SAMPLES",
    "GUIDE_BIAS",
    "GUIDE_POINTS",
    "GUIDE_SPREAD",
    "HOLDS",
    "JOINS",
    "MAX_WAIT",
    "MIN_TRAVEL",
    "OTHER_BIAS",
    "ROOTS",
    "ROUNDS",
    "ROUNDS_AFTER",
    "SMOOTHINGS",
    "SPEEDS",
    "STEP",
    "TREES",
    "WAIT_SHARE",
    "TimedPaths",
    "characteristic_speed",
    "fit_timed_path",
    "rest_ramp",
    "shortcut",
    "timed_paths",
    "timed_roadmap_starts",
]

#: Targets drawn (extensions tried) per tree and round.
BATCH = 48

#: Most rounds per pair of trees (the sample budget: ``2 × TREES × ROUNDS × BATCH``
#: extensions).
ROUNDS = 60

#: Most pairs of trees grown (a fresh pair, from the next seed, while none was joined).
TREES = 4

#: Rounds run after the first join of the trees (earlier arrivals sought).
ROUNDS_AFTER = 8

#: Arrival times of the backward tree's roots (the goal held), evenly from the kinematic
#: lower bound to the largest T.
ROOTS = 48

#: Nearest nodes of the other tree each new node tries to join.
JOINS = 3

#: Share of the targets drawn near a guide configuration.
GUIDE_BIAS = 0.75

#: Share of the targets drawn at a node of the other tree (overriding the above).
OTHER_BIAS = 0.0

#: Spread of the targets about a guide configuration: the standard deviation per joint is
#: this time [s] × the characteristic speed.
GUIDE_SPREAD = 0.3

#: Configurations taken along each guide move.
GUIDE_POINTS = 40

#: Longest move of an extension [s] at the characteristic speed.
STEP = 0.25

#: Speed factors f of an edge's move (of the characteristic speed).
SPEEDS: tuple[float, ...] = (1.0, 1.5, 2.0)

#: Share of the extensions that wait before their move.
WAIT_SHARE = 0.3

#: Share of the backward tree's extensions that wait (near the goal, where a moving
#: obstacle that blocks the goal passes, a wait is seldom clear).
BACKWARD_WAIT_SHARE = 0.0

#: Longest wait [s] before an extension's move (drawn uniformly up to it).
MAX_WAIT = 0.5

#: Weight of a node's time (forward) or arrival (backward) in the nearest-node choice.
EARLY = 0.25

#: Instants checked per edge, its later end included.
EDGE_SAMPLES = 12

#: Least travel of a joint in :func:`characteristic_speed`, a fraction of its range.
MIN_TRAVEL = 0.05

#: Clearance [m] kept by the trees beyond the problem's margin (room for the smooth fit).
CLEARANCE = 0.0

#: Factors of the arrival time at which a path is fitted (the rest held at the goal).
HOLDS: tuple[float, ...] = (1.0, 1.1, 1.2)

#: Weights µ [rad²] of the accelerations in the fits (:func:`fit_timed_path`).
SMOOTHINGS: tuple[float, ...] = (1e-3, 1e-2, 1e-1)

#: Weight of the distance violation against the limits' in the ranking of the fits.
DISTANCE_WEIGHT = 10.0

#: Instants of the least-squares fit.
FIT_SAMPLES = 80

#: Earliest arrivals fitted by :func:`timed_roadmap_starts`.
_PATHS = 4


@dataclass(frozen=True)
class TimedPaths:
    """The joined paths of :func:`timed_paths`, earliest arrival first.

    Attributes
    ----------
    paths: per path, (m, nq) states [rad | m] from the start to the goal; a state repeated
        at two times is a wait.
    times: per path, (m,) their non-decreasing times [s] (motion time), from 0 to its arrival.
    arrival: (k,) the arrival times [s], increasing.
    n_nodes: nodes of both trees.
    n_edges: edges checked.
    """

    paths: tuple[np.ndarray, ...]
    times: tuple[np.ndarray, ...]
    arrival: np.ndarray
    n_nodes: int
    n_edges: int


class _Tree:
    """One tree: nodes (q, t), parents, the move [s] of the edge to the parent, and the
    key of the early bias (forward: the time; backward: the root's arrival time)."""

    def __init__(self, q: np.ndarray, t: np.ndarray, key: np.ndarray) -> None:
        self.q, self.t, self.key = [q], [t], [key]
        self.parent, self.move = [np.full(len(t), -1)], [np.zeros(len(t))]

    def add(self, q: Any, t: Any, key: Any, parent: Any, move: Any) -> int:
        first = self.size
        for part, value in zip(
            (self.q, self.t, self.key, self.parent, self.move), (q, t, key, parent, move)
        ):
            part.append(np.asarray(value))
        return first

    @property
    def size(self) -> int:
        return sum(len(t) for t in self.t)

    def arrays(self) -> tuple[np.ndarray, ...]:
        return tuple(np.concatenate(p) for p in (self.q, self.t, self.key, self.parent, self.move))

    def chain(self, n: int) -> list[int]:
        parent, nodes = np.concatenate(self.parent), []
        while n >= 0:
            nodes.append(n)
            n = int(parent[n])
        return nodes


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
    """Time [s] added to a move for each end at rest (after a wait, at the start, into the
    goal): :math:`\max_i v_{c,i} / a_{\max,i}`, the time to reach the characteristic
    speed at the acceleration limit."""
    return float(np.max(0.5 * characteristic_speed(problem) / problem.robot.limits.acceleration))


def timed_paths(
    problem: Any, seed: int, *, guides: Any = None, rounds: int | None = None
) -> TimedPaths:
    """Grow the two trees over joint space × scene time (module docstring) and return their
    joined paths.

    Parameters
    ----------
    problem: the :class:`~adept_traj.problem.TrajectoryProblem`.
    seed: seed of the generator (≥ 0).
    guides: (k, n_var) moves whose configurations the targets follow (e.g. the fastest
        move without the moving obstacles); default: the straight move.
    rounds: most rounds (≥ 1) of :data:`BATCH` extensions per tree (default :data:`ROUNDS`).
    """
    seed = as_integer(seed, "seed", minimum=0, error=ConfigurationError)
    rounds = as_integer(ROUNDS if rounds is None else rounds, "rounds", minimum=1,
                        error=ConfigurationError)
    n_nodes = n_edges = 0
    for k in range(TREES):  # fresh trees until a pair is joined
        rng = np.random.default_rng([seed, 24, k])
        fwd, bwd, joins, n = _grow(problem, rng, rounds, guides)
        n_nodes, n_edges = n_nodes + fwd.size + bwd.size, n_edges + n
        if joins:
            break
    joins.sort()
    paths = [shortcut(problem, *_path(fwd, bwd, a, b, m)) for _, a, b, m in joins[:_PATHS]]
    return TimedPaths(
        paths=tuple(p for p, _ in paths),
        times=tuple(t for _, t in paths),
        arrival=np.array([j[0] for j in joins]),
        n_nodes=n_nodes,
        n_edges=n_edges,
    )


def _grow(problem: Any, rng: Any, rounds: int, guides: Any) -> tuple[_Tree, _Tree, list, int]:
    """One pair of trees (module docstring): forward, backward, their joins (arrival [s],
    forward node, backward node, move [s]) and the edges checked."""
    lim = problem.robot.limits
    start, goal = np.asarray(problem.start, float), np.asarray(problem.goal, float)
    inset = LIMIT_INSET * (lim.upper - lim.lower)
    box = (lim.lower + inset, lim.upper - inset)
    v_c, ramp = characteristic_speed(problem), rest_ramp(problem)
    way = _guide_points(problem, guides)
    fwd = _Tree(start[None], np.zeros(1), np.zeros(1))
    roots = np.linspace(float(problem.xl[0]), float(problem.xu[0]), ROOTS)
    here = np.broadcast_to(goal, (ROOTS, 1, len(goal)))
    roots = roots[_clearance(problem, here, roots[:, None]) >= problem.settings.margin + CLEARANCE]
    bwd = _Tree(np.broadcast_to(goal, (len(roots), len(goal))).copy(), roots, roots)
    joins: list[tuple[float, int, int, float]] = []
    n_edges, left = 0, rounds
    while left > 0 and len(roots):
        left -= 1
        best = min(joins)[0] if joins else np.inf
        for forward in (True, False):
            tree, other = (fwd, bwd) if forward else (bwd, fwd)
            toward = np.concatenate(other.q)  # RRT-Connect: targets at the other tree too
            new, n = _extend(problem, tree, forward, best, rng, box, way, toward, v_c, ramp)
            n_edges += n
            if len(new):
                found, n = _join(problem, fwd, bwd, new, forward, best, v_c, ramp)
                n_edges += n
                had = bool(joins)
                joins += found
                if joins and not had:
                    left = min(left, ROUNDS_AFTER)
    return fwd, bwd, joins, n_edges


def _extend(
    problem: Any, tree: _Tree, forward: bool, best: float, rng: Any, box: Any, way: Any,
    toward: np.ndarray, v_c: np.ndarray, ramp: float,
) -> tuple[np.ndarray, int]:
    """One round of extensions of ``tree`` (forward in time or backward); returns the new
    nodes' indices and the edges checked."""
    Q, T, key, _, _ = tree.arrays()
    nq = Q.shape[1]
    target = rng.uniform(box[0], box[1], size=(BATCH, nq))
    guided = rng.random(BATCH) < GUIDE_BIAS
    noise = rng.normal(0.0, 1.0, (int(guided.sum()), nq)) * GUIDE_SPREAD * v_c
    target[guided] = np.clip(way[rng.integers(0, len(way), guided.sum())] + noise, *box)
    other = rng.random(BATCH) < OTHER_BIAS
    target[other] = toward[rng.integers(0, len(toward), other.sum())]
    speed = np.asarray(SPEEDS)[rng.integers(0, len(SPEEDS), BATCH)]
    share = WAIT_SHARE if forward else BACKWARD_WAIT_SHARE
    wait = np.where(rng.random(BATCH) < share, rng.uniform(0.0, MAX_WAIT, BATCH), 0.0)
    reach = np.max(np.abs(target[:, None] - Q[None]) / v_c, axis=2)  # (BATCH, N) [s]
    cost = reach + EARLY * key[None] + np.where(key < best, 0.0, np.inf)[None]
    near = np.argmin(cost, axis=1)
    rows = np.arange(BATCH)
    keep = np.flatnonzero(np.isfinite(cost[rows, near]) & (reach[rows, near] > 0.0))
    a = near[keep]
    scale = np.minimum(1.0, STEP / reach[keep, a])
    q_new = Q[a] + scale[:, None] * (target[keep] - Q[a])
    wait = wait[keep]
    if forward:  # wait at the node, then the move
        rest = (wait > 0.0).astype(float) + (T[a] == 0.0)
        move = scale * reach[keep, a] / speed[keep] + ramp * np.minimum(rest, 1.0)
        t_new = T[a] + wait + move
        ok = t_new < best
    else:  # the new node waits, then moves to the later node
        rest = (wait > 0.0).astype(float) + (a < len(tree.t[0]))  # into a root: at rest
        move = scale * reach[keep, a] / speed[keep] + ramp * rest
        t_new = T[a] - wait - move
        earliest = np.max(np.abs(q_new - problem.start) / v_c, axis=1) / max(SPEEDS) + ramp
        ok = t_new >= earliest
    a, q_new, wait, move, t_new = a[ok], q_new[ok], wait[ok], move[ok], t_new[ok]
    if forward:
        clear = _edges_clear(problem, Q[a], q_new, T[a], wait, move)
    else:
        clear = _edges_clear(problem, q_new, Q[a], t_new, wait, move)
    if not clear.any():
        return np.zeros(0, dtype=int), len(a)
    c = clear
    first = tree.add(q_new[c], t_new[c], key[a[c]], a[c], move[c])
    return first + np.arange(int(c.sum())), len(a)


def _join(
    problem: Any, fwd: _Tree, bwd: _Tree, new: np.ndarray, forward: bool, best: float,
    v_c: np.ndarray, ramp: float,
) -> tuple[list[tuple[float, int, int, float]], int]:
    """Edges from each new node (of the forward tree when ``forward``, else of the
    backward one) to its :data:`JOINS` nearest nodes of the other tree reachable in time;
    returns the kept joins (arrival [s], forward node, backward node, move [s]) and the
    edges checked."""
    Qf, Tf, _, _, _ = fwd.arrays()
    Qb, Tb, Rb, _, _ = bwd.arrays()
    n_roots = len(bwd.t[0])
    if forward:
        qa, ta = Qf[new], Tf[new]
        reach = np.max(np.abs(qa[:, None] - Qb[None]) / v_c, axis=2)  # (n, Nb)
        dt = Tb[None] - ta[:, None]
        root = np.broadcast_to(np.arange(len(Tb)) < n_roots, reach.shape)
        start = np.broadcast_to((ta == 0.0)[:, None], reach.shape)
        late = np.broadcast_to(Rb[None] >= best, reach.shape)
    else:
        qb, tb = Qb[new], Tb[new]
        reach = np.max(np.abs(qb[:, None] - Qf[None]) / v_c, axis=2)  # (n, Nf)
        dt = tb[:, None] - Tf[None]
        root = np.broadcast_to((new < n_roots)[:, None], reach.shape)
        start = np.broadcast_to((Tf == 0.0)[None], reach.shape)
        late = np.broadcast_to((Rb[new] >= best)[:, None], reach.shape)
    base = ramp * (root.astype(float) + start)
    ok = (dt >= reach / max(SPEEDS) + base) & ~late
    # nearest first; ties (the roots: the goal at many times) earliest first
    order = np.argsort(np.where(ok, reach, np.inf), axis=1, kind="stable")[:, :JOINS]
    i = np.repeat(np.arange(len(new)), order.shape[1])
    j = order.reshape(-1)
    keep = ok[i, j]
    i, j = i[keep], j[keep]
    d, r, b0 = dt[i, j], reach[i, j], base[i, j]
    # slow enough: move all the way; else a wait, then a move at v_c from rest
    move = np.where(d <= r / min(SPEEDS) + b0, d, np.minimum(d, r + b0 + ramp * ~start[i, j]))
    wait = d - move
    f, b = (new[i], j) if forward else (j, new[i])
    clear = _edges_clear(problem, Qf[f], Qb[b], Tf[f], wait, move)
    found = [(float(Rb[b[k]]), int(f[k]), int(b[k]), float(move[k])) for k in np.flatnonzero(clear)]
    return found, len(i)


def _path(fwd: _Tree, bwd: _Tree, a: int, b: int, join_move: float) -> tuple[np.ndarray, np.ndarray]:
    """(m, nq) states and (m,) times of the path start → forward node ``a`` → backward node
    ``b`` → root (each edge: a wait at its earlier end, then its move)."""
    Qf, Tf, _, _, Mf = fwd.arrays()
    Qb, Tb, _, _, Mb = bwd.arrays()
    chain = [(Qf[n], Tf[n], Mf[n]) for n in fwd.chain(a)[::-1]]
    later = [(Qb[n], Tb[n]) for n in bwd.chain(b)]
    moves = [join_move] + [Mb[n] for n in bwd.chain(b)[:-1]]
    q, t = [chain[0][0]], [0.0]
    for (q1, t1, m1) in chain[1:]:
        _wait_move(q, t, q1, t1, m1)
    for (q1, t1), m1 in zip(later, moves):
        _wait_move(q, t, q1, t1, m1)
    return np.array(q), np.array(t)


def _wait_move(q: list, t: list, q1: np.ndarray, t1: float, move: float) -> None:
    """Append the edge to (``q1``, ``t1``) of move ``move`` [s]: a wait, then the move."""
    begin = float(t1) - float(move)
    if begin > t[-1] + 1e-12:
        q.append(q[-1])
        t.append(begin)
    q.append(q1)
    t.append(max(float(t1), t[-1]))


def _clearance(problem: Any, q: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(n,) the smallest obstacle or self-distance [m] of each of the motions ``q``
    (n, k, nq) at times ``t`` (n, k) [s]: one batched call of the problem's checker."""
    frames = problem.robot.kinematics.joint_frames(q)
    d = problem.checker.min_distances(q, t, joint_frames=frames).distance.min(axis=-1, initial=np.inf)
    if problem.self_check is not None:
        d = np.minimum(d, problem.self_check.min_distances(q, frames, below=d).distance)
    return d


def _guide_points(problem: Any, guides: Any) -> np.ndarray:
    """(k · :data:`GUIDE_POINTS`, nq) configurations [rad | m] along the guide moves
    ``guides`` (k, n_var), or along the straight move when ``None``."""
    traj = problem.trajectory
    x = traj.straight_line(float(problem.xl[0]))[None] if guides is None else guides
    x = np.asarray(x, dtype=float).reshape(-1, problem.n_var)
    if not len(x):
        x = traj.straight_line(float(problem.xl[0]))[None]
    return traj.sample(x, np.linspace(0.0, 1.0, GUIDE_POINTS), orders=(0,)).q.reshape(-1, traj.nq)


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
    ok[i[try_], j[try_]] = _edges_clear(
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


def _edges_clear(
    problem: Any, qa: np.ndarray, qb: np.ndarray, ta: np.ndarray, wait: np.ndarray,
    move: np.ndarray,
) -> np.ndarray:
    """(n,) whether each edge (a wait of ``wait`` [s] at ``qa`` (n, nq) from time ``ta``
    (n,) [s], then a straight move to ``qb`` in ``move`` [s]) keeps every distance ≥
    margin + :data:`CLEARANCE` at its :data:`EDGE_SAMPLES` instants (its later end
    included)."""
    if not len(qa):
        return np.zeros(0, dtype=bool)
    tau = (wait + move)[:, None] * (np.arange(1, EDGE_SAMPLES + 1) / EDGE_SAMPLES)[None]
    w = np.clip((tau - wait[:, None]) / np.maximum(move, 1e-12)[:, None], 0.0, 1.0)
    q = qa[:, None] + w[..., None] * (qb - qa)[:, None]  # (n, k, nq)
    return _clearance(problem, q, ta[:, None] + tau) >= problem.settings.margin + CLEARANCE


def fit_timed_path(problem: Any, q: Any, t: Any, T: float, smoothing: float = 0.0) -> np.ndarray:
    r"""(n_var,) the decision vector of travel time ``T`` [s] whose free control points
    :math:`P` minimise, over :data:`FIT_SAMPLES` instants :math:`t_k` evenly over [0, T],

    .. math::
        \sum_k \lVert q(t_k) - p(t_k) \rVert^2
        + \mu \sum_k \sum_i \big(\ddot q_i(t_k) / a_{\max,i}\big)^2,

    :math:`p` the timed path through the states ``q`` at the times ``t`` (linear between
    them, held at the last after ``t[-1]``) and :math:`\mu` = ``smoothing`` [rad²]
    (≥ 0; it trades the fit for smaller accelerations); clipped to the bounds.

    Parameters
    ----------
    problem: the :class:`~adept_traj.problem.TrajectoryProblem`.
    q: (m, nq) states [rad | m], m ≥ 2.
    t: (m,) their times [s], non-decreasing from 0.
    T: travel time [s], at least ``t[-1]``.
    smoothing: the weight :math:`\mu` [rad²] of the accelerations.
    """
    traj = problem.trajectory
    q, t = np.asarray(q, dtype=float), np.asarray(t, dtype=float)
    if q.ndim != 2 or q.shape[1] != traj.nq or t.shape != (len(q),) or len(q) < 2:
        raise ConfigurationError(
            f"q must have shape (m, {traj.nq}) with m ≥ 2 and t shape (m,); "
            f"got {q.shape} and {t.shape}"
        )
    if not (np.all(np.isfinite(t)) and t[0] == 0.0 and np.all(np.diff(t) >= 0.0)):
        raise ConfigurationError(f"t must be finite and non-decreasing from 0 [s]; got {t}")
    if not (np.isfinite(T) and T >= t[-1] and T > 0.0):
        raise ConfigurationError(f"T must be finite, > 0 and ≥ t[-1] = {t[-1]} [s]; got {T}")
    if not (np.isfinite(smoothing) and smoothing >= 0.0):
        raise ConfigurationError(f"smoothing must be finite and ≥ 0 [rad²]; got {smoothing}")
    s = np.linspace(0.0, 1.0, FIT_SAMPLES)
    target = np.stack([np.interp(s * T, t, q[:, j]) for j in range(traj.nq)], axis=1)
    free = np.empty((traj.n_free, traj.nq))
    acc = problem.robot.limits.acceleration
    for j in range(traj.nq):  # per joint: its own acceleration scale
        rows, rhs = [], []
        for order, weight, goal in ((0, 1.0, target[:, j]), (2, smoothing, 0.0)):
            B = traj.basis_matrix(s, order) * (np.sqrt(weight) / (T**order * acc[j] ** (order / 2)))
            ends = B[:, :3].sum(axis=1) * traj.start[j] + B[:, -3:].sum(axis=1) * traj.goal[j]
            rows.append(B[:, 3:-3])
            rhs.append(np.sqrt(weight) * goal * (order == 0) - ends)
        free[:, j] = np.linalg.lstsq(np.concatenate(rows), np.concatenate(rhs), rcond=None)[0]
    return np.clip(traj.encode(float(T), free), problem.xl, problem.xu)


def timed_roadmap_starts(
    problem: Any, seed: int, *, guides: Any = None, n_starts: int = 3
) -> np.ndarray:
    """(k ≤ n_starts, n_var) starts from the timed trees (:func:`timed_paths`): the fits
    (:func:`fit_timed_path`) of their :data:`_PATHS` earliest arrivals, held to
    :data:`HOLDS` × their arrival time (at most the largest T), at each of
    :data:`SMOOTHINGS`; the evaluator-feasible ones first (fastest first), then the others
    by their distance violation × :data:`DISTANCE_WEIGHT` + their other violations (a
    limit is met by a slower move, a moving obstacle's phase is not); empty (0, n_var)
    when no pair of trees was joined.

    Parameters
    ----------
    problem: the :class:`~adept_traj.problem.TrajectoryProblem`.
    seed: seed of the trees' generators (≥ 0).
    guides: (k, n_var) guide moves of :func:`timed_paths` (default: the straight move).
    n_starts: most starts (≥ 1).
    """
    n_starts = as_integer(n_starts, "n_starts", minimum=1, error=ConfigurationError)
    found = timed_paths(problem, seed, guides=guides)
    t_max = float(problem.xu[0])
    fits = [
        fit_timed_path(problem, q, t, min(h * t[-1], t_max), mu)
        for q, t in zip(found.paths, found.times)
        for h in HOLDS
        for mu in SMOOTHINGS
    ]
    if not fits:
        return np.empty((0, problem.n_var))
    x = np.array(fits)
    g = np.maximum(problem.evaluate_batch(x).constraints, 0.0)
    key = DISTANCE_WEIGHT * g[:, -1] + g[:, :-1].sum(axis=1)
    key = np.where(key == 0.0, -1.0 / x[:, 0], key)  # the feasible first, fastest first
    return x[np.argsort(key, kind="stable")[:n_starts]]
