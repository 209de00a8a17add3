r"""The global stage against moving obstacles: two trees over joint space × scene time.

A fast move past a swinging load must be at the right place at the right time; starts made
of a path at a chosen speed (:mod:`~adept_traj.optimise.local.via_points`, the relaxed optimum
stretched) are blind to the phase. :func:`timed_paths` grows two trees of **timed states**
:math:`(q, t)` (a bidirectional RRT in joint space × scene time): one forward in time from
:math:`(q_s, 0)`, one backward in time from the goal held at :data:`ROOTS` arrival times
from the kinematic lower bound to the largest T (those where the goal pose is clear). An
edge from an earlier state :math:`(q_a, t_a)` to a later one :math:`(q_b, t_b)` waits at
:math:`q_a`, then moves along the straight joint-space line in

.. math::
    \tau = \max_i \frac{|q_{b,i} - q_{a,i}|}{f\, v_{c,i}} + \rho\, n_{rest},

:math:`f \in` :data:`~adept_traj.optimise.local.timed_edges.SPEEDS`, :math:`v_c` the
characteristic speeds (:func:`~adept_traj.optimise.local.timed_edges.characteristic_speed`),
:math:`\rho` the rest ramp (:func:`~adept_traj.optimise.local.timed_edges.rest_ramp`) and
:math:`n_{rest}` its ends at rest (after a wait, at the start, into the goal). Each round
draws :data:`BATCH` targets per tree (near the configurations of guide moves with
probability :data:`GUIDE_BIAS`, else uniform inside the joint limits shrunk by
:data:`~adept_traj.optimise.LIMIT_INSET`), extends the nearest node of each (in time at
:math:`v_c`, plus :data:`EARLY` × its time or arrival: a bias toward early arrival) by at
most :data:`STEP` [s] at :math:`v_c` (forward edges first wait with probability
:data:`WAIT_SHARE`, up to :data:`MAX_WAIT`), and joins every new node to its :data:`JOINS`
nearest nodes of the other tree that it can reach in time (the goal's roots earliest
first). Every edge is checked at instants spread evenly over its time with the problem's
own checker (:func:`~adept_traj.optimise.edges_clear`: one batched call per tree and
round, obstacle distances at those scene times and self-distances) and kept where every
distance is at least the problem's margin. Once the trees are joined, nodes later than the
earliest arrival are not extended; a pair of trees stops after :data:`ROUNDS` rounds, or
:data:`ROUNDS_AFTER` rounds after its first join, and up to :data:`TREES` pairs are grown
(each from its own seed) until one is joined: the sample budget is bounded.

:func:`~adept_traj.optimise.shortcut` straightens a joined path (the fewest states, each
at its time), and :mod:`~adept_traj.optimise.local.timed_starts` fits it into the decision
vector. Everything is drawn from generators seeded by ``seed``: the same problem and seed
give the same paths.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.local.timed_edges import (
    SPEEDS,
    characteristic_speed,
    clearance,
    edges_clear,
    rest_ramp,
    shortcut,
)
from adept_traj.optimise.local.via_points import LIMIT_INSET
from adept_traj.validation import as_integer

__all__ = [
    "BATCH",
    "EARLY",
    "GUIDE_BIAS",
    "GUIDE_POINTS",
    "GUIDE_SPREAD",
    "JOINED_PATHS",
    "JOINS",
    "MAX_WAIT",
    "ROOTS",
    "ROUNDS",
    "ROUNDS_AFTER",
    "STEP",
    "TREES",
    "WAIT_SHARE",
    "TimedPaths",
    "timed_paths",
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

#: Spread of the targets about a guide configuration: the standard deviation per joint is
#: this time [s] × the characteristic speed.
GUIDE_SPREAD = 0.3

#: Configurations taken along each guide move.
GUIDE_POINTS = 40

#: Longest move of an extension [s] at the characteristic speed.
STEP = 0.25

#: Share of the extensions that wait before their move.
WAIT_SHARE = 0.3

#: Longest wait [s] before an extension's move (drawn uniformly up to it).
MAX_WAIT = 0.5

#: Weight of a node's time (forward) or arrival (backward) in the nearest-node choice.
EARLY = 0.25

#: Joined paths returned by :func:`timed_paths` (the earliest arrivals).
JOINED_PATHS = 4


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
    rounds = as_integer(
        ROUNDS if rounds is None else rounds, "rounds", minimum=1, error=ConfigurationError
    )
    n_nodes = n_edges = 0
    for k in range(TREES):  # fresh trees until a pair is joined
        rng = np.random.default_rng([seed, 24, k])
        fwd, bwd, joins, n = _grow(problem, rng, rounds, guides)
        n_nodes, n_edges = n_nodes + fwd.size + bwd.size, n_edges + n
        if joins:
            break
    joins.sort()
    paths = [shortcut(problem, *_path(fwd, bwd, a, b, m)) for _, a, b, m in joins[:JOINED_PATHS]]
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
    roots = roots[clearance(problem, here, roots[:, None]) >= problem.settings.margin]
    bwd = _Tree(np.broadcast_to(goal, (len(roots), len(goal))).copy(), roots, roots)
    joins: list[tuple[float, int, int, float]] = []
    n_edges, left = 0, rounds
    while left > 0 and len(roots):
        left -= 1
        best = min(joins)[0] if joins else np.inf
        for forward in (True, False):
            tree = fwd if forward else bwd
            new, n = _extend(problem, tree, forward, best, rng, box, way, v_c, ramp)
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
    problem: Any,
    tree: _Tree,
    forward: bool,
    best: float,
    rng: Any,
    box: Any,
    way: Any,
    v_c: np.ndarray,
    ramp: float,
) -> tuple[np.ndarray, int]:
    """One round of extensions of ``tree`` (forward in time or backward); returns the new
    nodes' indices and the edges checked."""
    Q, T, key, _, _ = tree.arrays()
    nq = Q.shape[1]
    target = rng.uniform(box[0], box[1], size=(BATCH, nq))
    guided = rng.random(BATCH) < GUIDE_BIAS
    noise = rng.normal(0.0, 1.0, (int(guided.sum()), nq)) * GUIDE_SPREAD * v_c
    target[guided] = np.clip(way[rng.integers(0, len(way), guided.sum())] + noise, *box)
    speed = np.asarray(SPEEDS)[rng.integers(0, len(SPEEDS), BATCH)]
    # backward edges never wait: near the goal, where a moving obstacle blocking it
    # passes, a wait is seldom clear (measured)
    share = WAIT_SHARE if forward else 0.0
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
        clear = edges_clear(problem, Q[a], q_new, T[a], wait, move)
    else:
        clear = edges_clear(problem, q_new, Q[a], t_new, wait, move)
    if not clear.any():
        return np.zeros(0, dtype=int), len(a)
    c = clear
    first = tree.add(q_new[c], t_new[c], key[a[c]], a[c], move[c])
    return first + np.arange(int(c.sum())), len(a)


def _join(
    problem: Any,
    fwd: _Tree,
    bwd: _Tree,
    new: np.ndarray,
    forward: bool,
    best: float,
    v_c: np.ndarray,
    ramp: float,
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
    clear = edges_clear(problem, Qf[f], Qb[b], Tf[f], wait, move)
    found = [(float(Rb[b[k]]), int(f[k]), int(b[k]), float(move[k])) for k in np.flatnonzero(clear)]
    return found, len(i)


def _path(
    fwd: _Tree, bwd: _Tree, a: int, b: int, join_move: float
) -> tuple[np.ndarray, np.ndarray]:
    """(m, nq) states and (m,) times of the path start → forward node ``a`` → backward node
    ``b`` → root (each edge: a wait at its earlier end, then its move)."""
    Qf, Tf, _, _, Mf = fwd.arrays()
    Qb, Tb, _, _, Mb = bwd.arrays()
    chain = [(Qf[n], Tf[n], Mf[n]) for n in fwd.chain(a)[::-1]]
    later = [(Qb[n], Tb[n]) for n in bwd.chain(b)]
    moves = [join_move] + [Mb[n] for n in bwd.chain(b)[:-1]]
    q, t = [chain[0][0]], [0.0]
    for q1, t1, m1 in chain[1:]:
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


def _guide_points(problem: Any, guides: Any) -> np.ndarray:
    """(k · :data:`GUIDE_POINTS`, nq) configurations [rad | m] along the guide moves
    ``guides`` (k, n_var), or along the straight move when ``None``."""
    traj = problem.trajectory
    x = traj.straight_line(float(problem.xl[0]))[None] if guides is None else guides
    x = np.asarray(x, dtype=float).reshape(-1, problem.n_var)
    if not len(x):
        x = traj.straight_line(float(problem.xl[0]))[None]
    return traj.sample(x, np.linspace(0.0, 1.0, GUIDE_POINTS), orders=(0,)).q.reshape(-1, traj.nq)
