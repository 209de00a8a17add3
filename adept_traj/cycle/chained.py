"""Every pass of a periodic cycle back to back, from the plans the cycle already has.

The default schedule of a periodic scene (:func:`~adept_traj.cycle.plan_on_clock`) plans
one pass and rounds it up to a multiple of the period P with a final dwell, so that one
pass certified covers all ``repeat``. That waiting is a choice: :func:`chained_clock` runs
the passes one after the other with no final dwell, each move at the previous end with the
fastest of its plans that is certified started there (re-certified at that scene time,
whatever time it was planned at: :class:`~adept_traj.cycle.MoveCertifier`, batches of Dask
tasks), a certified dwell only where no plan is, backtracking where a move has no
certified step at all (:func:`~adept_traj.cycle.back_to_back`). The caller keeps the
shorter of the two.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from adept_traj.cycle.cycle_file import Cycle
from adept_traj.cycle.move_task import MoveTask
from adept_traj.cycle.recertify import MoveCertifier, PlannedMove, RestCertifier
from adept_traj.cycle.schedules import PhaseOption, chain_passes
from adept_traj.cycle.timeline import ClockedPlan, CycleClock, clocked_passes
from adept_traj.results import PlanningResult

__all__ = ["ChainPlan", "chained_clock"]


@dataclass(frozen=True)
class ChainPlan:
    """A plan of a move the chain may run.

    Attributes
    ----------
    folder: its result folder, relative to the cycle's output folder.
    result, member: its planning result and the front row the cycle runs.
    planned_at: the scene time [s] it was planned and certified at.
    T: travel time [s] of the member; certified: certified at ``planned_at``.
    """

    folder: str
    result: PlanningResult
    member: int
    planned_at: float
    T: float
    certified: bool


def _planned(task: MoveTask, plan: ChainPlan) -> PlannedMove:
    x = plan.result.front.x[plan.member]
    return PlannedMove(task.start, task.goal, x, plan.planned_at, plan.certified)


def chained_clock(
    cycle: Cycle,
    tasks: Sequence[MoveTask],
    period: float,
    plans: Sequence[Sequence[ChainPlan]],
    *,
    rest: RestCertifier,
    candidates: Sequence[tuple[tuple[float, float, bool], ...]],
    client: Any = None,
    dwells: Sequence[float] = (),
    mode: str = "dwell grid (back to back)",
) -> tuple[CycleClock | None, list[list[PlanningResult]], str | None]:
    """All ``cycle.repeat`` passes back to back (module doc) over ``plans`` (per move of
    ``tasks`` its plans): ``(clock, results per pass, None)``, or ``(None, [], why)`` when
    there is no such schedule (no certified step, or beyond
    :data:`~adept_traj.cycle.MAX_BACK_TO_BACK_MOVES`).

    ``rest(k, start, duration)``: the rest certificate at move k's start;
    ``candidates``: per move, what the clock reports as its candidates; ``client``: the
    Dask client the re-certifications run on (``None``: in this process); ``dwells``,
    ``mode``: the clock's dwell grid [s] and mode."""
    options = [
        [PhaseOption(math.fmod(p.planned_at, period), p.T, p.certified) for p in row]
        for row in plans
    ]
    planned = [[_planned(t, p) for p in row] for t, row in zip(tasks, plans)]
    move_ok = MoveCertifier(cycle.robot, cycle.scene, cycle.rate_hz, planned, client=client)
    runs, why = chain_passes(
        options, period, cycle.repeat, move_ok, lambda k, s, d: rest(k, s, d).certified
    )
    if runs is None:
        return None, [], why

    def described(k: int, i: int) -> ClockedPlan:
        p = plans[k][i]
        return ClockedPlan(tasks[k].move.name, p.folder, p.member, p.T, candidates[k], p.result)

    rows, results, _ = clocked_passes(runs, described, move_ok, rest)
    clock = CycleClock(
        period=None,
        passes=rows,
        final_dwell=0.0,
        final_rest=None,
        repeat=cycle.repeat,
        dwells=tuple(dwells),
        mode=mode,
    )
    return clock, results, None
