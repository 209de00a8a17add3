r"""The global stage: moves through random via configurations, to find the basins that the
evolutionary search and the straight or ramp starts miss.

Where an obstacle blocks the straight move and a fast move must pass on a particular side
of it, or fold the arm to get by it, or reach a place before a moving obstacle does, a
local solver needs a start in that basin. :class:`ViaPointSampling` draws rest-to-rest
moves that pass near one or two random **via configurations** :math:`v_i` (uniform inside
the joint limits, shrunk by :data:`LIMIT_INSET` of each range) at random normalised
times :math:`0 < s_1 < s_2 < 1`: the piecewise-linear joint path
:math:`p(u)` through :math:`(0, q_s), (s_1, v_1), [(s_2, v_2)], (1, q_g)`, timed by a
rest-to-rest S-curve :math:`u = \sigma(\xi)`, gives the free control points

.. math::
    P_c = p\big(\sigma(\xi_c)\big)

at their Greville abscissae :math:`\xi_c` (the spline rounds the corners at the vias).
The travel time is the move's kinematic minimum (:func:`~adept_traj.optimise.kinematic_time`)
times a factor drawn from :data:`SPEEDS` — against a moving obstacle the same path at
another speed passes it at another phase.

:func:`via_point_starts` evaluates batches of such moves, and as many seeded ramps at
their kinematic minimum T (:class:`~adept_traj.optimise.RampSampling`), with the
problem's evaluator (one batched call each) and returns the fastest evaluator-feasible move
of each basin (:func:`~adept_traj.optimise.basin_labels`), fastest first, and the
least-infeasible ones: starts for :func:`~adept_traj.optimise.refine_minimum_time`, whose
elastic solve may still reach the feasible set from them. Nothing about a scene is
assumed; every number comes from the seeded generator, so the same problem and seed give
the same starts.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.local.basins import basin_labels
from adept_traj.optimise.operators.repair import kinematic_time
from adept_traj.optimise.search.sampling import RampSampling
from adept_traj.process_pool import map_forked
from adept_traj.validation import as_integer

__all__ = [
    "GLOBAL_GAP",
    "GLOBAL_SEED",
    "LIMIT_INSET",
    "SPEEDS",
    "ViaPointSampling",
    "near_lower_bound",
    "via_point_starts",
]

#: The global stage runs when no certified refined move is within this fraction of the
#: kinematic lower bound T_lb (on the paper scene the fastest move is at 1.0036 × T_lb: no
#: move can be faster by more than 0.4 %, and the stage is skipped).
GLOBAL_GAP = 0.01

#: Seed of the global stage in the polish and the time-optimal mode: its starts are a
#: function of the problem alone, the same for every run, so the fastest move a run finds
#: does not hinge on the search's seed.
GLOBAL_SEED = 0

#: Fraction of each joint's range kept clear of its limits by the via configurations.
LIMIT_INSET = 0.05

#: Factors of the kinematic minimum T drawn for the travel time.
SPEEDS: tuple[float, ...] = (1.0, 1.0, 1.15, 1.35, 1.6)

#: Moves of each kind (via points, ramps) of one batch of :func:`via_point_starts` (one
#: evaluation of the batch by the problem).
_BATCH = 600

#: Least-infeasible moves returned after the feasible ones.
_LEAST_INFEASIBLE = 2


class ViaPointSampling:
    """Moves through one or two random via configurations (module docstring).

    Parameters
    ----------
    max_vias:
        Most via configurations of a move (1 or 2); each move has 1 … ``max_vias``.
    """

    def __init__(self, max_vias: int = 2) -> None:
        self.max_vias = as_integer(
            max_vias, "max_vias", minimum=1, maximum=2, error=ConfigurationError
        )

    def moves(self, problem: Any, n: int, rng: np.random.Generator) -> np.ndarray:
        """(n, n_var) moves through random vias, each at a drawn multiple of its kinematic
        minimum T, clipped to the decision bounds; randomness from ``rng`` only."""
        n = as_integer(n, "n", minimum=0, error=ConfigurationError)
        traj = problem.trajectory
        lower, upper = problem.robot.limits.lower, problem.robot.limits.upper
        inset = LIMIT_INSET * (upper - lower)
        k = rng.integers(1, self.max_vias + 1, size=n)  # vias per move
        vias = rng.uniform(lower + inset, upper - inset, size=(n, 2, traj.nq))
        s = np.sort(rng.uniform(0.15, 0.85, size=(n, 2)), axis=1)
        s[k == 1, 1] = 1.0  # one via: its second slot is the goal
        vias[k == 1, 1] = traj.goal
        knots = np.concatenate([np.zeros((n, 1)), s, np.ones((n, 1))], axis=1)  # (n, 4)
        points = np.concatenate(
            [
                np.broadcast_to(traj.start, (n, 1, traj.nq)),
                vias,
                np.broadcast_to(traj.goal, (n, 1, traj.nq)),
            ],
            axis=1,
        )  # (n, 4, nq)
        u = _smooth_step(traj.free_abscissae)  # (n_free,) rest to rest
        free = _piecewise_linear(knots, points, u)  # (n, n_free, nq)
        x = traj.encode(np.full(n, problem.xu[0]), free)
        x = np.clip(x, problem.xl, problem.xu)
        speed = np.asarray(SPEEDS)[rng.integers(0, len(SPEEDS), size=n)]
        x[:, 0] = np.clip(
            kinematic_time(problem, x) * speed * (1.0 + 1e-9), problem.xl[0], problem.xu[0]
        )
        return x


def via_point_starts(
    problem: Any,
    seed: int,
    *,
    n_starts: int = 3,
    n_batches: int = 1,
    n_moves: int = _BATCH,
    processes: int = 1,
) -> np.ndarray:
    """(k, n_var): the global stage's starts — the fastest evaluator-feasible move of each
    of at most ``n_starts`` basins, fastest first, then the :data:`_LEAST_INFEASIBLE`
    infeasible moves of least total violation (an elastic solve may reach the feasible
    set from them), from up to ``n_batches`` batches (the next only while fewer than
    ``n_starts`` basins were found) of ``n_moves`` via-point moves and ``n_moves``
    seeded ramps (:class:`~adept_traj.optimise.RampSampling`, each at its kinematic
    minimum T: the shape of time-optimal moves).

    Parameters
    ----------
    problem: the :class:`~adept_traj.problem.TrajectoryProblem`.
    seed: seed of the generators (≥ 0).
    n_starts: most feasible starts returned (≥ 1).
    n_batches: most batches (≥ 1).
    n_moves: moves of each kind per batch (≥ 1).
    processes: processes evaluating a batch, each a share of its moves
        (:func:`~adept_traj.process_pool.map_forked`; ≥ 1, for a problem evaluating in one
        process; a problem with workers of its own uses them): the same starts.
    """
    seed = as_integer(seed, "seed", minimum=0, error=ConfigurationError)
    n_starts = as_integer(n_starts, "n_starts", minimum=1, error=ConfigurationError)
    n_batches = as_integer(n_batches, "n_batches", minimum=1, error=ConfigurationError)
    n_moves = as_integer(n_moves, "n_moves", minimum=1, error=ConfigurationError)
    processes = as_integer(processes, "processes", minimum=1, error=ConfigurationError)
    sampler = ViaPointSampling()
    tried, violation = [], []
    for batch in range(n_batches):
        rng = np.random.default_rng([seed, 7, batch])
        ramps = RampSampling().ramps(problem, n_moves, rng, fast_times=False)
        t = kinematic_time(problem, ramps) * (1.0 + 1e-9)
        ramps[:, 0] = np.clip(t, problem.xl[0], problem.xu[0])
        x = np.concatenate([sampler.moves(problem, n_moves, rng), ramps])
        g = _constraints(problem, x, processes)
        tried.append(x)
        violation.append(np.maximum(g, 0.0).sum(axis=1))
        ok = np.concatenate(violation) == 0.0
        found = np.concatenate(tried)[ok]
        if len(found) and len(np.unique(basin_labels(problem, found))) >= n_starts:
            break
    x, v = np.concatenate(tried), np.concatenate(violation)
    found = x[v == 0.0]
    found = found[np.argsort(found[:, 0], kind="stable")]
    _, first = np.unique(basin_labels(problem, found), return_index=True)
    worst = np.flatnonzero(v > 0.0)
    least = worst[np.argsort(v[worst], kind="stable")][:_LEAST_INFEASIBLE]
    return np.concatenate([found[np.sort(first)][:n_starts], x[least]])


def _constraints(problem: Any, x: np.ndarray, processes: int) -> np.ndarray:
    """(n, n_con) the constraints of the moves ``x`` (n, n_var), in ``processes`` shares
    where the problem evaluates in one process (row by row the same values)."""
    shares = processes if problem.settings.workers == 1 else 1
    parts = np.array_split(x, min(shares, len(x)))
    values = map_forked(lambda part: problem.evaluate_batch(part).constraints, parts, len(parts))
    return np.concatenate(values)


def near_lower_bound(
    problem: Any, outcomes: Any, floor: float = 0.0, gap: float = GLOBAL_GAP
) -> bool:
    """Whether a certified refinement of ``outcomes`` (each with ``certified`` and ``x``)
    has a T within ``gap`` (a fraction, default :data:`GLOBAL_GAP`) of the problem's
    kinematic lower bound, or of ``floor`` [s] when larger (no move can then be faster by
    more than that, and the global stage is not needed). ``floor``: the fastest certified
    move of a relaxation of the problem (:func:`~adept_traj.optimise.global_stage`: the
    problem without its moving obstacles, whose feasible set contains the problem's), a
    bound as good as the relaxation's own search (which ends within
    :data:`~adept_traj.optimise.RELAXED_GAP` of T_lb)."""
    bound = max(problem.lower_bound.T_min, float(floor)) * (1.0 + gap)
    return any(o.certified and o.x[0] <= bound for o in outcomes)


def _smooth_step(xi: np.ndarray) -> np.ndarray:
    r"""The rest-to-rest time warp :math:`\sigma(\xi) = 10\xi^3 - 15\xi^4 + 6\xi^5` (zero
    speed and acceleration at both ends) of ``xi`` (k,) in [0, 1]."""
    xi = np.clip(xi, 0.0, 1.0)
    return xi**3 * (10.0 + xi * (-15.0 + 6.0 * xi))


def _piecewise_linear(knots: np.ndarray, points: np.ndarray, u: np.ndarray) -> np.ndarray:
    """(n, k, nq) the piecewise-linear paths through ``points`` (n, m, nq) at ``knots``
    (n, m) increasing from 0 to 1, at ``u`` (k,)."""
    n = len(knots)
    seg = np.sum(u[None, :, None] >= knots[:, None, 1:-1], axis=2)  # (n, k) interior knots ≤ u
    rows = np.arange(n)[:, None]
    k0, k1 = knots[rows, seg], knots[rows, seg + 1]
    w = np.where(k1 > k0, (u[None, :] - k0) / np.where(k1 > k0, k1 - k0, 1.0), 1.0)
    p0, p1 = points[rows, seg], points[rows, seg + 1]  # (n, k, nq)
    return p0 + w[..., None] * (p1 - p0)
