"""Input checks shared by the meshcat viewer and the plots: the result and its replay."""

from __future__ import annotations

from typing import Any

from adept_traj.results import PlanningResult, Replay
from adept_traj.validation import check_type

__all__ = ["as_result", "replay_for"]


def as_result(value: Any, name: str = "result") -> PlanningResult:
    """``value`` if it is a :class:`~adept_traj.results.PlanningResult`, else
    :class:`~adept_traj.errors.InvalidInputError` naming ``name``."""
    check_type(value, PlanningResult, name)
    return value


def replay_for(result: PlanningResult, replay: Any = None) -> Replay:
    """The replay of ``result``'s best solution (:meth:`~adept_traj.results.Replay.of_best`:
    ``replay`` checked when given, else built once)."""
    return Replay.of_best(result, replay)
