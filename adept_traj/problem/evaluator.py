"""Parallel evaluation of a population on the calling process and worker processes it owns.

A :class:`~adept_traj.problem.TrajectoryProblem` with ``workers > 1`` creates one
:class:`ParallelEvaluator` when a population first needs it. ``workers`` is the number of
processes that evaluate: the calling (main) process and ``workers - 1`` worker processes
that the evaluator forks (Linux ``fork``) at its first population. A population ``x``
(pop, n_var) is split into ``min(workers, pop)`` contiguous chunks: each worker
receives its chunk through its own pipe, the main process evaluates the last chunk
meanwhile, then reads the workers' evaluations back. Each chunk is evaluated exactly as
the serial evaluation would, so the results are identical, bit for bit, to evaluating
``x`` in one process.

The workers run the evaluation function they inherited when they were forked (in practice
a snapshot of the problem: a shallow copy without the evaluator); nothing is pickled but
the chunks and their :class:`~adept_traj.problem.Evaluation`, with no helper thread and no
queue in between (a :class:`concurrent.futures.ProcessPoolExecutor` hands each chunk
through a queue thread and a feeder thread to one more process). The workers hold the
problem as it was when they were forked: after an edit of the problem (e.g. of
``robot.model``) close the evaluator, or the main process' chunk (which sees the edit)
and the workers' chunks (which do not) disagree.

Errors: an exception in a worker is raised in the main process (the same exception, with
the worker's traceback as a note); a worker that dies (e.g. killed) raises
:class:`concurrent.futures.process.BrokenProcessPool`; on either, and on Ctrl-C (the
workers ignore SIGINT: the main process stops the run), the workers are stopped and the
next population forks new ones. The workers stop on :meth:`ParallelEvaluator.close`, on
leaving a ``with`` block, and when the evaluator's ``owner`` (the problem) is
garbage-collected (:func:`weakref.finalize`; the snapshot is a different object, so the
workers do not keep the owner alive); a worker whose main process dies reads the end of
its pipe and exits.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import pickle
import signal
import weakref
from collections.abc import Callable
from concurrent.futures.process import BrokenProcessPool
from multiprocessing.connection import Connection

import numpy as np

from adept_traj.errors import (
    AdeptTrajError,
    ConfigurationError,
    InputShapeError,
    error_from_process,
)
from adept_traj.problem._heap import keep_heap
from adept_traj.problem.evaluation import Evaluation, concatenate_evaluations
from adept_traj.processes import error_report
from adept_traj.validation import as_batch, as_integer

__all__ = ["ParallelEvaluator", "available_cores"]


def available_cores() -> int:
    """The number of CPU cores this process may run on (≥ 1): the size of its affinity
    mask (:func:`os.sched_getaffinity`, which honours ``taskset`` and container CPU sets),
    or :func:`os.cpu_count` where the platform has no affinity mask."""
    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # no affinity mask on this platform (macOS, Windows)
        n = os.cpu_count() or 1
    return max(1, n)


#: Seconds a worker is given to exit on the evaluator's word before it is terminated.
_STOP_TIMEOUT = 5.0


class _Workers:
    """The worker processes of one evaluator and the main process' end of their pipes
    (mutable state shared with the evaluator's finalizer, which must not hold the
    evaluator)."""

    def __init__(self) -> None:
        self.processes: list[multiprocessing.process.BaseProcess] = []
        self.connections: list[Connection] = []
        self.busy = False  # chunks sent whose evaluations are not read yet
        self.pid = os.getpid()  # the process that forked them (and may stop them)

    def start(self, evaluate: Callable[[np.ndarray], Evaluation], count: int) -> None:
        """Fork ``count`` workers running ``evaluate``."""
        context = multiprocessing.get_context("fork")
        for _ in range(count):
            mine, theirs = context.Pipe()
            process = context.Process(
                target=_serve, args=(evaluate, theirs, [mine, *self.connections]), daemon=True
            )
            process.start()
            theirs.close()  # the worker's end lives in the worker only: EOF if it dies
            self.processes.append(process)
            self.connections.append(mine)

    def stop(self, wait: bool) -> None:
        """Close the pipes (an idle worker exits on reading their end); terminate workers
        still evaluating; with ``wait``, wait for every worker to exit."""
        processes, connections, busy = self.processes, self.connections, self.busy
        self.processes, self.connections, self.busy = [], [], False
        mine = os.getpid() == self.pid  # else a forked copy of the main process
        for connection in connections:
            if mine and not busy:
                # An explicit word: another process forked from this one may hold a copy
                # of this end of the pipe, and the worker would never read its end.
                with contextlib.suppress(OSError):
                    connection.send(None)
            connection.close()
        if not mine:
            return
        for process in processes:
            if busy:
                process.terminate()
            if wait:
                process.join(timeout=_STOP_TIMEOUT)
                if process.is_alive():  # deaf to the word: stopped outright
                    process.terminate()
                    process.join()


def _serve(
    evaluate: Callable[[np.ndarray], Evaluation],
    connection: Connection,
    inherited: list[Connection],
) -> None:
    """A worker's loop: read a chunk, send back ``("", its Evaluation)`` or ``(the
    traceback, the pickled exception or None)``; return at the end of the pipe."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the main process' to handle
    keep_heap()  # a process of ours: its blocks' freed temporaries serve the next block
    for other in inherited:  # the main process' ends of this and earlier workers' pipes
        other.close()
    while True:
        try:
            x = connection.recv()
        except (EOFError, OSError):  # the evaluator closed the pipe, or its process died
            return
        if x is None:  # the evaluator's word to stop
            return
        try:
            reply = pickle.dumps(("", evaluate(x)), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception as exc:  # sent to the main process, which raises it
            reply = pickle.dumps(error_report(exc))
        try:
            connection.send_bytes(reply)
        except OSError:  # the main process is gone
            return


class ParallelEvaluator:
    """Evaluates populations in contiguous chunks on the calling process and
    ``workers - 1`` forked worker processes it owns.

    Parameters
    ----------
    evaluate:
        Function of a population (k, n_var) returning its :class:`Evaluation` (k rows);
        the workers receive it once, when they are forked, and the main process calls it on
        its own chunk. It must not refer to ``owner``, or the owner is never collected.
    workers:
        Number of processes that evaluate (the main process included), an integer ≥ 2.
    n_var:
        Length of a decision vector (the population's last axis).
    owner:
        The workers also stop when this object is garbage-collected (default: the
        evaluator itself).

    Raises
    ------
    ConfigurationError
        ``workers`` is not an integer ≥ 2, or the platform has no ``fork`` start method.
    """

    def __init__(
        self,
        evaluate: Callable[[np.ndarray], Evaluation],
        workers: int,
        n_var: int,
        owner: object | None = None,
    ) -> None:
        self.workers = as_integer(workers, "workers", minimum=2, error=ConfigurationError)
        self.n_var = as_integer(n_var, "n_var", minimum=1, error=ConfigurationError)
        if "fork" not in multiprocessing.get_all_start_methods():
            raise ConfigurationError("workers > 1 needs the 'fork' start method (Linux)")
        self._evaluate = evaluate
        self._workers = _Workers()
        # Collected owner: stop without waiting (a finalizer must not block on the workers).
        self._finalizer = weakref.finalize(
            self if owner is None else owner, self._workers.stop, wait=False
        )

    @property
    def running(self) -> bool:
        """Whether the evaluator is open (not yet closed nor finalised)."""
        return self._finalizer.alive

    def evaluate(self, x: np.ndarray) -> Evaluation:
        """Evaluate a population ``x`` (pop, n_var), pop ≥ 1.

        ``x`` is cut into ``min(workers, pop)`` chunks (a population smaller than
        ``workers`` leaves the last workers idle). Returns the rows of the chunks'
        evaluations in the order of ``x`` (``seconds`` 0: the caller times the call). If
        a chunk fails, its exception is raised here (a worker's with the worker's
        traceback as a note; a worker that died, while evaluating or before:
        :class:`concurrent.futures.process.BrokenProcessPool`) and the workers are stopped
        (new ones are forked for the next population).
        """
        if not self.running:
            raise ConfigurationError("this ParallelEvaluator is closed: make a new one")
        xa = as_batch(x, "x", self.n_var)
        if xa.ndim != 2 or len(xa) < 1:
            raise InputShapeError(
                f"x must have shape (pop, {self.n_var}) with pop ≥ 1; got {xa.shape}"
            )
        pool = self._workers
        if os.getpid() != pool.pid:
            # A forked copy of the process that owns the workers (e.g. a process that
            # certifies front members): their pipes are not its own; it evaluates the
            # population itself (the same rows bit for bit).
            return self._evaluate(xa)
        # The main process takes the last chunk; workers beyond the chunks stay idle.
        chunks = np.array_split(xa, min(self.workers, len(xa)))
        try:
            if not pool.processes:
                pool.start(self._evaluate, self.workers - 1)
            pool.busy = True
            used = list(zip(pool.processes, pool.connections))[: len(chunks) - 1]
            for (process, connection), chunk in zip(used, chunks):
                _send(process, connection, np.ascontiguousarray(chunk))
            mine = self._evaluate(chunks[-1])
            parts = [_receive(p, c) for p, c in used]
            pool.busy = False
        except BaseException:  # a failed chunk, a dead worker, Ctrl-C: stop the workers
            pool.stop(wait=True)
            raise
        return concatenate_evaluations([*parts, mine])

    def close(self) -> None:
        """Stop the worker processes and wait for them to exit (idempotent)."""
        if self._finalizer.detach() is not None:
            self._workers.stop(wait=True)

    def __enter__(self) -> ParallelEvaluator:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _send(
    process: multiprocessing.process.BaseProcess, connection: Connection, chunk: np.ndarray
) -> None:
    """Send ``chunk`` to a worker; a worker that died (e.g. killed between two
    populations) is a :class:`~concurrent.futures.process.BrokenProcessPool`."""
    try:
        connection.send(chunk)
    except OSError as exc:  # EPIPE: the worker's end is gone
        raise _broken(process) from exc


def _broken(process: multiprocessing.process.BaseProcess) -> BrokenProcessPool:
    """The error for a worker that died (its pipe broken or closed), once it is reaped."""
    process.join(timeout=1.0)
    return BrokenProcessPool(
        f"an evaluation worker process (pid {process.pid}) ended abruptly "
        f"(exit code {process.exitcode})"
    )


def _receive(process: multiprocessing.process.BaseProcess, connection: Connection) -> Evaluation:
    """A worker's evaluation of its chunk, or its exception raised here."""
    try:
        text, payload = pickle.loads(connection.recv_bytes())
    except (EOFError, OSError) as exc:  # the worker died without a word
        raise _broken(process) from exc
    if text:
        raise error_from_process(
            text,
            payload,
            "raised in an evaluation worker process",
            AdeptTrajError(f"the evaluation failed in a worker process:\n{text}"),
        )
    return payload
