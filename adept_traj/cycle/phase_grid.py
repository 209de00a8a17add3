r"""A periodic cycle planned on a phase grid: every move × start phase a Dask task at once,
then dynamic programming over the grid for the least certified pass time.

On a scene whose moving obstacles are periodic with period P
(:func:`~adept_traj.cycle.scene_period`), a move started at scene time s sees what it
sees when started at :math:`s \bmod P`. So every move k is planned, independently and
all at once (one Dask task per move × phase), for the N start phases
:math:`\varphi_j = j P / N` (``phases``). A schedule then starts move k at a time
:math:`s_k \equiv \varphi_{j_k} \pmod P`, the first such time at or after
the previous move's end (the robot dwells at rest in between):

.. math::
    s_k = \varphi_{j_k} + P \left\lceil \frac{e_{k-1} - \varphi_{j_k}}{P} \right\rceil,
    \qquad e_k = s_k + T_{k, j_k}, \qquad e_{-1} = 0,

and the pass ends at the next multiple of P after :math:`e_{K-1}` (a final dwell), so that
every pass repeats the first. :func:`phase_schedules` finds, by dynamic programming over
(move, phase) — the earliest certified end :math:`E_k(j)` of move k started at phase j,
:math:`E_k(j) = \min_i s(E_{k-1}(i), \varphi_j) + T_{k,j}` over certified moves and
certified dwells — the schedule of least pass time (exact over the grid's start times:
an earlier end never makes a later start; a dwell that is not certified only keeps the
earliest end per phase), and for comparison the **naive back-to-back** schedule, which
starts each move at the earliest grid time at or after the previous end whose move and
dwell are certified (it waits only where it must). The chosen moves are re-certified at
their exact start times (:func:`~adept_traj.analysis.certify`), and every dwell is
certified (:func:`~adept_traj.cycle.certify_rest`).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.analysis import certify
from adept_traj.cycle.choice import chosen_member
from adept_traj.cycle.clock import (
    ClockedMove,
    CycleClock,
    certify_rest,
    check_chained,
    scene_period,
)
from adept_traj.cycle.cycle_file import MAX_DWELL_CANDIDATES, Cycle
from adept_traj.cycle.runner import MOVES_FOLDER, cycle_tasks, run_planning_tasks
from adept_traj.errors import CycleError
from adept_traj.problem import ProblemSettings, TrajectoryProblem
from adept_traj.results import PlanningResult
from adept_traj.validation import as_integer

__all__ = ["DEFAULT_PHASES", "PhaseTable", "phase_schedules", "plan_phase_grid"]

#: Start phases per period by default.
DEFAULT_PHASES = 8


@dataclass(frozen=True)
class PhaseTable:
    """Every move planned at every start phase.

    Attributes
    ----------
    period: P [s]; phases: (N,) start phases [s] in [0, P).
    T: (K, N) travel time [s] of the member each move runs, per start phase.
    certified: (K, N) that member is certified at that start phase.
    members: (K, N) its row in the front.
    """

    period: float
    phases: np.ndarray
    T: np.ndarray
    certified: np.ndarray
    members: np.ndarray


def _next_start(end: float, phase: float, period: float) -> float:
    """The first scene time ≥ ``end`` [s] congruent to ``phase`` modulo ``period``."""
    return phase + period * max(0, math.ceil((end - phase) / period - 1e-12))


def phase_schedules(table: PhaseTable, rest_ok: Any) -> dict[str, list[tuple[int, float]] | None]:
    """The dynamic-programming schedule (``"optimised"``) and the naive back-to-back one
    (``"naive"``) over ``table`` (module doc): each a list of (phase index, start time [s])
    per move, or ``None`` when no certified schedule exists. ``rest_ok(k, start, duration)``
    says whether the robot may rest at move k's start over that scene time interval."""
    P, phases = table.period, table.phases.tolist()
    K, N = table.T.shape
    best: list[dict[int, tuple[float, list[tuple[int, float]]]]] = []
    for k in range(K):
        row: dict[int, tuple[float, list[tuple[int, float]]]] = {}
        previous = best[-1] if best else {-1: (0.0, [])}
        for j in range(N):
            if not table.certified[k, j]:
                continue
            options = sorted((_next_start(e, phases[j], P), i) for i, (e, _) in previous.items())
            for start, i in options:  # the earliest start whose dwell is certified
                e_prev, path = previous[i]
                if rest_ok(k, e_prev, start - e_prev):
                    row[j] = (start + float(table.T[k, j]), [*path, (j, start)])
                    break
        best.append(row)
    finals = [(math.ceil(e / P - 1e-9), e, path) for e, path in best[-1].values()]
    optimised = min(finals, default=None)
    naive: list[tuple[int, float]] | None = []
    end = 0.0
    for k in range(K):
        starts = sorted(
            (_next_start(end, phases[j], P), j) for j in range(N) if table.certified[k, j]
        )
        chosen = next(((s, j) for s, j in starts if rest_ok(k, end, s - end)), None)
        if chosen is None:
            naive = None
            break
        naive.append((chosen[1], chosen[0]))
        end = chosen[0] + float(table.T[k, chosen[1]])
    return {"optimised": None if optimised is None else optimised[2], "naive": naive}


def plan_phase_grid(
    cycle: Cycle,
    out: str | os.PathLike[str],
    *,
    phases: int = DEFAULT_PHASES,
    schedule: str = "optimised",
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
) -> tuple[CycleClock, list[list[PlanningResult]], dict[str, Any]]:
    """Plan a periodic ``cycle`` on the phase grid (module doc): returns the clock of the
    ``schedule`` (``"optimised"`` or ``"naive"``), the chosen results (one pass) and a
    report ``{"optimised": pass time [s] | None, "naive": …, "table": PhaseTable}``.
    Tasks are saved into ``out/moves/NAME.phJ/``.

    Raises
    ------
    CycleError
        The scene is not periodic; the moves do not chain; no certified schedule exists on
        the grid; ``phases`` not in [1, MAX_DWELL_CANDIDATES]; ``out`` holds an earlier
        run and ``resume`` is false.
    """
    n = as_integer(phases, "phases", minimum=1, maximum=MAX_DWELL_CANDIDATES, error=CycleError)
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
    if not resume and where.exists() and any(where.iterdir()):
        raise CycleError(f"{where} holds an earlier run: give --resume or another folder")
    grid = P * np.arange(n) / n
    base = cycle_tasks(cycle)
    tasks = [
        replace(t, move=replace(t.move, name=f"{t.move.name}.ph{j}"), start_time=float(s))
        for t in base
        for j, s in enumerate(grid.tolist())
    ]
    flat = run_planning_tasks(tasks, where, workers=workers, scheduler=scheduler, resume=True)
    results = [flat[k * n : (k + 1) * n] for k in range(len(base))]
    members = np.array([[chosen_member(r, t.move) for r in row] for t, row in zip(base, results)])
    table = PhaseTable(
        period=P,
        phases=grid,
        T=np.array(
            [
                [r.front.objectives[m, 0] for r, m in zip(row, ms)]
                for row, ms in zip(results, members)
            ]
        ),
        certified=np.array(
            [
                [bool(r.front.feasible[m]) for r, m in zip(row, ms)]
                for row, ms in zip(results, members)
            ]
        ),
        members=members,
    )
    robot, settings = cycle.robot.load(), ProblemSettings()
    checked: dict[tuple[int, float, float], Any] = {}

    def rest(k: int, start: float, duration: float) -> Any:
        key = (k, start, duration)
        if key not in checked:
            q = base[k].start
            checked[key] = certify_rest(
                robot, cycle.scene, q, start, duration, settings=settings, rate_hz=cycle.rate_hz
            )
        return checked[key]

    found = phase_schedules(table, lambda k, s, d: rest(k, s, d).certified)
    path = found[schedule]
    if path is None:
        counts = ", ".join(
            f"{t.move.name} {int(c.sum())}/{n}" for t, c in zip(base, table.certified)
        )
        unsafe = sorted({base[k].move.start for (k, _, _), v in checked.items() if not v.certified})
        raise CycleError(
            f"{cycle.source}: no certified {schedule} schedule on a grid of {n} phases "
            f"(certified start phases: {counts}; a move starts on the grid, so the robot "
            f"dwells before it, and a dwell was not certified at {unsafe or 'no location'}); "
            "plan the cycle without --phase-grid (its dwells may be 0)"
        )
    row, chosen = [], []
    end = 0.0
    for k, (j, start) in enumerate(path):
        r, m = results[k][j], int(members[k, j])
        problem = TrajectoryProblem(
            robot, cycle.scene, base[k].start, base[k].goal, workers=1, start_time=start
        )
        try:  # the exact start time, not the grid phase it is congruent to
            again = certify(problem, r.front.x[m], rate_hz=cycle.rate_hz)
        finally:
            problem.close()
        row.append(
            ClockedMove(
                pass_index=0,
                index=k,
                name=base[k].move.name,
                folder=f"{MOVES_FOLDER}/{tasks[k * n + j].move.name}",
                member=m,
                start_time=start,
                dwell=start - end,
                T=float(table.T[k, j]),
                move_certified=bool(again.certified),
                rest=rest(k, end, start - end),
                candidates=tuple(
                    zip(grid.tolist(), table.T[k].tolist(), table.certified[k].tolist())
                ),
            )
        )
        chosen.append(r)
        end = start + float(table.T[k, j])
    final = math.ceil(end / P - 1e-9) * P - end if cycle.repeat > 1 else 0.0
    final_rest = None
    if cycle.repeat > 1:
        final_rest = certify_rest(
            robot,
            cycle.scene,
            base[-1].goal,
            end,
            max(final, 0.0),
            settings=settings,
            rate_hz=cycle.rate_hz,
        )
    clock = CycleClock(
        period=P,
        passes=(tuple(row),),
        final_dwell=max(final, 0.0),
        final_rest=final_rest,
        repeat=cycle.repeat,
        dwells=tuple(grid.tolist()),
        mode=f"phase grid ({schedule})",
    )
    report = {"table": table}
    for name, p in found.items():
        if p is None:
            report[name] = None
            continue
        k_last, (j_last, s_last) = len(p) - 1, p[-1]
        e = s_last + float(table.T[k_last, j_last])
        report[name] = math.ceil(e / P - 1e-9) * P if cycle.repeat > 1 else e
    return clock, [chosen], report
