"""Input checks shared by the meshcat viewer and the plots: the result and its replay."""

from __future__ import annotations

from typing import Any

import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.results import PlanningResult, Replay
from adept_traj.validation import check_type

__all__ = ["as_result", "replay_for"]


def as_result(value: Any, name: str = "result") -> PlanningResult:
    """``value`` if it is a :class:`~adept_traj.results.PlanningResult`, else
    :class:`~adept_traj.errors.InvalidInputError` naming ``name``."""
    check_type(value, PlanningResult, name)
    return value


def replay_for(result: PlanningResult, replay: Any = None) -> Replay:
    """The replay of ``result``'s best solution: ``replay`` when the caller has one (checked:
    a :class:`~adept_traj.results.Replay` of ``result.best_x``), else
    ``Replay.of(result)`` (loads the robot files and parses the stored scene, once).

    Raises
    ------
    InvalidInputError
        ``replay`` is not a Replay, or replays another decision vector than
        ``result.best_x`` (n_var,).
    """
    if replay is None:
        return Replay.of(result)
    check_type(replay, Replay, "replay")
    best = np.asarray(result.best_x, dtype=float)
    if replay.x.shape != best.shape or not np.array_equal(replay.x, best):
        raise InvalidInputError(
            "replay must replay the result's best solution (replay.x == result.best_x); "
            f"got x with T = {replay.duration:.6g} s, best T = {float(best[0]):.6g} s"
        )
    return replay
