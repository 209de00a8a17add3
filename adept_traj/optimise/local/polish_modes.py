r"""The polish steps of :func:`~adept_traj.plan`: after the search, and instead of it.

:func:`polish_run` is the polish after the search, by :data:`POLISH_MODES`:

- ``"off"``: none;
- ``"fastest"``: :func:`polish_fastest` only;
- ``"front"`` (the default of ``plan``): :func:`polish_fastest`, then :func:`polish_members`
  of the best trade-off (lowest rank sum of :func:`~adept_traj.analysis.best_tradeoff`
  with the run's weights) and :data:`SPREAD_MEMBERS` more members evenly spread over the
  trade-off order of the front, as many as fit in :data:`POLISH_SHARE` of the search's
  evaluations (so that the polish costs ≲ 25 % of the run);
- ``"all"``: :func:`polish_fastest`, then every other feasible front member.

The front and its normalisation bounds are taken from the population **before** any polish
(frozen), so the choice does not depend on what the polish finds first.

:func:`polish_fastest` takes a run's final population (a
:class:`~adept_traj.optimise.RunState`) and refines the fastest feasible member of each of
its fastest basins, and — unless one comes within 1 % of the kinematic lower bound, or
when no member is feasible at all — the global stage's starts
(:func:`~adept_traj.optimise.fastest_of_basins`, ``docs/engine.md``). Every refined move
that passes its certificate (the certificate decides, not the solver) and is new (not its
certified start) joins the population; the front is taken from the population afterwards,
so a refined move replaces the members it dominates. Its wall time and its evaluations
(each constraint-and-Jacobian evaluation counts as one) are added to the run's. No
randomness: the same final population gives the same refined moves, so a run resumed from
a checkpoint ends with the same result.

:func:`time_optimal_run` is ``plan(problem, algorithm="time-optimal")``: the moves of
:func:`~adept_traj.optimise.time_optimal` (the certified local solver from the straight
move, seeded ramps and the global stage) as a population, for the same front extraction
and certificates.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Any

import numpy as np

from adept_traj.analysis.decision import best_tradeoff
from adept_traj.analysis.indicators import non_dominated
from adept_traj.certification.member_certificate import MemberCertificate, certify_members
from adept_traj.errors import ConfigurationError
from adept_traj.optimise.local.epsilon_constraint import MAX_EVALUATIONS, epsilon_step
from adept_traj.optimise.local.minimum_time import PolishOutcome
from adept_traj.optimise.local.multi_start import fastest_of_basins, time_optimal
from adept_traj.optimise.local.refinement import (
    SCREEN_BOXES,
)
from adept_traj.optimise.search.run_records import RunState
from adept_traj.problem import from_pymoo, to_pymoo
from adept_traj.robot.limits import LIMITS

__all__ = [
    "GRADIENT_COST",
    "POLISH_MODES",
    "POLISH_SHARE",
    "SPREAD_MEMBERS",
    "TIME_OPTIMAL",
    "polish_fastest",
    "polish_members",
    "polish_mode",
    "polish_run",
    "polish_run_with_certificates",
    "time_optimal_run",
]

#: The polish settings of :func:`~adept_traj.plan` (``polish=True`` is ``"front"``,
#: ``polish=False`` is ``"off"``).
POLISH_MODES: tuple[str, ...] = ("off", "fastest", "front", "all")

#: Front members polished by ``"front"`` besides the fastest and the best trade-off.
SPREAD_MEMBERS = 2

#: Cost of one gradient evaluation of the polish (constraints, objectives and their
#: Jacobians of one move) in evaluations of one move by the search's evaluator (within a
#: paper population): the ratio of the two times, measured on the paper scene.
GRADIENT_COST = 40

#: Share of the search's evaluations (in evaluator units, :data:`GRADIENT_COST`) that
#: ``"front"`` may spend on the polish: the members are polished in order while a whole
#: step (at most :data:`~adept_traj.optimise.local.epsilon_constraint.MAX_EVALUATIONS` gradient
#: evaluations) fits. Counted, not timed: the same run polishes the same members on any
#: machine (exact resume). A small run (a few hundred evaluations) polishes the fastest
#: member only.
POLISH_SHARE = 0.25

#: The name of the single-objective mode of :func:`~adept_traj.plan`.
TIME_OPTIMAL = "time-optimal"


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
    return _polish_fastest(problem, state, rate_hz, {})


def _polish_fastest(
    problem: Any, state: RunState, rate_hz: float, certified: dict[int, MemberCertificate]
) -> RunState:
    """:func:`polish_fastest`, adding to ``certified`` the summaries of the certificates of
    its member starts and of the moves it adds, under their rows in the population."""
    X = np.asarray(state.X, dtype=float)
    feasible = np.flatnonzero(np.all(np.asarray(state.G) <= 0.0, axis=1))
    tic = time.perf_counter()  # no feasible member: the global stage alone
    outcomes, starts = fastest_of_basins(problem, X[feasible], rate_hz=rate_hz)
    wall = time.perf_counter() - tic
    counted = dataclasses.replace(
        state,
        n_evaluations=state.n_evaluations + sum(o.n_evaluations for o in outcomes),
        total_s=state.total_s + wall,
        evaluation_s=state.evaluation_s + _evaluation_wall_s(outcomes, wall),
    )
    for row, o in zip(feasible[starts], outcomes):
        certified[int(row)] = o.start_certificate  # a member: not certified again
    kept = []
    for o in outcomes:
        new = o.certified and not (o.start_certified and o.x[0] >= o.start[0])
        if new and not any(np.allclose(o.x, k.x, rtol=0.0, atol=1e-9) for k in kept):
            certified[len(X) + len(kept)] = o.certificate  # its row once appended
            kept.append(o)
    return _with_members(counted, kept) if kept else counted


def polish_mode(polish: Any) -> str:
    """The name in :data:`POLISH_MODES` of a ``polish`` setting: True → ``"front"``, False →
    ``"off"``, or one of the names (else :class:`ConfigurationError`)."""
    if polish is True or polish is False:
        return "front" if polish else "off"
    if not isinstance(polish, str) or polish not in POLISH_MODES:
        raise ConfigurationError(
            f"polish must be True, False or one of {', '.join(POLISH_MODES)}; got {polish!r}"
        )
    return polish


def polish_run(problem: Any, state: RunState, rate_hz: float, mode: str, weights: Any) -> RunState:
    """``state`` after the polish ``mode`` (:data:`POLISH_MODES`, see the module docstring)
    with the f_c ``weights`` (6,) of the run."""
    return polish_run_with_certificates(problem, state, rate_hz, mode, weights)[0]


def polish_run_with_certificates(
    problem: Any, state: RunState, rate_hz: float, mode: str, weights: Any
) -> tuple[RunState, dict[int, MemberCertificate]]:
    """:func:`polish_run`, and the summaries of the certificates it made, by the move's row
    in the polished population (:func:`~adept_traj.analysis.certify_members` at ``rate_hz``
    with its default tolerance: what :func:`~adept_traj.plan` makes for a front member, so
    that ``plan`` certifies no polished move twice)."""
    mode = polish_mode(mode)
    certified: dict[int, MemberCertificate] = {}
    if mode == "off":
        return state, certified
    members, scale = _chosen_members(state, mode, weights)
    budget = None
    if mode == "front":
        budget = int(POLISH_SHARE * state.n_evaluations / GRADIENT_COST)
    before = state.n_evaluations
    state = _polish_fastest(problem, state, rate_hz, certified)
    if budget is not None:
        budget -= state.n_evaluations - before
    state = _polish_members(problem, state, members, scale, rate_hz, budget, certified)
    return state, certified


def _chosen_members(state: RunState, mode: str, weights: Any) -> tuple[np.ndarray, np.ndarray]:
    """Rows of the state's feasible non-dominated members to polish besides the fastest —
    none (``"fastest"``), the best trade-off and :data:`SPREAD_MEMBERS` evenly spread in
    the trade-off order (``"front"``), or all (``"all"``), in the trade-off order — and
    (6,) the front's range of each objective (its largest absolute value where the range
    is 0)."""
    feasible = np.flatnonzero(np.all(np.asarray(state.G) <= 0.0, axis=1))
    if mode == "fastest" or len(feasible) == 0:
        return np.empty(0, dtype=int), np.ones(6)
    objectives = from_pymoo(state.F)
    front = feasible[non_dominated(objectives[feasible])]
    fastest = feasible[np.argmin(np.asarray(state.X)[feasible, 0])]
    choice = best_tradeoff(objectives[front], weights)
    order = front[choice.order]
    order = order[order != fastest]
    if mode == "front" and len(order) > 1 + SPREAD_MEMBERS:
        spread = np.linspace(0, len(order) - 1, SPREAD_MEMBERS + 1).round().astype(int)[1:]
        order = order[np.concatenate([[0], spread])]
    span = choice.z_max - choice.z_min
    largest = np.maximum(np.abs(objectives[front]).max(axis=0), 1e-12)
    return order, np.where(span > 0.0, span, largest)


def polish_members(
    problem: Any,
    state: RunState,
    members: Any,
    scale: Any,
    rate_hz: float,
    *,
    max_evaluations: int | None = None,
) -> RunState:
    """``state`` with the ε-constraint step (:func:`~adept_traj.optimise.epsilon_step` on z1)
    of each of its rows ``members`` appended when the step improved it and the result
    passes its certificate; time and evaluations counted as in :func:`polish_fastest`.

    The step lowers the travel time z1 with z2…z6 not worse (so a kept move dominates its
    start). z1 is chosen for every member because it is smooth and linear in x: measured
    on a paper front, ε-steps on the member's worst-ranked objective (z2 or z6 there) did
    not converge in 10 iterations on 3 of 4 members (z2's Coulomb term jumps where a joint
    starts to move), those on z1 converged on 3 of 4 in 4–7 iterations.

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem` (``z3="clearance"`` and finite
        torque limits, which the objective gradients need; otherwise ``state`` is returned
        unchanged).
    state:
        The run's population (X (pop, n_var), F, G, CV (pop,)).
    members:
        Rows of ``state`` to polish (feasible ones).
    scale:
        (6,) a typical range of each objective (> 0; e.g. the front's, frozen before the
        polish): it scales the solve (:func:`~adept_traj.optimise.epsilon_step`).
    rate_hz:
        Rate [Hz] of the certificates (:func:`~adept_traj.analysis.certify_members`).
    max_evaluations:
        Gradient evaluations the steps may spend together (``None``: no bound): a member
        is polished only while a whole step (at most
        :data:`~adept_traj.optimise.local.epsilon_constraint.MAX_EVALUATIONS`) fits in what is left.
    """
    return _polish_members(problem, state, members, scale, rate_hz, max_evaluations, {})


def _polish_members(
    problem: Any,
    state: RunState,
    members: Any,
    scale: Any,
    rate_hz: float,
    max_evaluations: int | None,
    certified: dict[int, MemberCertificate],
) -> RunState:
    """:func:`polish_members`, adding the summaries of the certificates of the moves it
    adds to ``certified`` under their rows in the population."""
    rows = np.asarray(members, dtype=int).ravel()
    torque_limit = problem.robot.limits.bound(LIMITS[4].name)
    if problem.settings.z3 != "clearance" or not np.all(np.isfinite(torque_limit)):
        return state  # no objective gradients (objective_gradients refuses)
    if len(rows) == 0:
        return state
    X = np.asarray(state.X, dtype=float)
    kept, n_evaluations, seconds, evaluation_s = [], 0, 0.0, 0.0
    for k in rows:
        if max_evaluations is not None and n_evaluations + MAX_EVALUATIONS > max_evaluations:
            break
        outcome = epsilon_step(problem, X[k], 0, scale)
        tic = time.perf_counter()
        summary = None
        if outcome.feasible and outcome.x[0] < X[k, 0]:
            summary = certify_members(problem, outcome.x[None], rate_hz=rate_hz)[0]
        seconds += outcome.seconds + time.perf_counter() - tic
        n_evaluations += outcome.n_evaluations
        evaluation_s += outcome.evaluation_s
        if summary is not None and summary.feasible:
            certified[len(X) + len(kept)] = summary  # its row once appended
            kept.append(outcome)
    if n_evaluations == 0:  # no step ran
        return state
    counted = dataclasses.replace(
        state,
        n_evaluations=state.n_evaluations + n_evaluations,
        total_s=state.total_s + seconds,
        evaluation_s=state.evaluation_s + evaluation_s,
    )
    return _with_members(counted, kept) if kept else counted


def time_optimal_run(problem: Any, seed: int, **params: Any) -> tuple[RunState, dict[str, Any]]:
    """The population of ``plan(problem, algorithm="time-optimal")`` and its settings: the
    certified refinements of :func:`~adept_traj.optimise.time_optimal` from ``n_starts``
    starts (≥ 1) with at most ``max_iter`` trust boxes in each screening (≥ 1). A move
    equal to an earlier one (every entry within 1e-9 of it) is left out. ``params``:
    ``n_starts`` (default 3) and ``max_iter`` (default
    :data:`~adept_traj.optimise.SCREEN_BOXES`); any other name is refused
    (:class:`ConfigurationError`)."""
    unknown = sorted(set(params) - {"n_starts", "max_iter"})
    if unknown:
        raise ConfigurationError(
            f"unknown parameter(s) {unknown} of algorithm {TIME_OPTIMAL!r}: it takes n_starts "
            "and max_iter"
        )
    n_starts = params.get("n_starts", 3)
    max_iter = params.get("max_iter", SCREEN_BOXES)
    started = time.perf_counter()
    outcomes = time_optimal(problem, seed, n_starts=n_starts, max_boxes=max_iter)
    wall = time.perf_counter() - started
    empty = RunState(
        X=np.empty((0, problem.n_var)),
        F=np.empty((0, problem.n_obj)),
        G=np.empty((0, problem.n_ieq_constr)),
        CV=np.empty(0),
        n_generations=0,
        n_evaluations=sum(o.n_evaluations for o in outcomes),
        total_s=wall,
        evaluation_s=_evaluation_wall_s(outcomes, wall),
    )
    settings = {"name": TIME_OPTIMAL, "n_starts": n_starts, "max_iter": max_iter}
    distinct = [
        o
        for i, o in enumerate(outcomes)
        if not any(np.allclose(o.x, e.x, rtol=0.0, atol=1e-9) for e in outcomes[:i])
    ]
    return _with_members(empty, distinct), settings


def _evaluation_wall_s(outcomes: list[Any], wall_s: float) -> float:
    """The part [s] of the wall time ``wall_s`` that refinements ``outcomes`` (each with
    ``evaluation_s`` ≤ ``seconds`` [s]) spent evaluating: the sum of their evaluation
    times, scaled by ``wall_s`` / Σ ``seconds`` where they ran at once on worker processes
    (Σ ``seconds`` > ``wall_s``) — never above ``wall_s``, which the optimiser overhead
    (:func:`~adept_traj.analysis.optimizer_overhead`) requires."""
    evaluation = sum(o.evaluation_s for o in outcomes)
    busy = sum(o.seconds for o in outcomes)
    return min(evaluation * wall_s / busy, wall_s) if busy > wall_s else evaluation


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


#: :func:`_with_members`'s public name (used by :mod:`~adept_traj.optimise.local.weighted_move`).
with_members = _with_members
