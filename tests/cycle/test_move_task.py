"""A cycle's move as a task: the relaxed optima shared by the tasks of a group (a move at
every start phase, every seed) give the same plans as each task making its own."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from adept_traj.cycle import (
    MoveSpec,
    MoveTask,
    plan_move,
    relaxed_group,
    relaxed_optima,
)
from adept_traj.robot import RobotSource
from adept_traj.scene import Scene
from adept_traj.testing.cycle_files import HOME, PLACE


def _task(scene: Scene, **move: object) -> MoveTask:
    spec = {"index": 0, "name": "a-b", "start": "a", "goal": "b", "algorithm": "nsga2"}
    spec["seed"] = 3
    spec.update({"pop_size": 8, "n_gen": 3, "weights": (1.0,) * 6, "choose": "trade-off"})
    spec.update(move)
    return MoveTask(
        move=MoveSpec(**spec),
        start=np.array(HOME),
        goal=np.array(PLACE),
        robot=RobotSource(),
        scene=scene,
        rate_hz=1000.0,
    )


def test_relaxed_group_is_what_the_relaxed_problem_depends_on() -> None:
    """The start time, seed, algorithm, budget and name do not change the group; the
    move's ends, the rate, the scene do; without moving obstacles there is none."""
    detour = Scene.shipped("detour")
    task = _task(detour)
    group = relaxed_group(task)
    assert group is not None
    same = [
        replace(task, start_time=1.25),
        _task(detour, seed=9, algorithm="mode", pop_size=20, n_gen=7, name="other"),
    ]
    assert all(relaxed_group(t) == group for t in same)
    other = [
        replace(task, goal=np.array(PLACE) + np.array([0.0, 0.0, 0.01, 0.0])),
        replace(task, rate_hz=500.0),
        _task(Scene.shipped("paper")),
    ]
    assert all(relaxed_group(t) not in (None, group) for t in other)
    still = replace(detour, obstacles=detour.fixed)
    assert not still.moving
    assert relaxed_group(_task(still)) is None


def _same(a, b) -> bool:
    return (
        np.array_equal(a.front.x, b.front.x)
        and np.array_equal(a.front.objectives, b.front.objectives)
        and np.array_equal(a.best_x, b.best_x)
        and np.array_equal(a.front.feasible, b.front.feasible)
    )


@pytest.mark.slow  # three small plans on the detour scene: ~25 s
def test_shared_relaxed_optima_give_the_same_plan() -> None:
    """A move planned at a start phase with the relaxed optima made by the task of another
    phase (a worker of the phase grid) is the move that phase's task plans by itself, bit
    for bit; the optima are not empty here (the detour's straight move is blocked), and
    other optima handed to it give another plan (they are used, not made again)."""
    task = replace(_task(Scene.shipped("detour")), start_time=0.5)
    made = relaxed_optima(replace(task, start_time=0.0))
    assert made
    assert all(len(x) > 0 and floor > 0 for x, floor in made.values())
    alone = plan_move(task)
    shared = plan_move(task, made)
    assert _same(alone, shared)
    # and they are what the search starts from: other optima, another plan
    other = {k: (x[::-1][:1], floor) for k, (x, floor) in made.items()}
    assert not _same(alone, plan_move(task, other))
