"""Shared fixtures: the paper problem (built once per session; evaluation is pure)."""

from __future__ import annotations

import pytest

from adept_traj import Robot, Scene
from adept_traj.problem import TrajectoryProblem


@pytest.fixture(scope="session")
def problem() -> TrajectoryProblem:
    """The paper scenario's problem with default settings."""
    scene = Scene.paper()
    return TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)
