"""A value computed ahead, at the lowest priority, in a helper process: :class:`WorkAhead`.

A caller that may need a value later starts it here and goes on. The worker
(:class:`~adept_traj.process_pool.Worker`) computes it as its preparation, at nice
:data:`~adept_traj.process_pool.LOWEST_PRIORITY`: it takes a core only while one idles,
never one from the caller nor from the other helpers' imports, which share that priority.
:meth:`WorkAhead.result` raises it and every process it forked to the caller's priority
(:meth:`~adept_traj.process_pool.Worker.hurry`: the caller waits for it now) and returns
the value; :meth:`~adept_traj.process_helper.Helper.cancel` drops it unused.

The time-optimal mode computes the relaxed problem's optimum this way while it screens its
first start (:func:`~adept_traj.optimise.time_optimal`): on the paper scene that start
ends near the bound and the optimum is never used; on the detour scene it is, and the
caller waits for it with its own core idle.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

from adept_traj.errors import WorkerDiedError
from adept_traj.process_helper import Helper
from adept_traj.process_pool import LOWEST_PRIORITY, Channel, Worker, can_fork

__all__ = ["WorkAhead"]


class WorkAhead(Helper):
    """``make()`` computed in a worker process at the lowest priority (module docstring).

    Parameters
    ----------
    make:
        The computation, called without arguments in the worker (a copy of the caller at
        the fork: nothing is pickled but its value). It runs in a thread of the worker: a
        process it forks must end before it returns (as those of
        :func:`~adept_traj.process_pool.map_forked` do), since Linux ends a process forked
        from a thread that ends (:mod:`adept_traj.process_pool`).
    note:
        The note put before the worker's traceback on its error.

    Attributes
    ----------
    pid : int or None
        The worker's process id (``None`` without one: no ``fork``, or once it is reaped).
    """

    def __init__(self, make: Callable[[], Any], *, note: str = "raised in a worker ahead") -> None:
        self._make = make
        self._worker = None
        if can_fork():
            made: list[Any] = []
            self._worker = Worker(_send, made, prepare=partial(_made, made, make),
                                  prepare_niceness=LOWEST_PRIORITY, note=note)  # fmt: skip

    def result(self) -> Any:
        """The value of ``make()``: the worker's, raised first to the caller's priority
        (with the processes it forked); computed here without a worker, or if the worker
        died without a word (killed). The worker is stopped afterwards.

        Raises
        ------
        Exception
            The error of ``make`` (the worker's, with its traceback as a note).
        """
        worker = self._worker
        if worker is None or worker.pid is None:
            return self._make()
        worker.hurry()  # where the system refuses, it runs on at nice 19 (as fast on an idle core)
        try:
            return worker.recv()
        except WorkerDiedError:
            return self._make()
        finally:
            worker.close()


def _made(made: list[Any], make: Callable[[], Any]) -> None:
    """The worker's preparation: compute the value, or the error, and keep it."""
    try:
        made.append((True, make()))
    except Exception as exc:  # raised by the target, whose errors reach the caller as such
        made.append((False, exc))


def _send(channel: Channel, made: list[Any]) -> None:
    """The worker's target: send the value its preparation made, or raise its error."""
    done, value = made[0]
    if not done:
        raise value
    channel.send(value)
