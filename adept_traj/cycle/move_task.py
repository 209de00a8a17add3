"""One move of a cycle as a task: what a worker needs to plan it, and the planning itself.

A :class:`MoveTask` is pickled to a Dask worker, which plans it with
:func:`plan_and_encode` (:func:`plan_move`, then the result's files encoded in the worker).

**Shared relaxed optima.** Where obstacles move, :func:`~adept_traj.optimise.plan` seeds
its search with the relaxed problem's fastest certified move
(:func:`~adept_traj.optimise.initial_starts`: the move's problem without its moving
obstacles). That relaxed problem does not depend on the task's start time, seed,
algorithm or budget: only on the robot, the scene's fixed obstacles, the move's ends and
the certificate rate (:func:`relaxed_group`). So the tasks of one group (a move at every
start phase of a phase grid, every seed of a seed study) share it: it is made once per
group by :func:`relaxed_optima` (a task of its own) and handed to each task, which keeps it
on its problem before planning (``plan_move(task, relaxed)``,
:meth:`~adept_traj.problem.TrajectoryProblem.derived`) instead of solving it again. The
same values, bit for bit: the relaxed optimum is deterministic.
"""

from __future__ import annotations

import json
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.cycle.cycle_file import Cycle, MoveSpec
from adept_traj.optimise import initial_starts, plan
from adept_traj.optimise.local.multi_start import made_relaxed_optima
from adept_traj.problem import TrajectoryProblem
from adept_traj.results import PlanningResult
from adept_traj.robot import RobotSource
from adept_traj.scene import Scene
from adept_traj.scene.robot_motion import load_robot

__all__ = [
    "MoveTask",
    "RelaxedOptima",
    "SavedMove",
    "cycle_tasks",
    "plan_and_encode",
    "plan_move",
    "relaxed_group",
    "relaxed_optima",
]

#: The relaxed optima a problem made, by their key (``made_relaxed_optima``): (k, n_var)
#: moves and the floor T [s].
RelaxedOptima = dict[str, tuple[np.ndarray, float]]


@dataclass(frozen=True)
class MoveTask:
    """Everything a worker needs to plan one move (pickled to it).

    Attributes
    ----------
    move: the move; start, goal: (nq,) joints [rad | m].
    robot: where the worker loads the robot; scene: the scene; rate_hz: certificate rate.
    start_time: scene time [s] at which the move starts (the problem's ``start_time``).
    """

    move: MoveSpec
    start: np.ndarray
    goal: np.ndarray
    robot: RobotSource
    scene: Scene
    rate_hz: float
    start_time: float = 0.0

    def description(self) -> dict[str, Any]:
        """The JSON form written to ``move.json`` (what identifies the task's result)."""
        m = self.move
        clock = {"start_time": self.start_time} if self.start_time else {}  # 0: as before
        return json.loads(
            json.dumps(
                {
                    **clock,
                    "name": m.name,
                    "from": m.start,
                    "to": m.goal,
                    "start": self.start.tolist(),
                    "goal": self.goal.tolist(),
                    "algorithm": m.algorithm,
                    "seed": m.seed,
                    "pop_size": m.pop_size,
                    "n_gen": m.n_gen,
                    "weights": list(m.weights),
                    "rate_hz": self.rate_hz,
                    "robot": {"urdf": str(self.robot.urdf), "params": str(self.robot.params)},
                    "scene": self.scene.to_dict(),
                }
            )
        )


def cycle_tasks(cycle: Cycle) -> list[MoveTask]:
    """One :class:`MoveTask` per move of ``cycle``, in order."""
    return [
        MoveTask(
            move=m,
            start=cycle.locations[m.start].joints,
            goal=cycle.locations[m.goal].joints,
            robot=cycle.robot,
            scene=cycle.scene,
            rate_hz=cycle.rate_hz,
        )
        for m in cycle.moves
    ]


def _problem(task: MoveTask) -> TrajectoryProblem:
    robot = load_robot(task.robot)  # once per source in a worker process
    return TrajectoryProblem(
        robot, task.scene, task.start, task.goal, workers=1, start_time=task.start_time
    )


def relaxed_group(task: MoveTask) -> str | None:
    """What the relaxed optimum of ``task`` depends on, as a key (module doc): tasks of
    equal keys share it; ``None`` without moving obstacles (there is none to make)."""
    if not task.scene.moving:
        return None
    d = task.description()
    return json.dumps([d[k] for k in ("start", "goal", "rate_hz", "robot", "scene")])


def relaxed_optima(task: MoveTask) -> RelaxedOptima:
    """The relaxed optima :func:`~adept_traj.optimise.plan` makes for ``task``'s search
    (:func:`~adept_traj.optimise.initial_starts`), by key, to hand to every task of its
    :func:`relaxed_group` (the body of a Dask task)."""
    problem = _problem(task)
    try:
        initial_starts(problem, rate_hz=task.rate_hz)
        return made_relaxed_optima(problem)
    finally:
        problem.close()


def plan_move(task: MoveTask, relaxed: RelaxedOptima | None = None) -> PlanningResult:
    """Plan one move (the body of a Dask task; also callable directly); ``relaxed``: its
    group's relaxed optima (:func:`relaxed_optima`), kept on the problem and not made
    again."""
    m = task.move
    problem = _problem(task)
    for key, value in (relaxed or {}).items():
        problem.derived(key, lambda _p, v=value: v)
    try:
        return plan(
            problem,
            m.algorithm,
            seed=m.seed,
            pop_size=m.pop_size,
            n_gen=m.n_gen,
            weights=m.weights,
            rate_hz=task.rate_hz,
        )
    finally:
        problem.close()


@dataclass(frozen=True)
class SavedMove:
    """What a cycle's task returns: the planning ``result`` and ``files``, file name ->
    bytes of every file :meth:`~adept_traj.results.PlanningResult.save` writes."""

    result: PlanningResult
    files: dict[str, bytes]


def plan_and_encode(task: MoveTask, relaxed: RelaxedOptima | None = None) -> SavedMove:
    """Plan one move (:func:`plan_move`) and encode its result files in the worker (the
    body of a cycle's Dask task): the command only writes the bytes, so the encoding runs
    in parallel."""
    result = plan_move(task, relaxed)
    with tempfile.TemporaryDirectory(prefix="adept-traj-move-") as tmp:
        folder = result.save(Path(tmp) / "result")
        files = {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}
    return SavedMove(result, files)
