"""Tasks on a problem, run on forked processes that share it: the pool of the phases of
:func:`~adept_traj.plan` after the search (the polish's local solves and the certificates,
:mod:`adept_traj.optimise.post_search`) and of
:func:`~adept_traj.optimise.certify_front_members`.

A task is a module-level function ``fn(problem, *args)``. :class:`ProblemTasks` with
``processes`` ≥ 2 forks that many processes (Linux ``fork``) once, at its first task, which
inherit the problem (and whatever the parent made of it before: e.g. its certifying problem,
:func:`~adept_traj.analysis.certifying_problem`), so that nothing but each task's
arguments and result is pickled; with one process, or where the platform has no
``fork``, every task runs in this process, in the order submitted, when its result is
asked for (:meth:`ProblemTasks.wait`). A task's result depends only on its arguments, so
both give the same results.

The caller keeps at most :attr:`ProblemTasks.processes` tasks submitted and not yet
waited for, and chooses the next one when one ends: the order of the work is the
caller's. An error of a task is raised by :meth:`~ProblemTasks.wait` (the same exception,
with the forked process' traceback and the task's name as a note); leaving the ``with``
block, normally, on an error or on Ctrl-C (which the forked processes leave to this one),
stops the processes at once, tasks still running included.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import queue
import signal
from collections import deque
from collections.abc import Callable
from typing import Any

from adept_traj.errors import ConfigurationError
from adept_traj.validation import as_integer

__all__ = ["ProblemTasks", "one_blas_thread"]

#: The problem of this forked process, set once by the pool's initializer; ``None`` in
#: every other process.
_PROBLEM: Any = None


class ProblemTasks:
    """Tasks ``fn(problem, *args)`` on ``processes`` forked processes (module docstring).

    Parameters
    ----------
    problem:
        The object every task receives first (a
        :class:`~adept_traj.problem.TrajectoryProblem`).
    processes:
        Processes running tasks at once, an integer ≥ 1; 1 (or no ``fork`` on this
        platform) runs them in this process.
    """

    def __init__(self, problem: Any, processes: int) -> None:
        n = as_integer(processes, "processes", minimum=1, error=ConfigurationError)
        if "fork" not in multiprocessing.get_all_start_methods():
            n = 1
        self.problem, self.processes = problem, n
        self._next = 0  # ticket of the next task
        self._names: dict[int, str] = {}
        self._inline: deque[tuple[int, Callable[..., Any], tuple[Any, ...]]] = deque()
        self._done: queue.SimpleQueue[int] = queue.SimpleQueue()
        self._results: dict[int, Any] = {}
        self._pool: Any = None  # forked at the first task
        self._blas: Any = None  # this process' BLAS thread limit while the pool lives

    @property
    def running(self) -> int:
        """Tasks submitted and not yet returned by :meth:`wait`."""
        return len(self._names)

    def submit(self, fn: Callable[..., Any], *args: Any, name: str = "a task") -> int:
        """Start ``fn(problem, *args)`` (queued, in this process); return its ticket.
        ``name`` (e.g. ``"the certificate of 4 members"``) is quoted if it fails."""
        ticket = self._next
        self._next += 1
        self._names[ticket] = name
        if self.processes == 1:
            self._inline.append((ticket, fn, args))
        else:
            if self._pool is None:
                # One BLAS thread in the processes, set before the fork (set in a forked
                # process it would start OpenBLAS' threads there, which spin), and in
                # this one while they run (it mostly waits for them).
                self._blas = one_blas_thread()
                self._blas.__enter__()
                context = multiprocessing.get_context("fork")
                self._pool = context.Pool(
                    self.processes, initializer=_start, initargs=(self.problem,)
                )
            self._results[ticket] = self._pool.apply_async(
                _call,
                (fn, args),
                callback=lambda _, t=ticket: self._done.put(t),
                error_callback=lambda _, t=ticket: self._done.put(t),
            )
        return ticket

    def wait(self) -> tuple[int, Any]:
        """(ticket, result) of a submitted task that ended (in this process: the oldest,
        run now). Raises the task's error, with the forked process' traceback as a note."""
        if not self._names:
            raise ConfigurationError("no task is running")
        if self.processes == 1:
            ticket, fn, args = self._inline.popleft()
            self._names.pop(ticket)
            return ticket, fn(self.problem, *args)
        ticket = self._done.get()
        name = self._names.pop(ticket)
        try:
            return ticket, self._results.pop(ticket).get()
        except Exception as exc:
            cause = exc.__cause__
            exc.add_note(f"raised by {name} in a forked process{':' if cause else ''}")
            if cause is not None:  # multiprocessing's RemoteTraceback: the child's text
                exc.add_note(str(cause).strip())
            raise

    def close(self) -> None:
        """Stop the processes at once (idempotent); tasks still running are lost."""
        pool, self._pool = self._pool, None
        if pool is not None:
            pool.terminate()
            pool.join()
        blas, self._blas = self._blas, None
        if blas is not None:
            blas.__exit__(None, None, None)
        self._names.clear()
        self._inline.clear()

    def __enter__(self) -> ProblemTasks:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def one_blas_thread() -> contextlib.AbstractContextManager[Any]:
    """A ``with`` block computing with one BLAS thread (:mod:`threadpoolctl`): SLSQP
    amplifies the last-bit differences of a BLAS whose sums depend on its thread count.
    In a :class:`ProblemTasks` process, which computes with one BLAS thread from its start
    (set in the parent before the fork), nothing: setting the count there again would
    start OpenBLAS' threads, which spin ≈ 20 ms each after starting."""
    if _PROBLEM is not None:
        return contextlib.nullcontext()
    # Lazy, and scipy first: the limit covers only the libraries loaded when it is set.
    import scipy.optimize  # noqa: F401
    from threadpoolctl import threadpool_limits  # lazy: scans the loaded libraries

    return threadpool_limits(limits=1, user_api="blas")


def _start(problem: Any) -> None:
    """Pool initializer, once per forked process: keep the problem; Ctrl-C is the parent's.
    The process computes with one BLAS thread (the parent's setting at the fork)."""
    global _PROBLEM
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _PROBLEM = problem


def _call(fn: Callable[..., Any], args: tuple[Any, ...]) -> Any:
    """Run in a forked process: ``fn(problem, *args)``."""
    if _PROBLEM is None:  # only a pool started by ProblemTasks calls this
        raise ConfigurationError("_call runs in a ProblemTasks process only")
    return fn(_PROBLEM, *args)
