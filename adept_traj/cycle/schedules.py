r"""Schedules of a periodic cycle over the plans of its moves: dynamic programming over the
end times (:func:`phase_frontier`, :func:`phase_schedules`) and the naive back-to-back
schedule (:func:`naive_schedule`); the arithmetic of the scene clock modulo the period
(:func:`next_start`, :func:`congruent`, :func:`pass_end`); every pass back to back without
a final dwell, backtracking where a move has no certified step (:func:`back_to_back`).
Pure functions of the plans' phases, travel times and certificates and of rest and
certificate predicates: what they mean and how the plans are made is
:mod:`adept_traj.cycle.phase_grid`'s and :mod:`adept_traj.cycle.clock`'s.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

from adept_traj.errors import CycleError

__all__ = [
    "MAX_BACK_TO_BACK_MOVES",
    "MAX_UNDONE",
    "PREFETCH",
    "SAME_TIME",
    "MoveOk",
    "PhaseOption",
    "RestOk",
    "Step",
    "back_to_back",
    "chain_passes",
    "congruent",
    "naive_schedule",
    "next_start",
    "pass_end",
    "phase_frontier",
    "phase_schedules",
]

#: Two scene times closer than this [s] are the same start (no dwell).
SAME_TIME = 1e-9

#: Most moves scheduled back to back (``repeat`` × the moves of a pass): each is certified
#: at its own start time, so the cost grows with the cycle; beyond it the periodic schedule.
MAX_BACK_TO_BACK_MOVES = 10_000
#: Steps :func:`back_to_back` may undo (backtracking) before it gives up with an error.
MAX_UNDONE = 10_000
#: Moves ahead :func:`back_to_back` hands to its ``prefetch`` at once.
PREFETCH = 256

#: One step of a schedule: (plan index in the move's options, start time [s]).
Step = tuple[int, float]


@dataclass(frozen=True)
class PhaseOption:
    """One plan of a move: planned for start phase ``phase`` [s] in [0, P), travel time
    ``T`` [s] of the member it runs, ``certified`` at that phase."""

    phase: float
    T: float
    certified: bool


def next_start(end: float, phase: float, period: float) -> float:
    """The first scene time ≥ ``end`` [s] congruent to ``phase`` [s] modulo ``period`` [s]
    (``end`` itself within :data:`SAME_TIME`)."""
    s = phase + period * max(0, math.ceil((end - phase) / period - 1e-12))
    return end if abs(s - end) <= SAME_TIME * max(1.0, abs(end)) else s


RestOk = Callable[[int, float, float], bool]
#: ``move_ok(k, plan, start)``: whether plan ``plan`` of move k is certified started at the
#: scene time ``start`` [s] (re-certified there, whatever phase it was planned at).
MoveOk = Callable[[int, int, float], bool]


def _steps(
    options: Sequence[PhaseOption],
    k: int,
    end: float,
    period: float,
    rest_ok: RestOk,
    banned: frozenset[tuple[int, int, float]],
) -> list[tuple[float, float, int]]:
    """(start, end, plan) of every allowed step of move k after a schedule ending at
    ``end`` [s], by start time then end time."""
    out = []
    for i, o in enumerate(options):
        if not o.certified:
            continue
        s = next_start(end, o.phase, period)
        if (k, i, s) not in banned and rest_ok(k, end, s - end):
            out.append((s, s + o.T, i))
    return sorted(out)


def phase_frontier(
    options: Sequence[Sequence[PhaseOption]],
    period: float,
    rest_ok: RestOk,
    *,
    beam: int,
    banned: frozenset[tuple[int, int, float]] = frozenset(),
) -> list[list[tuple[float, tuple[Step, ...]]]]:
    """Per move k, every schedule of moves 0 … k as ``(end [s], steps)`` by end time (one
    per end time), each extending one of the ``beam`` earliest of move k − 1 (module doc).

    ``options[k]``: the plans of move k; ``rest_ok(k, start, duration)``: whether the robot
    may rest at move k's start over those scene times [s]; ``banned``: steps
    ``(k, plan, start)`` not to take."""
    states: list[tuple[float, tuple[Step, ...]]] = [(0.0, ())]
    stages = []
    for k, opts in enumerate(options):
        found: dict[float, tuple[float, tuple[Step, ...]]] = {}
        for e, path in states:
            for s, end, i in _steps(opts, k, e, period, rest_ok, banned):
                key = round(end, 9)
                if key not in found or end < found[key][0]:
                    found[key] = (end, (*path, (i, s)))
        stage = sorted(found.values())
        stages.append(stage)
        states = stage[:beam]
    return stages


def naive_schedule(
    options: Sequence[Sequence[PhaseOption]],
    period: float,
    rest_ok: RestOk,
    banned: frozenset[tuple[int, int, float]],
) -> tuple[float, tuple[Step, ...]] | None:
    """The naive back-to-back schedule (module doc): (end [s], steps) or ``None``."""
    end, path = 0.0, ()
    for k, opts in enumerate(options):
        steps = _steps(opts, k, end, period, rest_ok, banned)
        if not steps:
            return None
        s, end, i = steps[0]
        path = (*path, (i, s))
    return end, path


def congruent(a: float, b: float, period: float) -> bool:
    """Whether the scene times ``a`` and ``b`` [s] are the same phase modulo ``period``."""
    d = abs(math.fmod(a - b, period))
    return min(d, period - d) <= SAME_TIME * max(1.0, abs(a), abs(b))


def pass_end(end: float, period: float, repeat: int) -> float:
    """Scene time [s] a pass whose last move ends at ``end`` [s] ends: the next multiple of
    ``period`` with ``repeat`` > 1 (every pass then repeats the first), else ``end``."""
    return math.ceil(end / period - 1e-9) * period if repeat > 1 else end


def phase_schedules(
    options: Sequence[Sequence[PhaseOption]],
    period: float,
    rest_ok: RestOk,
    *,
    beam: int,
    repeat: int,
    banned: frozenset[tuple[int, int, float]] = frozenset(),
) -> dict[str, tuple[Step, ...] | None]:
    """The optimised and the naive back-to-back schedule (module doc) over ``options``
    (per move its plans): ``{"optimised": steps | None, "naive": steps | None}``, steps
    ``(plan, start [s])`` per move. ``rest_ok(k, start, duration)`` for k = K is the final
    dwell at the last move's goal; the other arguments as :func:`phase_frontier`."""
    K = len(options)

    def finished(end: float) -> bool:
        return repeat <= 1 or rest_ok(K, end, pass_end(end, period, repeat) - end)

    last = phase_frontier(options, period, rest_ok, beam=beam, banned=banned)[-1]
    ranked = sorted(last, key=lambda st: (pass_end(st[0], period, repeat), st[0]))
    best = next((st for st in ranked if finished(st[0])), None)
    naive = naive_schedule(options, period, rest_ok, banned)
    if naive is not None and not finished(naive[0]):
        naive = None
    if naive is not None and (
        best is None
        or pass_end(naive[0], period, repeat) < pass_end(best[0], period, repeat) - SAME_TIME
    ):
        best = naive  # the beam may have left out the naive schedule's states
    return {
        "optimised": None if best is None else best[1],
        "naive": None if naive is None else naive[1],
    }


def back_to_back(
    options: Sequence[Sequence[PhaseOption]],
    period: float,
    repeat: int,
    move_ok: MoveOk,
    rest_ok: RestOk,
    *,
    prefetch: Callable[[list[tuple[int, int, float]]], None] | None = None,
    max_undone: int | None = None,
) -> list[tuple[Step, ...]] | None:
    """Every one of the ``repeat`` passes planned back to back, with no final dwell: each
    move starts at the previous end with the plan of least T that ``move_ok`` certifies
    started there (any phase: it is re-certified at that scene time), and only where none
    is, at the earliest start ≥ the previous end in a plan's phase whose dwell ``rest_ok``
    allows and whose plan ``move_ok`` certifies (the robot waits only where it must).

    Where a move has no such step at all (e.g. no plan certified at the previous end and
    the robot may not wait at its start), the schedule **backtracks**: the move before it
    takes its next step in the same order (the next plan certified at its start, then its
    later starts), and so on back (depth first). ``max_undone`` bounds the steps undone
    (default :data:`MAX_UNDONE`; :class:`~adept_traj.errors.CycleError` naming it beyond).

    ``prefetch(queries)``, when given, is called with the ``(k, plan, start)`` of the next
    :data:`PREFETCH` moves as they would run with each move's fastest plan and no dwell,
    before ``move_ok`` is asked about them (so that a caller can certify them all at once,
    in parallel), and again wherever the schedule leaves that prediction.

    Returns per pass its steps ``(plan, start [s])``, or ``None`` when no schedule of
    certified steps exists over the plans."""
    K, limit = len(options), MAX_UNDONE if max_undone is None else max_undone
    total = repeat * K
    fastest = [
        min(
            (i for i, o in enumerate(opts) if o.certified),
            key=lambda i: (opts[i].T, i),
            default=None,
        )
        for opts in options
    ]
    predicted: dict[int, float] = {}

    def candidates(n: int, end: float) -> Iterator[Step]:
        k = n % K
        if prefetch is not None and predicted.get(n) != end:
            predicted.clear()
            queries, e = [], end
            for m in range(n, min(total, n + PREFETCH)):
                i = fastest[m % K]
                if i is None:
                    break
                predicted[m] = e
                queries.append((m % K, i, e))
                e = e + options[m % K][i].T
            prefetch(queries)
        return _candidates(options[k], k, end, period, move_ok, rest_ok)

    path: list[Step] = []
    stack = [candidates(0, 0.0)]
    undone = 0
    while len(path) < total:
        step = next(stack[-1], None)
        if step is None:  # no step left here: undo the move before
            stack.pop()
            if not path:
                return None
            path.pop()
            undone += 1
            if undone > limit:
                raise CycleError(
                    f"back to back: {undone} steps undone without a certified schedule, more "
                    f"than MAX_UNDONE = {limit}"
                )
            continue
        path.append(step)
        if len(path) < total:
            k = (len(path) - 1) % K
            stack.append(candidates(len(path), step[1] + options[k][step[0]].T))
    return [tuple(path[p * K : (p + 1) * K]) for p in range(repeat)]


def _candidates(
    opts: Sequence[PhaseOption],
    k: int,
    end: float,
    period: float,
    move_ok: MoveOk,
    rest_ok: RestOk,
) -> Iterator[Step]:
    """:func:`back_to_back`'s steps of move k after ``end`` [s], in the order tried."""
    good = [i for i, o in enumerate(opts) if o.certified]
    for i in sorted(good, key=lambda i: (opts[i].T, i)):  # no dwell
        if move_ok(k, i, end):
            yield i, end
    later = sorted((next_start(end, opts[i].phase, period), opts[i].T, i) for i in good)
    for s, _, i in later:
        if s > end and rest_ok(k, end, s - end) and move_ok(k, i, s):
            yield i, s


def chain_passes(
    options: Sequence[Sequence[PhaseOption]],
    period: float,
    repeat: int,
    move_ok: MoveOk,
    rest_ok: RestOk,
) -> tuple[list[tuple[Step, ...]] | None, str | None]:
    """:func:`back_to_back` within :data:`MAX_BACK_TO_BACK_MOVES` (``move_ok.prefetch`` its
    prefetch, when ``move_ok`` has one): ``(passes, None)``, or ``(None, why)`` saying why
    there is no back-to-back schedule (the limit named)."""
    moves = repeat * len(options)
    if moves > MAX_BACK_TO_BACK_MOVES:
        return None, (
            f"not tried: repeat × moves = {moves}, more than MAX_BACK_TO_BACK_MOVES = "
            f"{MAX_BACK_TO_BACK_MOVES}"
        )
    try:
        runs = back_to_back(
            options, period, repeat, move_ok, rest_ok, prefetch=getattr(move_ok, "prefetch", None)
        )
    except CycleError as exc:
        return None, str(exc)
    return runs, None if runs is not None else "no schedule of certified moves and dwells"
