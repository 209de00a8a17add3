"""A process and every process it forked, their threads and their priority:
:func:`tree_threads`, :func:`raise_priority`.

:meth:`~adept_traj.process_pool.Worker.hurry` raises a worker through them: a worker whose
preparation forks processes of its own (the relaxed problem's optimum computed ahead,
:class:`~adept_traj.work_ahead.WorkAhead`, screens its starts on two) has them raised with
it, since Linux niceness is per thread and a forked process starts at the niceness of the
thread that forked it.
"""

from __future__ import annotations

import contextlib
import os

__all__ = ["raise_priority", "tree_threads"]


def tree_threads(pid: int) -> list[int]:
    """The thread ids of process ``pid`` and of its descendants, parents first (Linux
    ``/proc/<pid>/task/<tid>/children``); ``[]`` once ``pid`` has ended or without
    ``/proc``. A process forked or ended meanwhile may be missed or listed: the caller
    treats each id as possibly gone.

    Parameters
    ----------
    pid:
        A process id.

    Returns
    -------
    list of int
        Thread ids (a process's first thread id is its process id).
    """
    out: list[int] = []
    todo = [pid]
    while todo:
        process = todo.pop(0)
        with contextlib.suppress(FileNotFoundError, ProcessLookupError):
            for tid in map(int, os.listdir(f"/proc/{process}/task")):
                out.append(tid)
                with (
                    contextlib.suppress(FileNotFoundError, ProcessLookupError),
                    open(f"/proc/{process}/task/{tid}/children") as children,
                ):
                    todo += [int(child) for child in children.read().split()]
    return out


def raise_priority(pid: int, niceness: int) -> bool:
    """Lower to ``niceness`` the niceness of every thread of process ``pid`` and of its
    descendants above it (:func:`tree_threads`; one at or below it is left as it is).

    Parameters
    ----------
    pid:
        A process id.
    niceness:
        The niceness to raise them to (e.g. the caller's,
        ``os.getpriority(os.PRIO_PROCESS, threading.get_native_id())``).

    Returns
    -------
    bool
        Whether it was done: ``False`` where the system refuses (that needs
        ``CAP_SYS_NICE`` or ``RLIMIT_NICE``), and once ``pid`` has ended or without
        ``/proc``.
    """
    threads = tree_threads(pid)
    try:
        for tid in threads:
            with contextlib.suppress(ProcessLookupError):  # that thread has ended
                current = os.getpriority(os.PRIO_PROCESS, tid)
                if current > niceness:
                    os.setpriority(os.PRIO_PROCESS, tid, niceness)
    except PermissionError:  # not allowed
        return False
    return bool(threads)
