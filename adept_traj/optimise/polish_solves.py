"""The polish's local solves: which ones run, each solve with its move's certificate (a
task that depends on its arguments alone, run in this process or in a forked one), and
how their moves join the population.

:func:`~adept_traj.optimise.polish_run` (serially) and the phases of
:func:`~adept_traj.plan` after the search (:mod:`adept_traj.optimise.post_search`, on
the problem's worker count of processes) share them, so that both take the same
decisions: the fastest feasible member's polish, then the ε-steps of the chosen members
in order while a whole step fits in the budget (:meth:`_PolishPlan.runs`), each kept move
appended to the population in that order.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.analysis.member_certificate import MemberCertificate, certify_members
from adept_traj.errors import ConfigurationError
from adept_traj.optimise.loop import RunState
from adept_traj.optimise.member_polish import MAX_EVALUATIONS, epsilon_step
from adept_traj.optimise.polish import PolishOutcome, minimum_time
from adept_traj.problem import to_pymoo

__all__: list[str] = []

#: SLSQP iterations of the polish (a start near an optimum converges in 3–10; from a slow
#: detour SLSQP may not converge at all).
_POLISH_ITERATIONS = 30


@dataclass(frozen=True)
class _PolishPlan:
    """What the polish of a population does (made by ``polish_step._polish_plan``).

    Attributes
    ----------
    fastest: the row of the fastest feasible member, polished first (``None``: none).
    members: (m,) rows of the members whose ε-step may follow, in that order (empty
        without objective gradients).
    scale: (6,) the front's range of each objective (the steps' scale).
    budget: gradient evaluations the fastest member's polish and the steps may spend
        together (``None``: no bound).
    """

    fastest: int | None
    members: np.ndarray
    scale: np.ndarray
    budget: int | None

    def runs(self, used: list[int]) -> bool | None:
        """Whether the step of ``members[len(used) - 1]`` runs, given ``used``: the
        evaluations of the fastest member's polish (0 when there is none), then of each
        step before it; ``None`` in ``used``: not known yet (the answer then is ``None``
        when it depends on it). A step runs while a whole step
        (:data:`~adept_traj.optimise.member_polish.MAX_EVALUATIONS`) fits in the budget;
        the steps stop at the first that does not."""
        i = len(used) - 1
        if i >= len(self.members):
            return False
        if self.budget is None:
            return True
        if any(u is None for u in used):
            return None
        spent = sum(used[1:])
        return spent + MAX_EVALUATIONS <= self.budget - used[0]


@dataclass(frozen=True)
class _Solved:
    """One local solve of the polish (:func:`_solve`) and the certificate of its move.

    Attributes
    ----------
    outcome: the solver's :class:`~adept_traj.optimise.PolishOutcome`.
    summary: the move's certificate summary, made when the move is feasible at the
        evaluator's samples and faster than its start (else ``None``).
    seconds: wall time [s] of the solve and the certificate.
    """

    outcome: PolishOutcome
    summary: MemberCertificate | None
    seconds: float

    @property
    def kept(self) -> bool:
        """Whether the move joins the population (it passed its certificate)."""
        return self.summary is not None and self.summary.feasible


def _solve(problem: Any, kind: str, x0: np.ndarray, scale: Any, rate_hz: float) -> _Solved:
    """The polish of the member ``x0`` (n_var,): ``kind`` ``"fastest"``
    (:func:`~adept_traj.optimise.minimum_time`) or ``"step"`` (the ε-constraint step on z1
    with the objectives' ``scale`` (6,), :func:`~adept_traj.optimise.epsilon_step`), and
    the certificate at ``rate_hz`` [Hz] of a move that is feasible and faster than ``x0``.
    A task of :class:`~adept_traj.optimise.forks.ProblemTasks` (it depends on its
    arguments alone)."""
    if kind == "fastest":
        outcome = minimum_time(problem, x0, max_iter=_POLISH_ITERATIONS)
    else:
        outcome = epsilon_step(problem, x0, 0, scale)
    tic = time.perf_counter()
    summary = None
    if outcome.feasible and outcome.x[0] < x0[0]:
        summary = certify_members(problem, outcome.x[None], rate_hz=rate_hz)[0]
    return _Solved(outcome, summary, outcome.seconds + time.perf_counter() - tic)


def _fastest_row(state: RunState) -> int | None:
    """The row of the state's fastest feasible member (``None``: no member is feasible)."""
    feasible = np.flatnonzero(np.all(np.asarray(state.G) <= 0.0, axis=1))
    if len(feasible) == 0:
        return None
    return int(feasible[np.argmin(np.asarray(state.X, dtype=float)[feasible, 0])])


def _polished(
    state: RunState,
    fastest: _Solved | None,
    steps: list[_Solved] | None,
    certified: dict[bytes, MemberCertificate],
) -> RunState:
    """``state`` with the fastest member's polish, then the members' steps (``None``: no
    step ran) counted and their kept moves appended, in that order; the summaries made are
    added to ``certified`` under each move's ``x.tobytes()``."""
    for solved in ([fastest] if fastest is not None else []) + (steps or []):
        if solved.summary is not None:
            certified[solved.outcome.x.tobytes()] = solved.summary
    if fastest is not None:
        state = _counted(state, [fastest])
    if steps:
        state = _counted(state, steps)
    return state


def _counted(state: RunState, solved: list[_Solved]) -> RunState:
    """``state`` with the evaluations and times of ``solved`` added, and their kept moves
    appended (in order)."""
    n_evaluations, seconds, evaluation_s = 0, 0.0, 0.0
    for s in solved:
        n_evaluations += s.outcome.n_evaluations
        seconds += s.seconds
        evaluation_s += s.outcome.evaluation_s
    counted = dataclasses.replace(
        state,
        n_evaluations=state.n_evaluations + n_evaluations,
        total_s=state.total_s + seconds,
        evaluation_s=state.evaluation_s + evaluation_s,
    )
    kept = [s.outcome for s in solved if s.kept]
    return _with_members(counted, kept) if kept else counted


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
