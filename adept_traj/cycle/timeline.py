"""A cycle on the scene clock as it runs: each move of each pass with its start time, dwell
and certificates (:class:`ClockedMove`), and the whole cycle (:class:`CycleClock`), as
:func:`~adept_traj.cycle.plan_on_clock` and :func:`~adept_traj.cycle.plan_phase_grid`
make them and ``cycle.json`` records them.
"""

from __future__ import annotations

from dataclasses import dataclass

from adept_traj.cycle.rest import RestCheck

__all__ = ["ClockedMove", "CycleClock"]


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
