"""adept_traj.process_tree: the threads of a process tree against an independent reading
of /proc (each process's parent from ``/proc/<pid>/stat``, not the ``children`` files),
and the raise of their priority (every thread of the tree, checked in /proc), refused
and said so where the system does not allow it."""

from __future__ import annotations

import contextlib
import os
import subprocess
import time
from pathlib import Path

from adept_traj.process_tree import raise_priority, tree_threads
from tests.conftest import may_lower_niceness

#: A shell that starts two sleeping children, one with a sleeping child of its own.
_TREE = "sleep 60 & (sleep 60 & wait) & wait"


def _parent_of() -> dict[int, int]:
    """Every process's parent, from field 4 of ``/proc/<pid>/stat``."""
    out = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:  # ended meanwhile
                continue
            out[int(entry.name)] = int(stat[stat.rfind(")") + 2 :].split()[1])
    return out


def _descendants(pid: int) -> set[int]:
    parent = _parent_of()
    found, todo = {pid}, [pid]
    while todo:
        p = todo.pop()
        kids = [c for c, pp in parent.items() if pp == p and c not in found]
        found.update(kids)
        todo += kids
    return found


def _tree(niceness: int = 0) -> subprocess.Popen:
    """The shell tree of :data:`_TREE` (four processes), started at ``niceness``, once
    its processes all exist."""
    shell = subprocess.Popen(
        ["sh", "-c", _TREE], preexec_fn=(lambda: os.nice(niceness)) if niceness else None
    )
    deadline = time.monotonic() + 30.0
    while len(_descendants(shell.pid)) < 4 and time.monotonic() < deadline:
        time.sleep(0.01)
    return shell


def _stop(shell: subprocess.Popen) -> None:
    for pid in sorted(_descendants(shell.pid), reverse=True):
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, 9)
    shell.wait(timeout=30)


def _processes(threads: list[int]) -> set[int]:
    """The processes (thread group ids) of these thread ids."""
    out = set()
    for tid in threads:
        status = Path(f"/proc/{tid}/status").read_text()
        out.add(int(status.split("Tgid:")[1].split()[0]))
    return out


def test_the_threads_of_a_tree_are_those_of_the_process_and_all_its_descendants() -> None:
    shell = _tree()
    try:
        threads = tree_threads(shell.pid)
        expected = _descendants(shell.pid)
        assert len(expected) == 4
        assert _processes(threads) == expected
        assert threads[0] == shell.pid  # parents first
        assert set(threads) >= expected  # a process's first thread id is its pid
    finally:
        _stop(shell)
    assert tree_threads(shell.pid) == []  # ended


def test_an_ended_process_has_no_threads_and_cannot_be_raised() -> None:
    ended = subprocess.Popen(["true"])
    ended.wait(timeout=30)  # reaped: its pid names no process now
    assert tree_threads(ended.pid) == []
    assert raise_priority(ended.pid, 0) is False


def _niceness(tid: int) -> int:
    return os.getpriority(os.PRIO_PROCESS, tid)


def test_raise_priority_lowers_the_niceness_of_every_thread_of_the_tree() -> None:
    own = os.getpriority(os.PRIO_PROCESS, 0)
    shell = _tree(niceness=19 - own)
    try:
        members = _descendants(shell.pid)
        assert {_niceness(pid) for pid in members} == {19}  # inherited by every fork
        if not may_lower_niceness():
            assert raise_priority(shell.pid, own) is False  # refused, said so
            return
        assert raise_priority(shell.pid, own) is True
        assert {_niceness(pid) for pid in members} == {own}
        assert raise_priority(shell.pid, 19) is True  # never lowered below: left as it is
        assert {_niceness(pid) for pid in members} == {own}
    finally:
        _stop(shell)
