"""adept_traj.processes: a forked helper says "ready" once prepared (its preparation runs
in a thread at nice 19), answers over its pipe, and is stopped and reaped when the block is
left, however it is left; a helper killed before answering gives None."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

from adept_traj.processes import LOWEST_PRIORITY, READY, ForkedHelper, prepare_quietly


def _echo(conn, callers_end, parent, how: str) -> None:
    """A helper: say ready, then answer its parent's pid and the preparing thread's
    niceness, be killed before answering, or wait forever."""
    callers_end.close()
    nice = []
    prepare_quietly(lambda: nice.append(os.getpriority(os.PRIO_PROCESS, threading.get_native_id())))
    conn.send(READY)
    if how == "killed":
        os.kill(os.getpid(), signal.SIGKILL)
    if how == "waits":
        time.sleep(60.0)
    conn.send((parent, nice[0]))
    os._exit(0)


def test_a_helper_is_ready_answers_and_is_reaped(process_gone) -> None:
    with ForkedHelper(_echo, ("answers",)) as helper:
        pid = helper.pid
        assert helper.ready(30.0)
        assert helper._answer() == (os.getpid(), LOWEST_PRIORITY)
        assert helper.pid is None
    assert process_gone(pid)


def test_a_killed_helper_answers_none() -> None:
    with ForkedHelper(_echo, ("killed",)) as helper:
        assert helper.ready(30.0)
        assert helper._answer() is None


def test_leaving_the_block_stops_the_helper(process_gone) -> None:
    helper = ForkedHelper(_echo, ("waits",))
    pid = helper.pid

    def interrupted() -> None:
        with helper:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        interrupted()
    assert helper.pid is None
    assert process_gone(pid)
    assert not helper.ready()


def test_no_target_forks_nothing() -> None:
    helper = ForkedHelper(None)
    assert helper.pid is None
    assert not helper.ready()
    helper.cancel()  # a no-op


def test_prepare_quietly_returns_the_traceback_of_a_failure() -> None:
    def fails() -> None:
        raise RuntimeError("import broken")

    assert "import broken" in prepare_quietly(fails)
    assert prepare_quietly(lambda: None) == ""
