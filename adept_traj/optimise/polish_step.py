r"""The polish steps of :func:`~adept_traj.plan`: after the search, and instead of it.

:func:`polish_fastest` takes a run's final population (a
:class:`~adept_traj.optimise.RunState`), polishes its fastest feasible member (none when
no member is feasible: the result then stays the least-infeasible front) by
:func:`~adept_traj.optimise.minimum_time`,
and adds the polished move to the population when it passes its certificate (the
certificate decides, not the solver) and is faster than its start. The front is taken from
the population afterwards, so the polished move replaces the members it dominates. Its wall
time and its evaluations (each constraint-and-Jacobian evaluation counts as one) are added
to the run's. No randomness: the same final population gives the same polished move, so a
run resumed from a checkpoint ends with the same result.

:func:`time_optimal_run` is ``plan(problem, algorithm="time-optimal")``: the moves of
:func:`~adept_traj.optimise.time_optimal` (multi-start SLSQP from the straight move and
seeded ramps) as a population, for the same front extraction and certificates.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np

from adept_traj.analysis.member_certificate import certify_members
from adept_traj.errors import ConfigurationError
from adept_traj.optimise.loop import RunState
from adept_traj.optimise.polish import PolishOutcome, minimum_time, time_optimal
from adept_traj.problem import to_pymoo

__all__ = ["TIME_OPTIMAL", "polish_fastest", "time_optimal_run"]

#: The name of the single-objective mode of :func:`~adept_traj.plan`.
TIME_OPTIMAL = "time-optimal"

#: SLSQP iterations of the polish (a start near an optimum converges in 3–10; from a slow
#: detour SLSQP may not converge at all).
_POLISH_ITERATIONS = 30


def polish_fastest(problem: Any, state: RunState, rate_hz: float) -> RunState:
    """``state`` with the polished fastest member appended to its population when it passes
    the certificate (see the module docstring).

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    state:
        The run's final population (X (pop, n_var), F, G, CV (pop,)).
    rate_hz:
        Rate [Hz] of the certificate (made as for the front's members,
        :func:`~adept_traj.analysis.certify_members`).
    """
    X = np.asarray(state.X, dtype=float)
    feasible = np.flatnonzero(np.all(np.asarray(state.G) <= 0.0, axis=1))
    if len(feasible) == 0:
        return state
    start = feasible[np.argmin(X[feasible, 0])]
    outcome = minimum_time(problem, X[start], max_iter=_POLISH_ITERATIONS)
    tic = time.perf_counter()
    keep = (
        outcome.feasible
        and outcome.x[0] < X[start, 0]
        and certify_members(problem, outcome.x[None], rate_hz=rate_hz)[0].feasible
    )
    spent = outcome.seconds + time.perf_counter() - tic
    counted = dataclasses.replace(
        state,
        n_evaluations=state.n_evaluations + outcome.n_evaluations,
        total_s=state.total_s + spent,
        evaluation_s=state.evaluation_s + outcome.evaluation_s,
    )
    if not keep:
        return counted
    return _with_members(counted, [outcome])


def time_optimal_run(problem: Any, seed: int, **params: Any) -> tuple[RunState, dict[str, Any]]:
    """The population of ``plan(problem, algorithm="time-optimal")`` and its settings: the
    moves of :func:`~adept_traj.optimise.time_optimal` from ``n_starts`` starts (≥ 1)
    with at most ``max_iter`` SLSQP iterations each (≥ 1). A move equal to an earlier one
    (every entry within 1e-9 of it) is left out. ``params``: ``n_starts`` (default 3) and
    ``max_iter`` (default 30); any other name is refused (:class:`ConfigurationError`)."""
    unknown = sorted(set(params) - {"n_starts", "max_iter"})
    if unknown:
        raise ConfigurationError(
            f"unknown parameter(s) {unknown} of algorithm {TIME_OPTIMAL!r}: it takes n_starts "
            "and max_iter"
        )
    n_starts = params.get("n_starts", 3)
    max_iter = params.get("max_iter", _POLISH_ITERATIONS)
    started = time.perf_counter()
    outcomes = time_optimal(problem, seed, n_starts=n_starts, max_iter=max_iter)
    empty = RunState(
        X=np.empty((0, problem.n_var)),
        F=np.empty((0, problem.n_obj)),
        G=np.empty((0, problem.n_ieq_constr)),
        CV=np.empty(0),
        n_generations=0,
        n_evaluations=sum(o.n_evaluations for o in outcomes),
        total_s=time.perf_counter() - started,
        evaluation_s=sum(o.evaluation_s for o in outcomes),
    )
    settings = {"name": TIME_OPTIMAL, "n_starts": n_starts, "max_iter": max_iter}
    distinct = [
        o
        for i, o in enumerate(outcomes)
        if not any(np.allclose(o.x, e.x, rtol=0.0, atol=1e-9) for e in outcomes[:i])
    ]
    return _with_members(empty, distinct), settings


def _with_members(state: RunState, outcomes: list[PolishOutcome]) -> RunState:
    """``state`` with the polished moves appended to its population (pymoo's signs)."""
    if not outcomes:
        raise ConfigurationError("no polished move to add")
    G = np.array([o.constraints for o in outcomes])
    return dataclasses.replace(
        state,
        X=np.concatenate([state.X, [o.x for o in outcomes]]),
        F=np.concatenate([state.F, to_pymoo(np.array([o.objectives for o in outcomes]))]),
        G=np.concatenate([state.G, G]),
        CV=np.concatenate([np.ravel(state.CV), np.maximum(G, 0.0).sum(axis=1)]),
    )
