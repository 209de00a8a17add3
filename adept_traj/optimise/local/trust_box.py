r"""The trust-box SQP of the certified local solver
(:func:`~adept_traj.optimise.refine_minimum_time`): the fastest move near a start inside
the smooth per-sample rows of :func:`~adept_traj.problem.local_constraints`.

:func:`trust_box_solve` runs the SQP of :func:`~adept_traj.optimise.local.sqp.sqp` (Kraft's
SLSQP method, DAQP for its subproblem) first over the whole decision domain (from a
start near its optimum, as on the paper scene, a few iterations reach it; from a start
outside the rows on the elastic problem below, whose subproblem stays compatible there:
``docs/engine.md``), then in **trust boxes** around the current point (half-width
:data:`BOX` of each control point's range and :data:`BOX_T` of T), each on the **elastic**
problem

.. math::
    \min_{x, e} \; T + \mu e \quad \text{s.t.} \quad g_k(x) \le e - \tau \ \ (k \in W),
    \quad e \ge 0, \quad x \in \text{box},

over a working set W of the rows that may bind inside the box by their linear bound
(the subproblem's cost grows with its rows; a left-out row that binds at the answer is
added and the box solved again). The box keeps a step from jumping through a thin obstacle
(a pendulum's rod), where the linearised distance rows mislead; the elastic e keeps the
linearisations compatible from a start outside the rows (the plain subproblem becomes
infeasible there and the solve stops, measured on the detour scene). When the answer lies
outside the rows, shorter steps towards it (:data:`FRACTIONS`) are tried. The next box is
centred at the fastest point met inside every row; a box without progress is followed by
one half as wide, and a second one ends the solve (a local optimum).
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from adept_traj.optimise.local.sqp import sqp
from adept_traj.problem import CONSTRAINT_KINDS, local_constraints

__all__ = ["BOX", "BOX_T", "FRACTIONS", "SolveCounts", "constraint_rows", "trust_box_solve"]

#: Index of the distance rows in :data:`~adept_traj.problem.CONSTRAINT_KINDS`.
_DISTANCE = CONSTRAINT_KINDS.index("distance")

#: Penalty μ of the elastic variable [s per unit of normalised violation].
_PENALTY = 100.0

#: Tightening τ of the rows handed to the SQP (normalised units): its answers then lie
#: inside the rows, not on them to rounding.
_TIGHTEN = 1e-7

#: A point is inside the rows when none exceeds this (normalised units; the evaluator and
#: the certificate decide afterwards).
_INSIDE = 1e-8

#: Half-width of the trust box around the current point: a fraction of each control
#: point's range, and of T (the T part scaled with it when the box shrinks).
BOX, BOX_T = 0.10, 0.20

#: SQP iterations per box, and of the first solve over the whole domain (from a start
#: near its optimum, as on the paper scene, that solve converges in 3–10).
_BOX_ITERATIONS, _FREE_ITERATIONS = 10, 15

#: Rows kept in a box's working set: those whose linear bound reaches −slack.
_ROW_SLACK = 0.05

#: Fractions of the way from the box's start to the solver's answer that are tried, in
#: turn, when the answer lies outside the rows (the SQP meets the nonlinear rows only to
#: first order; a shorter step in its direction often stays inside).
FRACTIONS = 0.5 ** np.arange(6)

#: Solves of one box while it finds no point inside, each adding the rows left out that
#: bound its answer (a box that found one goes on: the next box keeps those rows).
_WORKING_SET_ROUNDS = 3

#: A box whose best point lowers T by less than this fraction of T ends the solve.
_PROGRESS = 1e-4


class SolveCounts:
    """Work done by one refinement: SQP iterations, constraint-and-Jacobian and
    evaluator calls, and the seconds spent in them [s] (mutable counters)."""

    def __init__(self) -> None:
        self.iterations = 0
        self.evaluations = 0
        self.evaluation_s = 0.0


def constraint_rows(
    problem: Any, x: np.ndarray, extra: np.ndarray, buffer: float, counts: SolveCounts
) -> tuple[np.ndarray, np.ndarray]:
    """The rows g (m,) at ``x`` with the extra buffer, and their Jacobian (m, n_var)."""
    tic = time.perf_counter()
    lc = local_constraints(problem, x, extra_samples=extra if len(extra) else None)
    counts.evaluations += 1
    counts.evaluation_s += time.perf_counter() - tic
    g = lc.values[0]
    if buffer:
        g = g + (buffer / problem.settings.influence) * (lc.kind == _DISTANCE)
    return g, lc.jacobian[0]


def trust_box_solve(
    problem: Any,
    x: np.ndarray,
    extra: np.ndarray,
    buffer: float,
    max_boxes: int,
    counts: SolveCounts,
) -> tuple[np.ndarray, bool]:
    """The trust-box SQP of the module docstring from ``x``: the fastest point met inside
    every row (within :data:`_INSIDE`) and True, else ``x`` and False."""
    span = np.where(problem.xu > problem.xl, problem.xu - problem.xl, 1.0)
    g, J = constraint_rows(problem, x, extra, buffer, counts)
    inside = x.copy() if np.max(g) <= _INSIDE else None
    beta = math.inf  # the first box is the whole domain: from near an optimum, a few steps
    binding = np.zeros(len(g), dtype=bool)  # rows left out of a working set that bound
    for _ in range(max_boxes):
        half = np.minimum(beta * span, span)
        half[0] = min(BOX_T * beta / BOX * x[0], span[0])
        lower = np.maximum(problem.xl, x - half)
        upper = np.minimum(problem.xu, x + half)
        # the working set: rows that may bind inside the box by their linear bound
        live = ((g + np.abs(J) @ half > -_ROW_SLACK) | binding) & np.any(J != 0.0, axis=1)
        free = beta == math.inf
        iterations = _FREE_ITERATIONS if free else _BOX_ITERATIONS
        elastic = not free or inside is None  # from outside: elastic over the whole domain too
        for _ in range(_WORKING_SET_ROUNDS):
            found, violated, converged = _box_solve(
                problem, x, extra, buffer, lower, upper, live, iterations, elastic, counts
            )
            binding |= violated & ~live
            progress = found is not None and (inside is None or found[0] < inside[0])
            if progress or not np.any(violated & ~live) or inside is None:
                break  # progress (the next box keeps those rows); from outside: one solve
            live |= violated  # a row left out binds after all: solve the box again with it
        if found is not None and (inside is None or found[0] < inside[0]):
            improved = inside is None or found[0] < inside[0] * (1.0 - _PROGRESS)
            inside = found
            x = found
            g, J = constraint_rows(problem, x, extra, buffer, counts)
            if (not improved and not free) or (free and converged):
                break  # a local optimum
            beta = min(beta, BOX)
        elif inside is None and free:
            beta = BOX  # the whole domain gave no point inside: one box from the start
        elif inside is None:
            break  # no way into the rows from this start
        elif beta >= BOX:
            beta = min(beta, 2.0 * BOX) / 2.0  # nothing better: a smaller box
        else:
            break  # nothing better in the smallest box: a local optimum
    return (inside, True) if inside is not None else (x, False)


def _box_solve(
    problem: Any,
    x: np.ndarray,
    extra: np.ndarray,
    buffer: float,
    lower: np.ndarray,
    upper: np.ndarray,
    live: np.ndarray,
    iterations: int,
    elastic: bool,
    counts: SolveCounts,
) -> tuple[np.ndarray | None, np.ndarray, bool]:
    """The SQP in the box on min T, g_live ≤ 0 or (``elastic``) on min T + μ e,
    g_live ≤ e − τ, e ≥ 0: the fastest point met inside every row (``None``: none), the
    rows violated at the solver's answer (bool (m,)) and whether the SQP converged."""
    n = problem.n_var
    cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}
    best: list[Any] = [None]

    def rows(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = y[:n].tobytes()
        if key not in cache:
            cache.clear()
            xc = np.clip(y[:n], problem.xl, problem.xu)
            cache[key] = constraint_rows(problem, xc, extra, buffer, counts)
            if np.max(cache[key][0]) <= _INSIDE and (best[0] is None or xc[0] < best[0][0]):
                best[0] = xc
        return cache[key]

    g0 = rows(x)[0]
    if elastic:  # y = [x, e]: g_live − e + τ ≤ 0, e ≥ 0
        cost = np.zeros(n + 1)
        cost[0], cost[-1] = 1.0, _PENALTY
        y0 = np.concatenate([x, [max(0.0, float(np.max(g0[live], initial=0.0)))]])
        low, high = np.append(lower, 0.0), np.append(upper, np.inf)
        column = -np.ones((int(live.sum()), 1))

        def constraints(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            g, J = rows(y)
            return g[live] - y[-1] + _TIGHTEN, np.hstack([J[live], column])

    else:  # y = x: g_live ≤ 0
        cost = np.zeros(n)
        cost[0] = 1.0
        y0, low, high = x, lower, upper

        def constraints(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            g, J = rows(y)
            return g[live], J[live]

    res = sqp(cost, y0, low, high, constraints, max_iter=iterations, tol=1e-10)
    counts.iterations += int(res.nit)
    end = np.clip(res.x[:n], problem.xl, problem.xu)
    g_end = rows(end)[0]
    if best[0] is not None and best[0][0] <= end[0]:
        return best[0], g_end > _INSIDE, res.converged
    start = best[0] if best[0] is not None else x
    for fraction in FRACTIONS[1:]:  # the answer is outside: the way to it, shorter
        if np.max(g_end) <= _INSIDE or (best[0] is not None and best[0][0] <= end[0]):
            break
        rows(start + fraction * (end - start))
    return best[0], g_end > _INSIDE, res.converged
