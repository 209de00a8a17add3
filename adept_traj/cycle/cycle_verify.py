"""Re-certifying a whole cycle: every move of every pass at its start time on the scene clock.

:func:`verify_cycle` reads ``cycle.json`` and the moves' result folders of an
``adept-traj cycle`` output folder. A fixed-obstacle cycle: each move's best trade-off is
certified again (the start time does not matter). A cycle planned on the scene clock
(``clock`` in ``cycle.json``): the record's arithmetic is checked first (each move starts
at the previous end plus its dwell, its T and its result's start time are those recorded,
a periodic pass time is a multiple of the period; a phase grid's plan planned at a phase
congruent to its start time, or, every pass back to back, at any), then every move of
**every** pass of
the ``repeat`` is certified at its scene start time (a periodic cycle's pass p at the
first pass's times + p × the pass time), and every dwell (the robot at rest while the
obstacles move) with :func:`~adept_traj.cycle.certify_rest`.

Given ``workers`` or ``scheduler`` (``adept-traj verify CYCLE_DIR --workers N``), the
certificates run as Dask tasks on the cycle command's mechanism (a local cluster of
``workers`` processes, or a running scheduler; :func:`~adept_traj.cycle.check_moves`),
each move certified alone from the same values as in this process: the same verdicts
and lines, in the same order.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from adept_traj.cycle.recertify import MoveCheck, MoveVerdict, check_moves
from adept_traj.cycle.runner import dask_client
from adept_traj.cycle.summary import CYCLE_FILE
from adept_traj.errors import CycleError
from adept_traj.files import parse_json, read_bytes_bounded
from adept_traj.results import PlanningResult
from adept_traj.scene import Scene

__all__ = ["CycleVerification", "verify_cycle"]

#: Tolerance [s] of the recorded clock arithmetic (start = previous end + dwell).
_CLOCK_TOLERANCE = 1e-9


@dataclass(frozen=True)
class CycleVerification:
    """What :func:`verify_cycle` found.

    Attributes
    ----------
    lines: one line per move of every pass and per dwell checked.
    certified: every move and dwell is certified.
    mismatches: where the record's clock arithmetic or a move's result disagrees with it.
    n_moves: moves certified (passes × moves).
    """

    lines: tuple[str, ...]
    certified: bool
    mismatches: tuple[str, ...]
    n_moves: int


def verify_cycle(
    folder: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
) -> CycleVerification:
    """Re-certify the cycle saved in ``folder`` (module doc); with ``workers`` (local
    Dask worker processes) or ``scheduler`` (a running Dask scheduler's address) the
    certificates run as Dask tasks, else in this process.

    Raises
    ------
    CycleError
        ``folder`` holds no ``cycle.json`` or it cannot be read.
    """
    where = Path(folder)
    path = where / CYCLE_FILE
    summary = parse_json(read_bytes_bounded(path, CycleError), str(path), CycleError)
    results: dict[str, PlanningResult] = {}

    def load(rel: str) -> PlanningResult:
        if rel not in results:
            results[rel] = PlanningResult.load(where / rel)
        return results[rel]

    parallel = workers is not None or scheduler is not None
    with _client(parallel, workers, scheduler) as client:
        clock = summary.get("clock")
        if clock is None:
            return _fixed(summary, load, client)
        return _on_clock(summary, clock, load, client)


def _word(ok: bool) -> str:
    return "certified" if ok else "NOT CERTIFIED"


def _line(name: str, p: int, start: float, T: float, ok: bool, low: float) -> str:
    return f"pass {p} {name}: start {start:.4f} s, T {T:.4f} s: {_word(ok)} (min {low:.4f} m)"


@contextmanager
def _client(parallel: bool, workers: int | None, scheduler: str | None) -> Iterator[Any]:
    """A Dask client (:func:`~adept_traj.cycle.dask_client`) when ``parallel``, else
    ``None``."""
    if not parallel:
        yield None
        return
    with dask_client(workers, scheduler, 1024) as client:
        yield client


def _check_of(r: PlanningResult, x: Any, start: float, dwell: float) -> MoveCheck:
    """The check of ``r``'s member ``x`` started at scene time ``start`` [s] after a
    dwell [s] at its start (in one process: ``workers = 1``)."""
    settings = replace(r.problem_settings, start_time=start, workers=1)
    span = (start - dwell, dwell)
    return MoveCheck(settings, r.start, r.goal, x, r.certificate.rate_hz, span)


def _verdicts(first: PlanningResult, checks: Sequence[MoveCheck], client: Any) -> list[MoveVerdict]:
    scene = Scene.from_dict(first.scene, source="result scene")
    return check_moves(first.robot.source(), scene, checks, client)


def _fixed(
    summary: dict[str, Any], load: Callable[[str], PlanningResult], client: Any
) -> CycleVerification:
    moves = summary["moves"]
    loaded = [load(m["folder"]) for m in moves]
    xs = [r.front.x[m.get("member", r.best.index)] for m, r in zip(moves, loaded)]
    found: dict[int, MoveVerdict] = {}
    groups: dict[tuple[Any, str], list[int]] = {}  # moves of one robot and scene together
    for i, r in enumerate(loaded):
        groups.setdefault((r.robot.source(), json.dumps(r.scene, sort_keys=True)), []).append(i)
    for rows in groups.values():
        checks = [
            _check_of(loaded[i], xs[i], loaded[i].problem_settings.start_time, 0.0) for i in rows
        ]
        for i, v in zip(rows, _verdicts(loaded[rows[0]], checks, client)):
            found[i] = v
    lines, ok = [], True
    for i, (m, x) in enumerate(zip(moves, xs)):
        v = found[i]
        ok &= v.feasible
        lines.append(_line(m["name"], 0, 0.0, float(x[0]), v.feasible, v.min_distance))
    return CycleVerification(tuple(lines), ok, (), len(lines))


def _on_clock(
    summary: dict[str, Any],
    clock: dict[str, Any],
    load: Callable[[str], PlanningResult],
    client: Any,
) -> CycleVerification:
    passes, period = clock["passes"], clock["period"]
    repeat = int(summary["repeat"])
    mismatches = []
    t = 0.0
    for p, moves in enumerate(passes):
        for m in moves:
            r = load(m["folder"])
            start, T = t + m["dwell"], float(r.front.x[m["member"], 0])
            if abs(start - m["start_time"]) > _CLOCK_TOLERANCE:
                mismatches.append(
                    f"pass {p} {m['name']}: starts at {m['start_time']} s, not "
                    f"at the previous end + dwell = {start} s"
                )
            if m["T"] != T:
                mismatches.append(
                    f"pass {p} {m['name']}: T {m['T']} s recorded, {T} s in its result"
                )
            planned_at = r.problem_settings.start_time  # a phase grid's: congruent mod P
            gap = m["start_time"] - planned_at
            if period is not None and clock.get("mode", "").startswith("phase"):
                gap -= period * round(gap / period)
            if "back to back" in clock.get("mode", ""):
                gap = 0.0  # a plan run at another phase: its certificate there is below
            if abs(gap) > _CLOCK_TOLERANCE * max(1.0, abs(m["start_time"])):
                mismatches.append(
                    f"pass {p} {m['name']}: its result was planned at start time "
                    f"{planned_at} s, not {m['start_time']} s"
                )
            t = m["start_time"] + T
    pass_time = t + clock["final_dwell"]
    if period is not None and repeat > 1:
        ratio = pass_time / period
        if abs(ratio - round(ratio)) > 1e-9 * max(ratio, 1.0):
            mismatches.append(f"pass time {pass_time} s is not a multiple of the period {period} s")
    schedule = (
        [(p, m, p * pass_time) for p in range(repeat) for m in passes[0]]
        if period is not None
        else [(p, m, 0.0) for p, moves in enumerate(passes) for m in moves]
    )
    first = load(passes[0][0]["folder"])
    final = clock["final_dwell"]
    checks = []
    for _, m, shift in schedule:
        r = load(m["folder"])
        check = _check_of(r, r.front.x[m["member"]], m["start_time"] + shift, m["dwell"])
        if period is not None and m is passes[0][-1] and repeat > 1 and final > 0:
            check = replace(check, after=(check.settings.start_time + float(check.x[0]), final))
        checks.append(check)
    lines, ok = [], True
    for (p, m, _), check, v in zip(schedule, checks, _verdicts(first, checks, client)):
        start, T = check.settings.start_time, float(check.x[0])
        ok &= bool(v.feasible and v.before)
        line = _line(m["name"], p, start, T, v.feasible, v.min_distance)
        if m["dwell"]:
            line += f"; its dwell of {m['dwell']:.4f} s: {_word(v.before)}"
        lines.append(line)
        if v.after is not None:
            ok &= v.after
            lines.append(
                f"pass {p} final dwell {final:.4f} s from {start + T:.4f} s: {_word(v.after)}"
            )
    return CycleVerification(tuple(lines), ok, tuple(mismatches), len(schedule))
