r"""A periodic cycle planned on a phase grid: every move × start phase a Dask task at once,
then dynamic programming over the start times for the least certified pass time.

On a scene whose moving obstacles are periodic with period P
(:func:`~adept_traj.cycle.scene_period`), a move started at scene time s sees what it
sees when started at :math:`s \bmod P`. A **plan** of move k is the move planned for one
start phase φ (``TrajectoryProblem(..., start_time=φ)``); it may run at any scene time
:math:`s \equiv \varphi \pmod P`. A schedule starts move k with plan i at

.. math::
    s_k = \varphi_i + P \left\lceil \frac{e_{k-1} - \varphi_i}{P} \right\rceil,
    \qquad e_k = s_k + T_{k,i}, \qquad e_{-1} = 0,

the first such time at or after the previous move's end, the robot dwelling at rest at
the move's start location in between (dwell :math:`s_k - e_{k-1}`, 0 when
:math:`e_{k-1} \equiv \varphi_i`); with ``repeat`` > 1 the pass ends at the next multiple
of P after :math:`e_{K-1}` (a final dwell), so that every pass repeats the first.

The plans, in rounds (one Dask cluster for all):

1. **the grid**: every move at the N phases :math:`\varphi_j = j P / N`, all at once
   (one task per move × phase);
2. **the arrivals**: for k = 1 … K − 1 in turn, move k at the start phase
   :math:`e \bmod P` of each of the ``beam`` earliest ends e of the schedules of moves
   0 … k − 1 found so far and of the naive schedule's end (one task each, all of the
   round at once): started there it needs no dwell, which matters where the robot may not
   wait (a pendulum swinging through the location).

The schedules (:func:`phase_schedules`), over every plan:

- **optimised**: dynamic programming over the moves, a state being a schedule's end time
  :math:`e_k` (states of equal end merged; the ``beam`` earliest kept per move, every one
  at the last move); the schedule of least pass time, the earliest end on a tie;
- **naive back-to-back**: each move at the earliest start at or after the previous end,
  over the plans (it waits only where it must).

A step is taken only where its dwell is allowed by the location's
:class:`~adept_traj.cycle.RestProfile` (a conservative prefilter over one period) and its
plan is certified at its phase. A chosen schedule is then **re-certified at its real scene
times**: every move of every pass (:func:`~adept_traj.analysis.certify` at
:math:`s_k + p \cdot` pass time) and every dwell and final dwell
(:func:`~adept_traj.cycle.certify_rest`); a step that fails any of them is banned and the
schedule chosen again, until a schedule passes every check or none is left
(:func:`~adept_traj.cycle.certified_schedules`). So only moves and dwells certified at the
times they run are reported.

3. **refinement**: where no schedule is certified, the grid is refined: every move is
   planned at the phases :math:`(2j + 1) P / 2N` halfway between the grid's (the grid
   becomes 2N phases, the plans made so far kept), the arrivals' round runs again over
   every plan, and the schedules are chosen again; up to ``max_phases`` phases
   (:data:`MAX_PHASES` by default), after which the cycle is refused, naming the grids
   tried. A coarse grid whose moves all end where the next move can neither start nor
   wait (a pendulum at its start location then) is so still planned, with plans
   ending at other phases.

With ``repeat`` > 1 the final dwell that makes a pass a multiple of P is a choice, not a
need: where ``repeat`` × K ≤ :data:`~adept_traj.cycle.MAX_BACK_TO_BACK_MOVES`, every pass
is also scheduled **back to back** (:func:`~adept_traj.cycle.back_to_back`: each move at
the previous end with the fastest plan certified there, whatever phase it was planned at,
a dwell only where none is, backtracking where a move has no certified step; no final
dwell), each move re-certified at its real start time in batches of Dask tasks
(:class:`~adept_traj.cycle.MoveCertifier`).
That is the **naive** schedule then (it waits only where it must), and the optimised one
when its cycle time is shorter than ``repeat`` × the periodic schedule's pass time: the
clock then holds every pass (``period`` ``None``, mode ``"phase grid (optimised, back to
back)"``).
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.cycle.certified_schedule import certified_schedules, schedule_span
from adept_traj.cycle.choice import chosen_member
from adept_traj.cycle.clock import (
    CycleClock,
    check_chained,
    scene_period,
)
from adept_traj.cycle.cycle_file import MAX_DWELL_CANDIDATES, Cycle
from adept_traj.cycle.move_task import MoveTask, cycle_tasks
from adept_traj.cycle.recertify import MoveCertifier, PlannedMove, RestCertifier
from adept_traj.cycle.rest import RestProfile
from adept_traj.cycle.runner import (
    MOVES_FOLDER,
    dask_client,
    refuse_earlier_run,
    run_planning_tasks,
)
from adept_traj.cycle.schedules import (
    SAME_TIME,
    PhaseOption,
    RestOk,
    congruent,
    naive_schedule,
    pass_end,
    phase_frontier,
)
from adept_traj.cycle.timeline import ClockedPlan, clocked_passes
from adept_traj.errors import CycleError
from adept_traj.problem import ProblemSettings
from adept_traj.results import PlanningResult
from adept_traj.validation import as_integer

__all__ = [
    "DEFAULT_PHASES",
    "MAX_PHASES",
    "MAX_REFINED_PHASES",
    "RECERTIFIED_PASSES",
    "plan_phase_grid",
]

#: Start phases per period by default.
DEFAULT_PHASES = 8
#: Most start phases per period a refined grid reaches by default (``max_phases``).
MAX_PHASES = 32
#: The bound of ``max_phases`` (each phase is a planning task per move).
MAX_REFINED_PHASES = 1024
#: Passes re-certified one by one at their scene times; later passes (congruent modulo P)
#: are covered by the periodicity.
RECERTIFIED_PASSES = 100


@dataclass(frozen=True)
class _Plan:
    """A planned task of the phase grid: its option, folder name, result and member."""

    option: PhaseOption
    name: str
    result: PlanningResult
    member: int


def _plans(tasks: Sequence[MoveTask], results: Sequence[PlanningResult]) -> list[_Plan]:
    out = []
    for t, r in zip(tasks, results):
        m = chosen_member(r, t.move)
        option = PhaseOption(
            t.start_time, float(r.front.objectives[m, 0]), bool(r.front.feasible[m])
        )
        out.append(_Plan(option, t.move.name, r, m))
    return out


def _planned(task: MoveTask, plan: _Plan) -> PlannedMove:
    """``plan`` of ``task``'s move, planned at the scene time ``plan.option.phase`` [s]."""
    x = plan.result.front.x[plan.member]
    return PlannedMove(task.start, task.goal, x, plan.option.phase, plan.option.certified)


def plan_phase_grid(
    cycle: Cycle,
    out: str | os.PathLike[str],
    *,
    phases: int = DEFAULT_PHASES,
    beam: int | None = None,
    schedule: str = "optimised",
    max_phases: int | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
    refining: Callable[[int], None] | None = None,
) -> tuple[CycleClock, list[list[PlanningResult]], dict[str, Any]]:
    """Plan a periodic ``cycle`` on the phase grid (module doc): returns the clock of the
    ``schedule`` (``"optimised"`` or ``"naive"``), the chosen results (per pass of the
    clock: one, or every pass back to back) and a report ``{"optimised": cycle time [s] |
    None, "naive": …, "periodic": the periodic schedule's cycle time [s] | None,
    "periodic_certified": whether it was re-certified (not when the back-to-back schedule
    is no longer: then "periodic" is its uncertified cycle time), "back_to_back": the
    back-to-back schedule's | None, "back_to_back_note": why there is none | None, "plans":
    plans per move, "phases": (M,) phases of the last grid [s], "grid_sizes": the grid's
    sizes, N first}``.
    Tasks are saved into ``out/moves/NAME.phJ/`` (grid phase J) and ``out/moves/NAME.xI/``
    (arrival I).

    ``beam``: schedules kept per move (default: ``phases``, the first grid's size, also
    on a refined grid). ``max_phases``: the most
    phases a refined grid may reach (module doc; default :data:`MAX_PHASES`, at least
    ``phases``; ``phases`` itself: no refinement); the report's ``"grid_sizes"`` lists the
    grid's sizes, ``"phases"`` the phases of the last.
    Refined phases are saved into ``out/moves/NAME.phJofM/`` (phase J P / M).
    ``progress`` is called with each task's folder name as its plan is saved (or found
    saved); ``refining`` with the refined grid's size M as a refinement starts.

    Raises
    ------
    CycleError
        The scene is not periodic; the moves do not chain; no certified schedule exists;
        ``phases`` or ``beam`` not in [1, MAX_DWELL_CANDIDATES], ``max_phases`` not in
        [``phases``, 1024]; ``out`` holds an earlier run and ``resume`` is false.
    """
    n = as_integer(phases, "phases", minimum=1, maximum=MAX_DWELL_CANDIDATES, error=CycleError)
    width = as_integer(
        n if beam is None else beam,
        "beam",
        minimum=1,
        maximum=MAX_DWELL_CANDIDATES,
        error=CycleError,
    )
    most = as_integer(
        max(MAX_PHASES, n) if max_phases is None else max_phases,
        "max_phases",
        minimum=n,
        maximum=MAX_REFINED_PHASES,
        error=CycleError,
    )
    if schedule not in ("optimised", "naive"):
        raise CycleError(f"schedule must be 'optimised' or 'naive'; got {schedule!r}")
    check_chained(cycle)
    P = scene_period(cycle.scene)
    if P is None:
        raise CycleError(
            f"{cycle.source}: the phase grid needs a periodic scene (every moving obstacle "
            "periodic with a common period); plan it with plan_on_clock"
        )
    where = Path(out) / MOVES_FOLDER
    refuse_earlier_run(where, resume)
    grid = P * np.arange(n) / n
    base = cycle_tasks(cycle)
    K = len(base)
    robot, settings = cycle.robot.load(), ProblemSettings()
    sites = [t.start for t in base] + [base[-1].goal]  # move k's start; k = K: the last goal
    profiles = [
        RestProfile.at(robot, cycle.scene, q, P, settings=settings, rate_hz=cycle.rate_hz)
        for q in sites
    ]

    def allowed(k: int, start: float, duration: float) -> bool:
        return profiles[k].allows(start, duration)

    def at(task: MoveTask, name: str, start: float) -> MoveTask:
        return replace(task, move=replace(task.move, name=name), start_time=float(start))

    rest = RestCertifier(robot, cycle.scene, sites, settings=settings, rate_hz=cycle.rate_hz)
    sizes = [n]  # the grid's sizes, each refinement doubling it
    with dask_client(workers, scheduler, K * n) as client:
        relaxed: dict[str, Any] = {}  # each move's relaxed optima, made once (move_task)

        def planned(tasks: list[MoveTask]) -> list[_Plan]:
            done = run_planning_tasks(
                tasks, where, resume=True, client=client, relaxed=relaxed, progress=progress
            )
            return _plans(tasks, done)

        tasks = [at(t, f"{t.move.name}.ph{j}", s) for t in base for j, s in enumerate(grid)]
        flat = planned(tasks)
        plans: list[list[_Plan]] = [[] for _ in range(K)]
        # one certifier over every round: plans are only appended, answers are kept
        move_ok = MoveCertifier(
            cycle.robot, cycle.scene, cycle.rate_hz, [[] for _ in range(K)], client=client
        )

        def add(k: int, new: list[_Plan]) -> None:
            plans[k].extend(new)
            move_ok.add(k, [_planned(base[k], p) for p in new])

        for k in range(K):
            add(k, flat[k * n : (k + 1) * n])
        arrivals = [0] * K  # arrival plans per move so far
        while True:
            for k in range(1, K):
                extra = []
                for s in _arrival_phases(plans[:k], plans[k], P, allowed, width):
                    name = f"{base[k].move.name}.x{arrivals[k]}"
                    extra.append(at(base[k], name, s))
                    arrivals[k] += 1
                if extra:
                    add(k, planned(extra))
            options = [[p.option for p in row] for row in plans]
            choice = certified_schedules(
                options,
                P,
                cycle.repeat,
                allowed=allowed,
                move_ok=move_ok,
                rest=rest,
                beam=width,
                passes=RECERTIFIED_PASSES,
            )
            if choice.back_to_back is not None or getattr(choice, schedule) is not None:
                break
            m = 2 * sizes[-1]
            if m > most:
                break
            sizes.append(m)  # refine: the phases (2j + 1) P / m between the grid's
            if refining is not None:
                refining(m)
            tasks = [
                at(t, f"{t.move.name}.ph{j}of{m}", P * j / m) for t in base for j in range(1, m, 2)
            ]
            flat = planned(tasks)
            half = m // 2
            for k in range(K):
                add(k, flat[k * half : (k + 1) * half])
            grid = P * np.arange(m) / m

        runs, runs_time = choice.back_to_back, choice.back_to_back_time
        chosen = {"optimised": choice.optimised, "naive": choice.naive}
        times = {
            name: None if v is None else cycle.repeat * schedule_span(v, options, P, cycle.repeat)
            for name, v in chosen.items()
        }
        report: dict[str, Any] = {
            "periodic": times["optimised"] if choice.bound is None else choice.bound,
            "periodic_certified": times["optimised"] is not None,
            "back_to_back": runs_time,
            "back_to_back_note": choice.back_to_back_note,
            "grid_sizes": list(sizes),
        }
        back = False
        if runs_time is not None:  # the naive schedule is the back-to-back one
            times["naive"] = runs_time
            periodic = times["optimised"]
            if periodic is None or runs_time < periodic - SAME_TIME:
                times["optimised"] = runs_time
                back = True  # and so is the optimised one
            back = back or schedule == "naive"
        if chosen[schedule] is None and not back:
            counts = ", ".join(
                f"{t.move.name} {sum(p.option.certified for p in row)}/{len(row)}"
                for t, row in zip(base, plans)
            )
            grids = " → ".join(str(m) for m in sizes)
            raise CycleError(
                f"{cycle.source}: no {schedule} schedule certified at its real start times on "
                f"a grid of {grids} phases (max_phases = {most}) and the arrivals (plans "
                f"certified at their phase: {counts}); plan the cycle without --phase-grid"
            )
        if back and runs is not None:
            chosen_passes = runs
        else:  # not None: refused above otherwise
            chosen_passes = [path for path in (chosen[schedule],) if path is not None]

        def described(k: int, i: int) -> ClockedPlan:
            p = plans[k][i]
            seen = tuple((o.phase, o.T, o.certified) for o in options[k])
            folder = f"{MOVES_FOLDER}/{p.name}"
            return ClockedPlan(base[k].move.name, folder, p.member, p.option.T, seen, p.result)

        rows, results, end = clocked_passes(chosen_passes, described, move_ok, rest)
        final = 0.0 if back else pass_end(end, P, cycle.repeat) - end
        clock = CycleClock(
            period=None if back else P,
            passes=rows,
            final_dwell=max(final, 0.0),
            final_rest=rest(K, end, max(final, 0.0)) if cycle.repeat > 1 and not back else None,
            repeat=cycle.repeat,
            dwells=tuple(grid.tolist()),
            mode=f"phase grid ({schedule}{', back to back' if back else ''})",
        )
        report.update({"optimised": times["optimised"], "naive": times["naive"]})
        report["plans"] = [len(r) for r in plans]
        report["phases"] = grid
        return clock, results, report


def _arrival_phases(
    earlier: Sequence[Sequence[_Plan]],
    row: Sequence[_Plan],
    period: float,
    allowed: RestOk,
    beam: int,
) -> list[float]:
    """The start phases [s] in [0, P) of the arrivals of a move (module doc) not planned
    yet: the ends mod P of the ``beam`` earliest schedules over the ``earlier`` moves'
    plans and of their naive schedule, not congruent to a phase of ``row``'s plans."""
    options = [[p.option for p in r] for r in earlier]
    ends = [e for e, _ in phase_frontier(options, period, allowed, beam=beam)[-1][:beam]]
    naive = naive_schedule(options, period, allowed, frozenset())
    ends += [] if naive is None else [naive[0]]
    new: list[float] = []
    for e in ends:
        known = [p.option.phase for p in row] + new
        if not any(congruent(e, f, period) for f in known):
            new.append(math.fmod(e, period))
    return new
