"""Shared fixtures: the paper problem (built once per session; evaluation is pure)."""

from __future__ import annotations

import os
import signal

import pytest

from adept_traj import Robot, Scene
from adept_traj.problem import TrajectoryProblem


@pytest.fixture(scope="session")
def problem() -> TrajectoryProblem:
    """The paper scenario's problem with default settings."""
    scene = Scene.paper()
    return TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)


@pytest.fixture
def process_gone():
    """``gone(pid)``: whether process ``pid`` has ended and been reaped (not in the
    process table any more)."""

    def gone(pid: int) -> bool:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        return False

    return gone


@pytest.fixture
def child_fault():
    """``faulty(real, fault)``: ``real`` wrapped so that in any process but this one it
    raises ``RuntimeError("broken in the child")`` (``fault="raises"``) or kills its
    process (``fault="killed"``); in this process it is ``real``."""
    caller = os.getpid()

    def faulty(real, fault: str):
        def wrapped(*args, **kwargs):
            if os.getpid() != caller:
                if fault == "killed":
                    os.kill(os.getpid(), signal.SIGKILL)
                raise RuntimeError("broken in the child")
            return real(*args, **kwargs)

        return wrapped

    return faulty
