"""Shared fixtures: the paper problem (built once per session; evaluation is pure)."""

from __future__ import annotations

import os
import signal

import pytest

from adept_traj import Robot, Scene
from adept_traj.problem import TrajectoryProblem

# A test run started in the background (`nohup … &`, a shell without job control) inherits
# SIGINT ignored, and so would every command the tests start (an ignored signal stays
# ignored across exec): the Ctrl-C tests would then see a command that Ctrl-C cannot stop.
# A Ctrl-C at a terminal reaches the foreground command: the tests run as under one.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


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
