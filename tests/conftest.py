"""Shared fixtures: the paper problem (built once per session; evaluation is pure), and
final populations of given members (``run_state``)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from adept_traj import Robot, Scene
from adept_traj.optimise import RunState
from adept_traj.problem import TrajectoryProblem, to_pymoo


@pytest.fixture(scope="session")
def problem() -> TrajectoryProblem:
    """The paper scenario's problem with default settings."""
    scene = Scene.paper()
    return TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)


@pytest.fixture(scope="session")
def run_state() -> Callable[[TrajectoryProblem, np.ndarray, int], RunState]:
    """``run_state(problem, x, n_evaluations)``: a search's final population of the members
    ``x`` (k, n_var) after ``n_evaluations`` evaluations (1 s of run, half of it evaluating),
    to polish or certify."""

    def make(problem: TrajectoryProblem, x: np.ndarray, n_evaluations: int) -> RunState:
        ev = problem.evaluate_batch(x)
        return RunState(
            X=x,
            F=to_pymoo(ev.objectives),
            G=ev.constraints,
            CV=np.maximum(ev.constraints, 0.0).sum(axis=1),
            n_generations=1,
            n_evaluations=n_evaluations,
            total_s=1.0,
            evaluation_s=0.5,
        )

    return make
