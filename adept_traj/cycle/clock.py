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
and certified covers all ``repeat`` of them. Otherwise every pass is planned, at most
:data:`MAX_CLOCKED_MOVES` moves in all (a larger cycle is refused before any planning).
"""

from __future__ import annotations

import itertools
import math
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.cycle.choice import chosen_member
from adept_traj.cycle.cycle_file import MAX_DWELL_CANDIDATES, Cycle
from adept_traj.cycle.rest import RestCheck, certify_rest
from adept_traj.cycle.runner import (
    MOVES_FOLDER,
    cycle_tasks,
    dask_client,
    run_planning_tasks,
)
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


@dataclass(frozen=True)
class ClockedMove:
    """One move of one pass on the scene clock.

    Attributes
    ----------
    pass_index, index, name: the pass (0-based), the move's place in the sequence, its name.
    folder: its result folder, relative to the cycle's output folder; member: the row of
        its front the cycle runs (:func:`~adept_traj.cycle.chosen_member`).
    start_time, dwell, T: scene time [s] the move starts, the dwell [s] before it, its
        travel time [s] (the reported solution's).
    move_certified: the reported solution is certified at ``start_time``.
    rest: the certificate of the dwell before it.
    candidates: per dwell of the grid, ``(dwell [s], T [s], certified)``.
    """

    pass_index: int
    index: int
    name: str
    folder: str
    member: int
    start_time: float
    dwell: float
    T: float
    move_certified: bool
    rest: RestCheck
    candidates: tuple[tuple[float, float, bool], ...]

    @property
    def end_time(self) -> float:
        """Scene time [s] the move ends, ``start_time + T``."""
        return self.start_time + self.T

    @property
    def certified(self) -> bool:
        """The move and the dwell before it are certified."""
        return self.move_certified and self.rest.certified


@dataclass(frozen=True)
class CycleClock:
    """A cycle planned on the scene clock (:func:`plan_on_clock`).

    Attributes
    ----------
    period: the scene's common period P [s], or ``None`` (every pass planned).
    passes: the planned passes (one for a periodic scene), each its moves in order.
    final_dwell, final_rest: the dwell [s] after the first pass that makes the pass time a
        multiple of P and its certificate (periodic scene with ``repeat`` > 1; else 0 and
        ``None``).
    repeat: passes per cycle; dwells: the dwell grid [s] (the start phases [s] of a phase
        grid, :mod:`adept_traj.cycle.phase_grid`).
    mode: ``"dwell grid"`` (:func:`plan_on_clock`) or ``"phase grid (optimised)"`` /
        ``"phase grid (naive)"`` (:func:`~adept_traj.cycle.plan_phase_grid`).
    """

    period: float | None
    passes: tuple[tuple[ClockedMove, ...], ...]
    final_dwell: float
    final_rest: RestCheck | None
    repeat: int
    dwells: tuple[float, ...]
    mode: str = "dwell grid"

    @property
    def pass_time(self) -> float:
        """Scene time [s] of one pass, dwells and the final dwell included (periodic
        scene); the end of the last planned pass otherwise."""
        return self.passes[-1][-1].end_time + self.final_dwell

    @property
    def cycle_time(self) -> float:
        """The whole cycle [s]: ``repeat`` × the pass time (periodic), else the end of the
        last pass."""
        return self.repeat * self.pass_time if self.period is not None else self.pass_time

    @property
    def certified(self) -> bool:
        """Every move and every dwell of every pass is certified."""
        rest = self.final_rest is None or self.final_rest.certified
        return rest and all(m.certified for moves in self.passes for m in moves)

    def start_times(self) -> list[list[float]]:
        """Per pass of the ``repeat`` passes, each move's scene start time [s] (a periodic
        cycle's passes p > 0 shifted by p × the pass time)."""
        if self.period is None:
            return [[m.start_time for m in moves] for moves in self.passes]
        shift = self.pass_time
        return [[m.start_time + p * shift for m in self.passes[0]] for p in range(self.repeat)]


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
    already saved for the same task. Returns the clock and, per planned pass, the chosen
    results in order. ``progress`` is called with each move's name when it is chosen.

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
    if not resume and where.exists() and any(where.iterdir()):
        raise CycleError(f"{where} holds an earlier run: give --resume or another folder")
    robot, settings = cycle.robot.load(), ProblemSettings()
    rest = {"settings": settings, "rate_hz": cycle.rate_hz}
    tasks = cycle_tasks(cycle)
    passes, chosen_results = [], []
    t = 0.0
    with dask_client(workers, scheduler, len(grid)) as client:
        for p in range(planned):
            row, row_results = [], []
            for task in tasks:
                m = task.move
                candidates = [
                    replace(task, move=replace(m, name=f"{m.name}.p{p}.w{j}"), start_time=t + d)
                    for j, d in enumerate(grid.tolist())
                ]
                results = run_planning_tasks(candidates, where, resume=True, client=client)
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
    return clock, chosen_results
