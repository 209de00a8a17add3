"""adept_traj.work_ahead.WorkAhead: the value computed in another process at nice 19,
raised with the processes it forked when the caller asks for it (checked in /proc), its
error carried back, computed in the caller without fork or when the worker was killed,
and dropped unused by cancel."""

from __future__ import annotations

import os
import signal
import threading
import time
from pathlib import Path

import pytest

import adept_traj.work_ahead as work_ahead
from adept_traj.process_pool import LOWEST_PRIORITY, map_forked
from adept_traj.work_ahead import WorkAhead
from tests.conftest import may_lower_niceness


def _where() -> tuple[int, int]:
    """(process id, niceness of this thread)."""
    return os.getpid(), os.getpriority(os.PRIO_PROCESS, threading.get_native_id())


def test_the_value_is_computed_in_another_process_at_the_lowest_priority() -> None:
    with WorkAhead(_where) as ahead:
        pid = ahead.pid
        assert pid is not None
        assert ahead.result() == (pid, LOWEST_PRIORITY)
    assert ahead.pid is None  # stopped once used


def _forks_and_reports(marker: Path) -> list[int]:
    """Two items on two processes (map_forked: the first in the worker's own thread):
    the forked one writes its pid; each waits until it is raised above nice 19 (at most
    60 s) and returns its niceness."""

    def item(k: int) -> int:
        if k == 1:  # written whole, then renamed: never read half-written
            part = marker.with_suffix(".part")
            part.write_text(str(os.getpid()))
            part.replace(marker)
        deadline = time.monotonic() + 60.0
        while _where()[1] == LOWEST_PRIORITY and time.monotonic() < deadline:
            time.sleep(0.01)
        return _where()[1]

    return map_forked(item, [0, 1], 2)


def test_result_raises_the_worker_and_the_processes_it_forked(tmp_path: Path) -> None:
    marker = tmp_path / "forked"
    own = os.getpriority(os.PRIO_PROCESS, 0)
    ahead = WorkAhead(lambda: _forks_and_reports(marker))
    deadline = time.monotonic() + 30.0
    while not marker.exists() and time.monotonic() < deadline:
        time.sleep(0.01)
    forked = int(marker.read_text())
    assert forked != ahead.pid
    assert os.getpriority(os.PRIO_PROCESS, forked) == LOWEST_PRIORITY  # forked at nice 19
    if not may_lower_niceness():
        ahead.cancel()  # the system refuses the raise: the forked item would wait 60 s
        return
    first, second = ahead.result()
    assert first == own  # the worker's thread, raised
    assert second == own  # the process it forked, raised with it


def _fails() -> None:
    raise ValueError("no relaxed optimum today")


def test_an_error_of_the_computation_is_raised_by_result() -> None:
    ahead = WorkAhead(_fails, note="raised in the test's worker")
    with pytest.raises(ValueError, match="no relaxed optimum today") as info:
        ahead.result()
    assert any("raised in the test's worker" in note for note in info.value.__notes__)
    assert ahead.pid is None


def test_without_fork_or_after_a_kill_the_value_is_computed_here(monkeypatch) -> None:
    here = os.getpid()

    def slow_elsewhere() -> tuple[int, int]:
        # the worker never finishes before its kill (its value sent first would be read)
        while os.getpid() != here:
            time.sleep(0.05)
        return _where()

    ahead = WorkAhead(slow_elsewhere)
    os.kill(ahead.pid, signal.SIGKILL)
    assert ahead.result() == _where()  # died without a word: computed in the caller
    monkeypatch.setattr(work_ahead, "can_fork", lambda: False)
    alone = WorkAhead(_where)
    assert alone.pid is None
    assert alone.result() == _where()


def test_cancel_drops_the_work_unused() -> None:
    """The worker is killed and reaped at once (no process left behind)."""
    ahead = WorkAhead(lambda: time.sleep(60))
    pid = ahead.pid
    assert Path(f"/proc/{pid}").exists()
    ahead.cancel()
    assert ahead.pid is None
    assert not Path(f"/proc/{pid}").exists()
