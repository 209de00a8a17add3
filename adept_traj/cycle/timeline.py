"""A cycle on the scene clock as it runs: each move of each pass with its start time, dwell
and certificates (:class:`ClockedMove`), and the whole cycle (:class:`CycleClock`), as
:func:`~adept_traj.cycle.plan_on_clock` and :func:`~adept_traj.cycle.plan_phase_grid`
make them and ``cycle.json`` records them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

from adept_traj.cycle.rest import RestCheck

__all__ = ["ClockedMove", "ClockedPlan", "CycleClock", "clocked_passes"]


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
    mode: ``"dwell grid"`` / ``"dwell grid (back to back)"``
        (:func:`~adept_traj.cycle.plan_on_clock`) or ``"phase grid (optimised)"`` /
        ``"phase grid (naive)"`` (:func:`~adept_traj.cycle.plan_phase_grid`).
    choice: which schedule was kept and why (the cycle times compared), or ``""``.
    """

    period: float | None
    passes: tuple[tuple[ClockedMove, ...], ...]
    final_dwell: float
    final_rest: RestCheck | None
    repeat: int
    dwells: tuple[float, ...]
    mode: str = "dwell grid"
    choice: str = ""

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


class ClockedPlan(NamedTuple):
    """What a pass's row says of one plan of a move (:func:`clocked_passes`): its move's
    name, its folder, the front member, its T [s], the clock's candidates of the move and
    the plan's result (whatever the caller keeps per move)."""

    name: str
    folder: str
    member: int
    T: float
    candidates: tuple
    result: Any


def clocked_passes(
    passes: Sequence[Sequence[tuple[int, float]]],
    planned: Callable[[int, int], ClockedPlan],
    move_ok: Callable[[int, int, float], bool],
    rest: Callable[[int, float, float], RestCheck],
) -> tuple[tuple[tuple[ClockedMove, ...], ...], list[list[Any]], float]:
    """The clock's rows of ``passes`` (per pass, per move k the plan index i and its start
    time [s] on the scene clock), each move's dwell the wait since the previous move's end:
    (rows, the plans' results per pass, the last move's end [s]). ``planned(k, i)``: plan i
    of move k; ``move_ok(k, i, start)``: whether it is certified there; ``rest(k, start,
    duration)``: the certificate of the robot at rest before move k."""
    rows, results, end = [], [], 0.0
    for q, path in enumerate(passes):
        row, row_results = [], []
        for k, (i, start) in enumerate(path):
            p = planned(k, i)
            row.append(
                ClockedMove(
                    pass_index=q,
                    index=k,
                    name=p.name,
                    folder=p.folder,
                    member=p.member,
                    start_time=start,
                    dwell=start - end,
                    T=p.T,
                    move_certified=move_ok(k, i, start),
                    rest=rest(k, end, start - end),
                    candidates=p.candidates,
                )
            )
            row_results.append(p.result)
            end = start + p.T
        rows.append(tuple(row))
        results.append(row_results)
    return tuple(rows), results, end
