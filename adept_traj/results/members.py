"""Picking a member of a result's front: its index, whether it is certified, its replay.

Picking a member is the point of a front. The viewer (``adept-traj show --member N``), the
ROS export (``member=N``) and the listing (``adept-traj front``) share these three rules:

- :func:`member_index`: ``None`` is the best trade-off (``result.best.index``); any other
  value must be an integer in [0, n − 1], n = ``len(result.front)``.
- :func:`certified_members`: ``front.feasible`` when :func:`~adept_traj.plan` certified
  every member (``front.n_certified`` set); for a result saved before that, only the best
  trade-off has a certificate (``result.feasible``) and no other member counts as
  certified.
- :func:`member_replay`: the :class:`~adept_traj.results.Replay` of a member, the
  caller's when it shows that member, else built once.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.results.record import PlanningResult
from adept_traj.results.replay import Replay
from adept_traj.validation import as_integer, check_type, deep_equal

__all__ = ["certified_members", "member_index", "member_replay"]


def member_index(result: PlanningResult, member: Any = None) -> int:
    """The row of ``result.front`` that ``member`` names: ``None`` → the best trade-off.

    Raises
    ------
    InvalidInputError: ``member`` is not an integer in [0, ``len(result.front)`` − 1].
    """
    check_type(result, PlanningResult, "result")
    if member is None:
        return int(result.best.index)
    return as_integer(member, "member", minimum=0, maximum=len(result.front) - 1)


def certified_members(result: PlanningResult) -> np.ndarray:
    """(n,) bool: which members of ``result.front`` are certified (see the module)."""
    check_type(result, PlanningResult, "result")
    front = result.front
    if front.n_certified is not None:
        return front.feasible.copy()
    certified = np.zeros(len(front), dtype=bool)
    certified[result.best.index] = result.feasible
    return certified


def member_replay(result: PlanningResult, index: int, replay: Any = None) -> Replay:
    """The :class:`~adept_traj.results.Replay` of ``result.front.x[index]``.

    Parameters
    ----------
    result: the planning result.
    index: a row of the front (:func:`member_index`).
    replay: the caller's replay of that member (no robot reload), or ``None`` to build
        ``Replay.of(result, result.front.x[index])``.

    Raises
    ------
    InvalidInputError: ``replay`` is not a Replay, or shows another move.
    """
    index = member_index(result, index)
    if index == result.best.index:
        return Replay.of_best(result, replay)
    x = result.front.x[index]
    if replay is None:
        return Replay.of(result, x)
    check_type(replay, Replay, "replay")
    same = deep_equal(replay.x, x)
    if same:  # joints, start, goal and knots: the checks of Replay.of_best, on the best's x
        try:
            Replay.of_best(result, dataclasses.replace(replay, x=result.best_x))
        except InvalidInputError:
            same = False
    if not same:
        raise InvalidInputError(
            f"replay must show member {index} of the front, result.front.x[{index}] "
            f"(Replay.of(result, result.front.x[{index}])); its joints, start, goal, n_knots "
            f"or x differ (replay T = {replay.duration:.6g} s, member T = {float(x[0]):.6g} s)"
        )
    return replay
