r"""A work cycle planned as it runs: every move at its real start time on the scene clock.

A moving obstacle does not stop when a move ends. On a scene with moving obstacles,
:func:`plan_on_clock` plans the moves one after the other in the order they run: move k of
pass p starts at

.. math::
    t_{p,k} = t_{p,k-1} + T_{p,k-1} + w_{p,k}

(scene time [s]; :math:`w_{p,k} \ge 0` the dwell, the robot waiting at rest at the
move's start location; the cycle starts at scene time 0 with the robot at rest at the first
move's start). Each move is planned and certified at its start time
(``TrajectoryProblem(..., start_time=t)``). The dwell of a move is chosen from a grid
(:func:`dwell_grid`): the move is planned for every dwell of the grid at once (one Dask
task each), each dwell's rest is certified (:func:`certify_rest`), and the dwell whose
certified move **ends earliest** is kept (the smallest such dwell on a tie; the dwell 0
when none is certified: the move is reported not certified).

Passes: when every moving obstacle's law is periodic with a common period P
(:func:`scene_period`), a final dwell at the end of the first pass makes the pass time a
multiple of P, so that every pass sees the obstacles in the same phases: one pass planned
and certified covers all ``repeat`` of them. That rounding is a choice: with ``repeat`` > 1
every pass is also chained back to back from the first pass's plans
(:func:`~adept_traj.cycle.chained_clock`, each move re-certified at its real start time),
and the shorter certified of the two schedules is kept (the periodic one on a tie; the
clock's ``choice`` says which and why). Otherwise every pass is planned, at most
:data:`MAX_CLOCKED_MOVES` moves in all (a larger cycle is refused before any planning).
"""

from __future__ import annotations

import itertools
import math
import os
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.cycle.chained import ChainPlan, chained_clock
from adept_traj.cycle.choice import chosen_member
from adept_traj.cycle.cycle_file import MAX_DWELL_CANDIDATES, Cycle
from adept_traj.cycle.move_task import cycle_tasks
from adept_traj.cycle.recertify import RestCertifier
from adept_traj.cycle.rest import certify_rest
from adept_traj.cycle.runner import (
    MOVES_FOLDER,
    dask_client,
    refuse_earlier_run,
    run_planning_tasks,
)
from adept_traj.cycle.schedules import SAME_TIME
from adept_traj.cycle.timeline import ClockedMove, CycleClock
from adept_traj.errors import CycleError
from adept_traj.problem import ProblemSettings
from adept_traj.results import PlanningResult
from adept_traj.scene import Scene

__all__ = [
    "DEFAULT_APERIODIC_DWELL",
    "MAX_CLOCKED_MOVES",
    "ClockedMove",
    "CycleClock",
    "check_chained",
    "dwell_grid",
    "plan_on_clock",
    "scene_period",
]

#: Most moves planned on the clock (passes planned × moves of a pass); each move is
#: planned once per dwell candidate.
MAX_CLOCKED_MOVES = 200
#: ``(step, max)`` [s] of the dwell grid on a scene that is not periodic.
DEFAULT_APERIODIC_DWELL = (0.25, 1.75)
#: Dwell candidates of a periodic scene by default: P / 8 apart, over one period.
_PERIODIC_STEPS = 8


def scene_period(scene: Scene) -> float | None:
    """The common period P [s] of the scene's moving obstacles: the longest of their laws'
    ``period`` when every other one divides it (to 1e-9 relative); ``None`` when a moving
    law has no period, the periods have no common multiple found so, or nothing moves."""
    periods = []
    for ob in scene.moving:
        p = getattr(ob.motion, "period", None)
        if p is None or not (math.isfinite(float(p)) and float(p) > 0):
            return None
        periods.append(float(p))
    if not periods:
        return None
    longest = max(periods)
    for p in periods:
        ratio = longest / p
        if abs(ratio - round(ratio)) > 1e-9 * ratio:
            return None
    return longest


def dwell_grid(cycle: Cycle, period: float | None) -> np.ndarray:
    """The dwells [s] a move may wait, ``0, step, 2·step, …`` up to ``max`` (the cycle
    file's ``[dwell]``; defaults: P / 8 up to 7 P / 8 for a periodic scene, else
    :data:`DEFAULT_APERIODIC_DWELL`)."""
    if period is not None:
        step0, most0 = period / _PERIODIC_STEPS, period * (_PERIODIC_STEPS - 1) / _PERIODIC_STEPS
    else:
        step0, most0 = DEFAULT_APERIODIC_DWELL
    step = cycle.dwell_step if cycle.dwell_step is not None else step0
    most = cycle.max_dwell if cycle.max_dwell is not None else most0
    n = math.floor(most / step + 1e-9) + 1
    if n > MAX_DWELL_CANDIDATES:
        raise CycleError(
            f"{cycle.source}: [dwell] max / step + 1 = {n} candidates per move, more than "
            f"MAX_DWELL_CANDIDATES = {MAX_DWELL_CANDIDATES}"
        )
    return step * np.arange(n)


def check_chained(cycle: Cycle) -> None:
    """Refuse (:class:`~adept_traj.errors.CycleError`) a sequence whose move k does not start
    where move k − 1 ends, or, repeated, whose last move does not end where the first
    starts: on the scene clock the robot waits where it is."""
    moves = cycle.moves
    for prev, move in itertools.pairwise(moves):
        if move.start != prev.goal:
            raise CycleError(
                f"{cycle.source}: move {move.name!r} starts at {move.start!r} but the move "
                f"before it ends at {prev.goal!r}: with moving obstacles the moves must chain"
            )
    if cycle.repeat > 1 and moves[0].start != moves[-1].goal:
        raise CycleError(
            f"{cycle.source}: repeat = {cycle.repeat} but the last move ends at "
            f"{moves[-1].goal!r}, not at the first move's start {moves[0].start!r}"
        )


def plan_on_clock(
    cycle: Cycle,
    out: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: Any = None,
) -> tuple[CycleClock, list[list[PlanningResult]]]:
    """Plan ``cycle`` (a scene with moving obstacles) on the scene clock (module doc).

    Every dwell candidate of every move is a Dask task, saved as it finishes into
    ``out/moves/NAME.pP.wJ/`` (pass P, dwell J of the grid); ``resume`` loads those
    already saved for the same task. Returns the clock (periodic, or every pass back to
    back where that is shorter: module doc) and, per pass of the clock, the chosen results
    in order. ``progress`` is called with each move's name when it is chosen.

    Raises
    ------
    CycleError
        The moves do not chain; more than :data:`MAX_CLOCKED_MOVES` moves to plan; ``out``
        holds an earlier run and ``resume`` is false.
    """
    check_chained(cycle)
    period = scene_period(cycle.scene)
    grid = dwell_grid(cycle, period)
    planned = 1 if period is not None else cycle.repeat
    if planned * len(cycle.moves) > MAX_CLOCKED_MOVES:
        raise CycleError(
            f"{cycle.source}: the scene is not periodic, so every pass is planned: "
            f"{cycle.repeat} passes × {len(cycle.moves)} moves = {planned * len(cycle.moves)} "
            f"moves, more than MAX_CLOCKED_MOVES = {MAX_CLOCKED_MOVES}; lower repeat"
        )
    where = Path(out) / MOVES_FOLDER
    refuse_earlier_run(where, resume)
    robot, settings = cycle.robot.load(), ProblemSettings()
    rest = {"settings": settings, "rate_hz": cycle.rate_hz}
    tasks = cycle_tasks(cycle)
    passes, chosen_results = [], []
    t = 0.0
    chain: list[list[ChainPlan]] = []  # the plans of pass 0, for every pass back to back
    with dask_client(workers, scheduler, len(grid)) as client:
        relaxed: dict[str, Any] = {}  # each move's relaxed optima, made once (move_task)
        for p in range(planned):
            row, row_results = [], []
            for task in tasks:
                m = task.move
                candidates = [
                    replace(task, move=replace(m, name=f"{m.name}.p{p}.w{j}"), start_time=t + d)
                    for j, d in enumerate(grid.tolist())
                ]
                results = run_planning_tasks(
                    candidates, where, resume=True, client=client, relaxed=relaxed
                )
                rests = [certify_rest(robot, cycle.scene, task.start, t, d, **rest) for d in grid]
                rows = [chosen_member(r, m) for r in results]
                times = [float(r.front.objectives[k, 0]) for r, k in zip(results, rows)]
                good = [bool(r.front.feasible[k]) for r, k in zip(results, rows)]
                ok = [g and c.certified for g, c in zip(good, rests)]
                ends = [(d + T, j) for j, (d, T) in enumerate(zip(grid.tolist(), times))]
                j = min((e for e, g in zip(ends, ok) if g), default=(0.0, 0))[1]
                r = results[j]
                row.append(
                    ClockedMove(
                        pass_index=p,
                        index=m.index,
                        name=m.name,
                        folder=f"{MOVES_FOLDER}/{candidates[j].move.name}",
                        member=rows[j],
                        start_time=t + float(grid[j]),
                        dwell=float(grid[j]),
                        T=times[j],
                        move_certified=good[j],
                        rest=rests[j],
                        candidates=tuple(zip(grid.tolist(), times, good)),
                    )
                )
                row_results.append(r)
                chain.append(
                    [
                        ChainPlan(f"{MOVES_FOLDER}/{c.move.name}", r, k, c.start_time, T, g)
                        for c, r, k, T, g in zip(candidates, results, rows, times, good)
                    ]
                )
                t = row[-1].end_time
                if progress is not None:
                    progress(m.name)
            passes.append(tuple(row))
            chosen_results.append(row_results)
        final, final_rest = 0.0, None
        if period is not None and cycle.repeat > 1:
            final = math.ceil(t / period - 1e-9) * period - t
            goal = tasks[-1].goal
            final_rest = certify_rest(robot, cycle.scene, goal, t, max(final, 0.0), **rest)
        clock = CycleClock(
            period=period,
            passes=tuple(passes),
            final_dwell=max(final, 0.0),
            final_rest=final_rest,
            repeat=cycle.repeat,
            dwells=tuple(float(d) for d in grid),
        )
        if period is None or cycle.repeat == 1:
            return clock, chosen_results
        sites = [task.start for task in tasks]
        back, back_results, why = chained_clock(
            cycle,
            tasks,
            period,
            chain,
            rest=RestCertifier(robot, cycle.scene, sites, **rest),
            candidates=[m.candidates for m in passes[0]],
            client=client,
            dwells=clock.dwells,
        )
    return _shorter(clock, chosen_results, back, back_results, why)


def _shorter(
    periodic: CycleClock,
    periodic_results: list[list[PlanningResult]],
    back: CycleClock | None,
    back_results: list[list[PlanningResult]],
    why: str | None,
) -> tuple[CycleClock, list[list[PlanningResult]]]:
    """The shorter certified of the periodic clock and every pass back to back (``back``,
    ``None`` when there is none: ``why``), the periodic one on a tie; its ``choice`` says
    which and why."""
    rounded = f"one pass rounded up to a multiple of P, × {periodic.repeat}"
    p_time = f"{periodic.cycle_time:.3f} s"
    p_state = "certified" if periodic.certified else "NOT certified"
    if back is None:
        text = f"periodic ({rounded}): {p_time}, {p_state}; every pass back to back: {why}"
        return replace(periodic, choice=text), periodic_results
    b_time = f"{back.cycle_time:.3f} s"
    shorter = back.cycle_time < periodic.cycle_time - SAME_TIME
    if back.certified and (shorter or not periodic.certified):
        reason = "shorter" if shorter else f"the periodic schedule is {p_state}"
        text = (
            f"every pass back to back: {b_time} ({reason}; periodic, {rounded}: {p_time}, "
            f"{p_state})"
        )
        return replace(back, choice=text), back_results
    text = f"periodic ({rounded}): {p_time}, {p_state}; every pass back to back: {b_time}"
    return replace(periodic, choice=text), periodic_results
