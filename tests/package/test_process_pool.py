"""adept_traj.process_pool.Worker, the one mechanism for processes beside the caller: it
inherits its function (no pickling), answers over its pipe, carries its error back as the
same exception with its traceback, reports its death as WorkerDiedError, prepares at nice
19, holds no other worker's pipe (checked in /proc), ignores Ctrl-C, is stopped by close,
its block, garbage collection and the interpreter's exit, and dies with a killed parent —
its own workers too (checked in /proc)."""

from __future__ import annotations

import fcntl
import gc
import os
import signal
import subprocess
import sys
import threading
import time
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import pytest

from adept_traj.errors import AdeptTrajError, WorkerDiedError, WorkerError
from adept_traj.process_pool import (
    LOWEST_PRIORITY,
    Channel,
    Worker,
    children,
    map_forked,
    prepare_quietly,
    serve,
)
from tests.conftest import may_lower_niceness


def _ended(pid: int, within: float = 10.0) -> bool:
    """Whether process ``pid`` has ended (gone, or a zombie not ours to reap), checked
    until ``within`` [s] have passed."""
    deadline = time.monotonic() + within
    while True:
        try:
            fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        except (FileNotFoundError, ProcessLookupError):
            return True
        if fields[0] == "Z" and int(fields[1]) != os.getpid():
            return True
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)


def test_a_worker_serves_the_function_it_inherited() -> None:
    offset = 7
    add = lambda a, b: (os.getpid(), a + b + offset)  # noqa: E731 (a closure: never pickled)
    with Worker(serve, add) as worker:
        pid = worker.pid
        assert pid in children()
        for k in range(3):
            worker.send(k, 10)
            assert worker.recv() == (pid, k + 10 + offset)
    assert worker.pid is None
    assert pid not in children()
    assert _ended(pid, within=0.0)  # reaped by the block


class _Unpicklable(Exception):
    def __init__(self, a: int, b: int) -> None:  # pickles, but does not unpickle
        super().__init__(f"unpicklable {a} {b}")


def _raise(kind: str) -> None:
    if kind == "library":
        raise WorkerError("the worker's own error")
    raise _Unpicklable(1, 2)


def test_an_error_comes_back_as_itself_with_the_worker_traceback() -> None:
    with Worker(serve, _raise, note="raised in the test's worker") as worker:
        pid = worker.pid
        worker.send("library")
        with pytest.raises(WorkerError, match="the worker's own error") as caught:
            worker.recv()
    (note,) = caught.value.__notes__
    assert note.startswith("raised in the test's worker:\nTraceback")
    assert "in _raise" in note
    assert _ended(pid, within=0.0)


def test_an_error_that_does_not_unpickle_is_a_worker_error_with_its_text() -> None:
    worker = Worker(serve, _raise)
    worker.send("other")
    with pytest.raises(WorkerError, match=r"(?s)does not unpickle.*unpicklable 1 2"):
        worker.recv()
    assert worker.pid is None


def test_a_killed_worker_is_a_worker_died_error_and_a_broken_pool() -> None:
    worker = Worker(serve, lambda: os.kill(os.getpid(), signal.SIGKILL))
    pid = worker.pid
    worker.send()
    with pytest.raises(WorkerDiedError, match=f"pid {pid}.*ended abruptly") as caught:
        worker.recv()
    assert isinstance(caught.value, BrokenProcessPool)
    assert isinstance(caught.value, AdeptTrajError)
    assert worker.pid is None
    with pytest.raises(WorkerDiedError):
        worker.send()


def _niceness(channel: Channel, seen: list[int]) -> None:
    channel.send((seen, os.getpriority(os.PRIO_PROCESS, threading.get_native_id())))


def test_prepare_runs_at_nice_19_before_the_target_at_the_callers_priority() -> None:
    seen: list[int] = []
    prepare = lambda: seen.append(os.getpriority(os.PRIO_PROCESS, threading.get_native_id()))  # noqa: E731
    own = os.getpriority(os.PRIO_PROCESS, 0)
    with Worker(_niceness, seen, prepare=prepare) as worker:
        assert worker.ready(30.0)
        assert worker.recv() == ([LOWEST_PRIORITY], own)


def test_prepare_runs_at_the_callers_priority_when_asked() -> None:
    seen: list[int] = []
    prepare = lambda: seen.append(os.getpriority(os.PRIO_PROCESS, threading.get_native_id()))  # noqa: E731
    own = os.getpriority(os.PRIO_PROCESS, 0)
    assert own != LOWEST_PRIORITY
    with Worker(_niceness, seen, prepare=prepare, prepare_niceness=None) as worker:
        assert worker.ready(30.0)
        assert worker.recv() == ([own], own)


def _until_hurried() -> None:
    """A preparation that lasts until its thread is raised above nice 19 (at most 60 s)."""
    deadline = time.monotonic() + 60.0
    while os.getpriority(os.PRIO_PROCESS, threading.get_native_id()) == LOWEST_PRIORITY:
        if time.monotonic() > deadline:
            raise TimeoutError("never hurried")
        time.sleep(0.01)


def test_hurry_raises_a_preparing_worker_to_the_callers_priority() -> None:
    seen: list[int] = []
    with Worker(_niceness, seen, prepare=_until_hurried) as worker:
        time.sleep(0.2)
        assert not worker.ready()  # still preparing at nice 19
        if not may_lower_niceness():
            assert worker.hurry() is False  # refused by the system, said so
            return
        assert worker.hurry() is True
        assert worker.ready(30.0)
        assert worker.recv() == ([], os.getpriority(os.PRIO_PROCESS, 0))
    assert worker.hurry() is False  # stopped


def test_a_failing_preparation_is_not_ready_and_reaped() -> None:
    def fails() -> None:
        raise ImportError("no such module")

    worker = Worker(serve, len, prepare=fails)
    pid = worker.pid
    deadline = time.monotonic() + 30.0
    while worker.ready() is False and worker.pid is not None and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not worker.ready()
    assert worker.pid is None
    assert _ended(pid, within=0.0)
    assert "no such module" in prepare_quietly(fails)
    assert prepare_quietly(lambda: None) == ""


def _socket_inodes(pid: int) -> set[int]:
    """The inodes of the sockets process ``pid`` holds open, read from /proc."""
    out = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = os.readlink(fd)
        except OSError:  # closed meanwhile
            continue
        if target.startswith("socket:["):
            out.add(int(target[8:-1]))
    return out


def test_a_worker_forked_later_holds_no_earlier_worker_pipe() -> None:
    """No ordering rule: a worker forked after another does not hold the caller's end of
    the first one's pipe, so closing that end ends the first worker's wait."""
    first = Worker(serve, len)
    second = Worker(serve, len)
    try:
        callers_end = os.fstat(first._connection.fileno()).st_ino
        assert callers_end in _socket_inodes(os.getpid())
        second.send("abc")
        assert second.recv() == 3  # the second worker runs: it has closed what it inherited
        assert callers_end not in _socket_inodes(second.pid)
    finally:
        first.close()
        second.close()


def test_ctrl_c_is_the_callers_a_worker_ignores_sigint() -> None:
    with Worker(serve, len) as worker:
        os.kill(worker.pid, signal.SIGINT)
        worker.send([1, 2])
        assert worker.recv() == 2


def test_a_sigint_at_the_fork_instant_is_ignored_too() -> None:
    """SIGINT sent the instant the fork returns, before the worker could ignore it
    (CI once saw such a worker raise and run on as a copy of the caller): held until it
    is ignored, on every one of many workers; the caller's own signal mask unchanged."""
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, set())
    for n in range(40):
        with Worker(serve, len) as worker:
            os.kill(worker.pid, signal.SIGINT)
            worker.send(list(range(n)))
            assert worker.recv() == n
    assert signal.pthread_sigmask(signal.SIG_BLOCK, set()) == mask


_SIGINT_AT_FORK: list[int] = []  # the thread to signal at the next fork (then emptied)


def _signal_at_fork() -> None:
    if _SIGINT_AT_FORK:  # to the forking thread: a process-wide SIGINT may go to another
        signal.pthread_kill(_SIGINT_AT_FORK.pop(), signal.SIGINT)


os.register_at_fork(before=_signal_at_fork)


def test_a_ctrl_c_of_the_caller_during_the_fork_is_raised_after_it_and_stops_the_worker():
    """The user's Ctrl-C arrives while the caller forks (sent from the fork's own hook):
    held over the fork, it is the caller's KeyboardInterrupt at once after it, and the
    worker just forked is stopped (no process left behind)."""
    before = _os_children()
    handler = signal.signal(signal.SIGINT, signal.default_int_handler)  # xdist ignores it
    mask = signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # and may block it
    try:
        _SIGINT_AT_FORK.append(threading.get_ident())
        with pytest.raises(KeyboardInterrupt):
            Worker(serve, len)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        signal.signal(signal.SIGINT, handler)
    assert not _SIGINT_AT_FORK
    gc.collect()
    deadline = time.monotonic() + 10.0
    while _os_children() != before:  # killed, and reaped once it ended
        assert time.monotonic() < deadline, _os_children() - before
        children()  # reaps what was killed
        time.sleep(0.02)


def _os_children() -> set[int]:
    """The process ids of every child process of this one (from /proc, zombies included)."""
    tasks = Path(f"/proc/{os.getpid()}/task")
    return {int(p) for t in tasks.iterdir() for p in (t / "children").read_text().split()}


def test_a_collected_worker_is_stopped() -> None:
    worker = Worker(serve, len)
    pid = worker.pid
    del worker
    gc.collect()
    deadline = time.monotonic() + 10.0
    while pid in children() or not _ended(pid, within=0.0):  # killed, reaped once it ended
        assert time.monotonic() < deadline
        time.sleep(0.02)


def test_a_forked_copy_of_the_caller_leaves_its_workers_alone() -> None:
    with Worker(serve, len) as worker:
        child = os.fork()
        if child == 0:  # a copy: closing its (closed) copy of the worker must not kill it
            try:
                worker.close()
            finally:
                os._exit(0)
        os.waitpid(child, 0)
        worker.send("ab")
        assert worker.recv() == 2


_SCRIPT = """
import os, sys, time
from adept_traj.process_pool import Worker, serve

def nested(channel):
    inner = Worker(serve, len)  # a worker's own worker
    channel.send(inner.pid)
    time.sleep(60)

outer = Worker(nested)
idle = Worker(serve, len)
busy = Worker(serve, time.sleep)
busy.send(60)
print(outer.pid, outer.recv(), idle.pid, busy.pid, flush=True)
time.sleep(60)
"""


def test_a_killed_parent_leaves_no_worker_behind() -> None:
    """Waiting, busy and nested workers all end when their parent is killed outright."""
    parent = subprocess.Popen(
        [sys.executable, "-c", _SCRIPT], stdout=subprocess.PIPE, text=True, cwd=os.getcwd()
    )
    try:
        pids = [int(p) for p in parent.stdout.readline().split()]
        assert len(pids) == 4
        assert not any(_ended(pid, within=0.0) for pid in pids)
    finally:
        parent.kill()
        parent.wait()
    assert all(_ended(pid) for pid in pids)


def test_a_script_that_never_closes_its_workers_still_exits() -> None:
    script = (
        "from adept_traj.process_pool import Worker, serve\nw = Worker(serve, len)\nprint(w.pid)"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=60, check=False
    )
    assert done.returncode == 0, done.stderr
    assert _ended(int(done.stdout.split()[-1]))


def _children_of(pid: int) -> list[int]:
    """The processes whose parent is ``pid``, read from /proc."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (FileNotFoundError, ProcessLookupError):
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


@pytest.mark.slow
def test_a_killed_plan_command_leaves_no_process_behind(tmp_path: Path) -> None:
    """``adept-traj plan`` killed outright mid-search (its evaluation worker, finisher and
    polisher running): none of its processes is left, so the run folder's lock (a
    ``flock`` every fork inherits) is free at once for ``--resume`` (a polisher left
    preparing held it before)."""
    out = tmp_path / "run"
    argv = [sys.executable, "-m", "adept_traj.cli", "plan", "--quiet", "--out", str(out)]
    command = subprocess.Popen([*argv, "--pop", "16", "--gens", "400", "--workers", "2"])
    try:
        deadline = time.monotonic() + 120.0
        while not (out / "checkpoint").exists():
            assert time.monotonic() < deadline
            assert command.poll() is None
            time.sleep(0.05)
        helpers = _children_of(command.pid)
        assert len(helpers) >= 3  # the evaluation worker, the finisher, the polisher
    finally:
        command.kill()
        command.wait()
    assert all(_ended(pid) for pid in helpers)
    fd = os.open(out, os.O_RDONLY | os.O_DIRECTORY)
    start = time.monotonic()
    try:
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:  # released as the killed processes' files close
                assert time.monotonic() - start < 2.0
                time.sleep(0.01)
    finally:
        os.close(fd)


def test_map_forked_is_the_loop_in_order_and_raises_a_workers_error() -> None:
    """map_forked: the values of the plain loop, in order, for every group size; the
    values are computed in other processes (their pids differ from this one's, except the
    first of each group); an error raised in a worker is raised here."""
    items = list(range(7))
    for processes in (1, 2, 3, 8):
        out = map_forked(lambda k: (k * k, os.getpid()), items, processes)
        assert [v for v, _ in out] == [k * k for k in items]
        here = [k for k, (_, pid) in enumerate(out) if pid == os.getpid()]
        assert here == list(range(0, len(items), processes))

    def fails(k: int) -> int:
        if k == 1:
            raise ValueError("item 1 is bad")
        return k

    with pytest.raises(ValueError, match="item 1 is bad"):
        map_forked(fails, [0, 1], 2)
    assert children() == []  # every worker reaped
