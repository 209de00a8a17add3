r"""The weighted-sum mode of :func:`~adept_traj.plan`: one move that minimises a weighted sum.

``plan(problem, algorithm="time-optimal", weights=w)`` (``adept-traj plan --algorithm
time-optimal --weights w1,...,w6``) solves

.. math::
    \min_x f_w(x) = \sum_i \hat w_i \sigma_i \frac{z_i(x)}{r_i} \quad \text{s.t.} \quad
    g_k(x) \le 0 \ \forall k, \qquad x_l \le x \le x_u,

with the fixed normalisation :math:`r` of :func:`~adept_traj.analysis.weighted_sum` (the
straight move at :math:`T_{lb}`) and the smooth per-sample constraints :math:`g_k` of
:func:`~adept_traj.problem.local_constraints`, by :func:`weighted_run`:

1. the minimum-T moves of :func:`~adept_traj.optimise.time_optimal_run` (multi-start SLSQP
   from the straight move and seeded ramps), each distinct feasible one a start;
2. from each start, :func:`weighted_descent`: **trust-region steps**. Each step is the
   SLSQP solve of :mod:`adept_traj.optimise.local.epsilon_constraint` with the cost :math:`c \cdot
   \hat z` (:attr:`~adept_traj.analysis.WeightedSum.cost`; z3 and z4 in epigraph form,
   exact gradients) and no "not worse" rows, inside the box :math:`|x - x_0| \le \beta
   (x_u - x_l)`, β = :data:`WEIGHTED_BOX`, around the current move, at most
   :data:`STEP_EVALUATIONS` constraint-and-Jacobian evaluations; after every SLSQP
   iteration the moves from the best so far towards the iterate (fractions 1, ½, …,
   1/32, T raised to the kinematic minimum) are evaluated by the problem and the best
   that is feasible and lowers :math:`f_w` (of the evaluator's objectives, not the
   solver's model) is kept. The next step starts from the kept move; the descent stops
   when a step lowers :math:`f_w` by less than :data:`STOP_DECREASE` or the start's
   budget of ``max_evaluations`` is spent.
3. The population is the minimum-T moves and the descended ones; ``plan`` certifies the
   front and reports the first **certified** member by increasing :math:`f_w` (a
   descended move that fails its certificate is passed over: the minimum-T move, whose
   :math:`f_w` is the start's, then stands).

Why so: a direct SLSQP on :math:`f_c` from front members left the feasible set and did not
converge on 5 of 5 members (``docs/engine.md``); the steps only ever keep a move the
evaluator finds feasible. The box and the budget were chosen on the paper scene (five
weight vectors, 3 starts, ``benchmarks/bench_weighted.py``, figures in
``docs/performance.md``): β = 0.3 with 100 evaluations a start gave the least sum of the
five best :math:`f_w` (2.882) at the least cost; β = 0.1 reached less (2.942), β = 0.5 was
worse on z2 (0.688 against 0.673), the ε-step's 3 % needed many more evaluations (from one
start, weights on z2: 404 for 0.803, against 170 with β = 0.1). Deterministic: the same
problem, seed and weights give the same bits (SLSQP with one BLAS thread).
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np

from adept_traj.analysis.weighted_sum import WeightedSum, weighted_sum
from adept_traj.errors import ConfigurationError
from adept_traj.optimise.local.epsilon_constraint import checked_start, epsilon_solve
from adept_traj.optimise.local.minimum_time import PolishOutcome
from adept_traj.optimise.local.polish_modes import time_optimal_run, with_members
from adept_traj.problem import from_pymoo
from adept_traj.validation import as_integer, check_type

__all__ = [
    "MAX_EVALUATIONS_PER_START",
    "STEP_EVALUATIONS",
    "STOP_DECREASE",
    "WEIGHTED_BOX",
    "weighted_descent",
    "weighted_run",
]

#: Half-width of each step's box, a fraction of each variable's range (xu − xl).
WEIGHTED_BOX = 0.3

#: Most constraint-and-Jacobian evaluations of one step (as the ε-step's).
STEP_EVALUATIONS = 20

#: The descent stops after a step that lowers f_w by less than this (f_w is O(1): the
#: weights sum to 1 and each objective is divided by its scale).
STOP_DECREASE = 1e-4

#: Default budget of evaluations of the steps from one start (gradient evaluations and
#: batches of moves; module docstring: 200 gave no lower f_w on the paper scene).
MAX_EVALUATIONS_PER_START = 100

#: SLSQP iterations of one step (the step's evaluation bound stops it first).
_STEP_ITERATIONS = 30


def weighted_descent(
    problem: Any,
    x0: Any,
    weighted: WeightedSum,
    *,
    max_evaluations: int = MAX_EVALUATIONS_PER_START,
) -> PolishOutcome:
    """Lower :math:`f_w` from the feasible move ``x0`` (n_var,) by trust-region steps with
    every constraint kept (module docstring, step 2).

    Parameters
    ----------
    problem, x0:
        As :func:`~adept_traj.optimise.local.epsilon_constraint.epsilon_step`.
    weighted:
        The :class:`~adept_traj.analysis.WeightedSum` to minimise.
    max_evaluations:
        Most evaluations of the steps (≥ :data:`STEP_EVALUATIONS`; a step starts only
        while a whole one fits).

    Returns
    -------
    PolishOutcome
        ``x`` the last kept move (``x0`` when no step lowered :math:`f_w`), its
        evaluation, ``n_iterations`` the SLSQP iterations of every step, ``n_evaluations``
        (the steps' and the start's evaluation) and ``seconds`` [s] of all of them;
        ``message`` says why the descent stopped.
    """
    x = checked_start(problem, x0)
    check_type(weighted, WeightedSum, "weighted")
    budget = as_integer(
        max_evaluations,
        "max_evaluations",
        minimum=STEP_EVALUATIONS,
        error=ConfigurationError,
    )
    started = time.perf_counter()
    cost = weighted.cost
    no_worse = np.zeros(len(cost), dtype=bool)
    ev = problem.evaluate_batch(x)  # the start: the step's comparisons need its f_w
    objectives, constraints, f = ev.objectives, ev.constraints, float(cost @ ev.objectives)
    n_iterations, n_evaluations, evaluation_s, spent = 0, 1, ev.seconds, 0
    message = "budget spent"
    while spent + STEP_EVALUATIONS <= budget:
        step = epsilon_solve(
            problem,
            x,
            cost,
            no_worse,
            weighted.scale,
            _STEP_ITERATIONS,
            box=WEIGHTED_BOX,
            max_evaluations=STEP_EVALUATIONS,
        )
        n_iterations += step.n_iterations
        n_evaluations += step.n_evaluations
        spent += step.n_evaluations
        evaluation_s += step.evaluation_s
        f_step = float(cost @ step.objectives)
        if not (step.feasible and f_step < f):
            message = "no lower f_w in the step's box"
            break
        decrease = f - f_step
        x, objectives, constraints, f = step.x, step.objectives, step.constraints, f_step
        if decrease < STOP_DECREASE:
            message = f"a step lowered f_w by {decrease:.2e} < {STOP_DECREASE:g}"
            break
    return PolishOutcome(
        x=x.copy(),
        objectives=objectives,
        constraints=constraints,
        feasible=bool(np.all(constraints <= 0.0)),
        start=np.asarray(x0, dtype=float).copy(),
        n_iterations=n_iterations,
        n_evaluations=n_evaluations,
        seconds=time.perf_counter() - started,
        evaluation_s=evaluation_s,
        message=message,
    )


def weighted_run(
    problem: Any, seed: int, weights: Any, **params: Any
) -> tuple[Any, dict[str, Any]]:
    """The population of ``plan(problem, algorithm="time-optimal", weights=weights)`` and
    its settings (module docstring).

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem` (``z3="clearance"``, finite
        torque limits).
    seed:
        Seed of the minimum-T starts' ramps (≥ 0).
    weights:
        (6,) w1…w6 for z1…z6: finite, ≥ 0, positive sum (rescaled to sum 1); checked,
        with the problem, before any solve.
    params:
        ``n_starts``, ``max_iter`` (:func:`~adept_traj.optimise.time_optimal_run`) and
        ``max_evaluations`` (:func:`weighted_descent`, per start; default
        :data:`MAX_EVALUATIONS_PER_START`); any other name is refused.

    Returns
    -------
    (RunState, dict)
        The minimum-T moves then the descended moves that lowered :math:`f_w` (pymoo's
        signs), with every solve's evaluations and time; the settings of
        :func:`~adept_traj.optimise.time_optimal_run` with ``max_evaluations`` and
        ``weighted_sum`` (:meth:`~adept_traj.analysis.WeightedSum.to_dict`: the weights,
        the scales and their reference), which ``plan`` and ``adept-traj verify`` read back.
    """
    weighted = weighted_sum(problem, weights)
    params = dict(params)
    budget = params.pop("max_evaluations", MAX_EVALUATIONS_PER_START)
    budget = as_integer(
        budget, "max_evaluations", minimum=STEP_EVALUATIONS, error=ConfigurationError
    )
    state, settings = time_optimal_run(problem, seed, **params)
    started = time.perf_counter()
    feasible = np.flatnonzero(np.all(np.asarray(state.G) <= 0.0, axis=1))
    outcomes = [
        weighted_descent(problem, state.X[k], weighted, max_evaluations=budget) for k in feasible
    ]
    cost = weighted.cost
    improved = [
        o for o, k in zip(outcomes, feasible) if cost @ o.objectives < cost @ from_pymoo(state.F[k])
    ]
    counted = _counted(state, outcomes, time.perf_counter() - started)
    settings = {**settings, "max_evaluations": budget, "weighted_sum": weighted.to_dict()}
    return (with_members(counted, improved) if improved else counted), settings


def _counted(state: Any, outcomes: list[PolishOutcome], seconds: float) -> Any:
    """``state`` with the outcomes' evaluations and ``seconds`` [s] added."""
    return dataclasses.replace(
        state,
        n_evaluations=state.n_evaluations + sum(o.n_evaluations for o in outcomes),
        total_s=state.total_s + seconds,
        evaluation_s=state.evaluation_s + sum(o.evaluation_s for o in outcomes),
    )
