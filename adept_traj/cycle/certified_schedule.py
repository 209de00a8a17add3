r"""The schedules of a periodic cycle over its plans, each re-certified at the scene times it
really runs (:func:`certified_schedules`), as :func:`~adept_traj.cycle.plan_phase_grid`
chooses them.

Over the plans of every move (:class:`~adept_traj.cycle.PhaseOption`), the **optimised**
and the **naive** periodic schedule (:func:`~adept_traj.cycle.phase_schedules`) are each
re-certified at their real scene times: every move of every pass (``move_ok`` at
:math:`s_k + p \cdot` pass time, up to ``passes`` passes, later ones congruent modulo P)
and every dwell and final dwell (``rest``). A step that fails any of them is banned and
the schedule chosen again, until a schedule passes every check or none is left. With
``repeat`` > 1 every pass is also scheduled **back to back**
(:func:`~adept_traj.cycle.chain_passes`); a periodic schedule no shorter than it is then
not re-certified (it would not be run).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from adept_traj.cycle.rest import RestCheck
from adept_traj.cycle.schedules import (
    SAME_TIME,
    MoveOk,
    PhaseOption,
    RestOk,
    Step,
    chain_passes,
    pass_end,
    phase_schedules,
)

__all__ = ["ScheduleChoice", "certified_schedules", "schedule_span"]

#: ``rest(k, start, duration)``: the certificate of the robot at rest at move k's start
#: (k = K: the last move's goal) over those scene times [s].
Rests = Callable[[int, float, float], RestCheck]


@dataclass(frozen=True)
class ScheduleChoice:
    """What :func:`certified_schedules` found.

    Attributes
    ----------
    optimised, naive: the periodic schedules (per move ``(plan, start [s])``) certified at
        their real scene times, or ``None``.
    back_to_back: every pass back to back (per pass its steps), or ``None``; its cycle
        time ``back_to_back_time`` [s] and why there is none, ``back_to_back_note``.
    bound: the cycle time [s] of a periodic schedule no shorter than the back-to-back one,
        not re-certified, or ``None``.
    """

    optimised: tuple[Step, ...] | None
    naive: tuple[Step, ...] | None
    back_to_back: list[tuple[Step, ...]] | None
    back_to_back_time: float | None
    back_to_back_note: str | None
    bound: float | None


def schedule_span(
    path: tuple[Step, ...], options: Sequence[Sequence[PhaseOption]], period: float, repeat: int
) -> float:
    """Pass time [s] of the schedule ``path`` (:func:`~adept_traj.cycle.pass_end` of its
    last move's end)."""
    i, s = path[-1]
    return pass_end(s + options[len(path) - 1][i].T, period, repeat)


def certified_schedules(
    options: Sequence[Sequence[PhaseOption]],
    period: float,
    repeat: int,
    *,
    allowed: RestOk,
    move_ok: MoveOk,
    rest: Rests,
    beam: int,
    passes: int,
) -> ScheduleChoice:
    """The schedules over ``options`` (per move its plans) certified at their real scene
    times (module doc).

    Parameters
    ----------
    options: per move k its plans; period: the scene's period P [s]; repeat: passes.
    allowed: ``allowed(k, start, duration)``, the rest prefilter (a location's
        :class:`~adept_traj.cycle.RestProfile`).
    move_ok: ``move_ok(k, plan, start)``, whether a plan is certified started at a scene
        time (with a ``prefetch(queries)`` method, queries computed at once).
    rest: the rest certificates (:class:`~adept_traj.cycle.RestCertifier`).
    beam: schedules kept per move (:func:`~adept_traj.cycle.phase_frontier`).
    passes: passes re-certified one by one (later ones are congruent modulo P).

    Returns
    -------
    ScheduleChoice
        The optimised schedule is never longer than the naive one (the naive one where the
        beam left it out); both ``None`` where none is certified.
    """
    K = len(options)
    prefetch = getattr(move_ok, "prefetch", None)

    def failures(path: tuple[Step, ...]) -> set[tuple[int, int, float]]:
        """The steps of ``path`` not certified at their real scene times, every pass."""
        span = schedule_span(path, options, period, repeat)
        checked = range(min(repeat, passes))
        if prefetch is not None:
            prefetch([(k, i, s + p * span) for p in checked for k, (i, s) in enumerate(path)])
        bad = set()
        for p in checked:
            shift, e = p * span, 0.0
            for k, (i, s) in enumerate(path):
                if not (move_ok(k, i, s + shift) and rest(k, e + shift, s - e).certified):
                    bad.add((k, i, s))
                e = s + options[k][i].T
            if repeat > 1 and not rest(K, e + shift, span - e).certified:
                bad.add((K - 1, *path[-1]))
        return bad

    runs, why = None, None  # every pass back to back, no final dwell
    if repeat > 1:
        runs, why = chain_passes(
            options,
            period,
            repeat,
            move_ok,
            lambda k, s, d: allowed(k, s, d) and rest(k, s, d).certified,
        )
    runs_time = None
    if runs is not None:
        i, s = runs[-1][-1]
        runs_time = s + options[-1][i].T
    chosen: dict[str, tuple[Step, ...] | None] = {"optimised": None, "naive": None}
    bound = None
    for name in ("optimised",) if runs is not None else ("optimised", "naive"):
        banned: frozenset[tuple[int, int, float]] = frozenset()
        while True:
            path = phase_schedules(options, period, allowed, beam=beam, repeat=repeat,
                                   banned=banned)[name]  # fmt: skip
            if path is not None and runs_time is not None:
                span = repeat * schedule_span(path, options, period, repeat)
                if span >= runs_time - SAME_TIME:
                    bound = span
                    break
            bad = set() if path is None else failures(path)
            if not bad:
                chosen[name] = path
                break
            banned = banned | bad
    if chosen["naive"] is not None:  # the beam after a ban may miss the naive schedule
        span = {
            k: schedule_span(v, options, period, repeat) for k, v in chosen.items() if v is not None
        }
        if chosen["optimised"] is None or span["naive"] < span["optimised"]:
            chosen["optimised"] = chosen["naive"]
    return ScheduleChoice(chosen["optimised"], chosen["naive"], runs, runs_time, why, bound)
