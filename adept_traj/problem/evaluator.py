"""Parallel evaluation of a population on the calling process and worker processes it owns.

A :class:`~adept_traj.problem.TrajectoryProblem` with ``workers > 1`` creates one
:class:`ParallelEvaluator` when a population first needs it. ``workers`` is the number of
processes that evaluate: the calling (main) process and ``workers - 1`` worker processes
(:class:`~adept_traj.process_pool.Worker`) that the evaluator forks at its first
population. A population ``x`` (pop, n_var) is split into ``min(workers, pop)``
contiguous chunks: each worker receives its chunk through its own pipe, the main process
evaluates the last chunk meanwhile, then reads the workers' evaluations back. Each chunk
is evaluated exactly as the serial evaluation would, so the results are identical, bit for
bit, to evaluating ``x`` in one process.

The workers run the evaluation function they inherited when they were forked (in practice
a snapshot of the problem: a shallow copy without the evaluator); nothing is pickled but
the chunks and their :class:`~adept_traj.problem.Evaluation`, with no helper thread and no
queue in between (a :class:`concurrent.futures.ProcessPoolExecutor` hands each chunk
through a queue thread and a feeder thread to one more process). The workers hold the
problem as it was when they were forked: after an edit of the problem (e.g. of
``robot.model``) close the evaluator, or the main process' chunk (which sees the edit)
and the workers' chunks (which do not) disagree.

Errors (:mod:`adept_traj.process_pool`): an exception in a worker is raised in the main
process (the same exception, with the worker's traceback as a note); a worker that dies
(e.g. killed) raises :class:`~adept_traj.errors.WorkerDiedError` (a
:class:`concurrent.futures.process.BrokenProcessPool`); on either, and on Ctrl-C (the
workers ignore SIGINT: the main process stops the run), the workers are stopped and the
next population forks new ones. The workers stop on :meth:`ParallelEvaluator.close`, on
leaving a ``with`` block, when the evaluator is garbage-collected (with the problem that
holds it: the snapshot is a different object, so the workers do not keep the problem
alive), and with the main process.
"""

from __future__ import annotations

import os
from collections.abc import Callable

import numpy as np

from adept_traj.errors import ConfigurationError, InputShapeError
from adept_traj.problem._heap import keep_heap
from adept_traj.problem.evaluation import Evaluation, concatenate_evaluations
from adept_traj.process_pool import Channel, Worker, can_fork, serve
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


#: The note before a worker's traceback on its error.
_NOTE = "raised in an evaluation worker process"


def _serve(channel: Channel, evaluate: Callable[[np.ndarray], Evaluation]) -> None:
    """A worker: evaluate each chunk the main process sends, send its evaluation back."""
    keep_heap()  # a process of ours: its blocks' freed temporaries serve the next block
    serve(channel, evaluate)


class ParallelEvaluator:
    """Evaluates populations in contiguous chunks on the calling process and
    ``workers - 1`` forked worker processes it owns.

    Parameters
    ----------
    evaluate:
        Function of a population (k, n_var) returning its :class:`Evaluation` (k rows);
        the workers receive it once, when they are forked, and the main process calls it on
        its own chunk.
    workers:
        Number of processes that evaluate (the main process included), an integer ≥ 2.
    n_var:
        Length of a decision vector (the population's last axis).

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
    ) -> None:
        self.workers = as_integer(workers, "workers", minimum=2, error=ConfigurationError)
        self.n_var = as_integer(n_var, "n_var", minimum=1, error=ConfigurationError)
        if not can_fork():
            raise ConfigurationError("workers > 1 needs the 'fork' start method (Linux)")
        self._evaluate = evaluate
        self._processes: list[Worker] = []  # forked at the first population
        self._pid = os.getpid()  # the process that forks them (and may use them)
        self._open = True

    @property
    def running(self) -> bool:
        """Whether the evaluator is open (not yet closed)."""
        return self._open

    def evaluate(self, x: np.ndarray) -> Evaluation:
        """Evaluate a population ``x`` (pop, n_var), pop ≥ 1.

        ``x`` is cut into ``min(workers, pop)`` chunks (a population smaller than
        ``workers`` leaves the last workers idle). Returns the rows of the chunks'
        evaluations in the order of ``x`` (``seconds`` 0: the caller times the call). If
        a chunk fails, its exception is raised here (a worker's with the worker's
        traceback as a note; a worker that died, while evaluating or before:
        :class:`~adept_traj.errors.WorkerDiedError`) and the workers are stopped
        (new ones are forked for the next population).
        """
        if not self.running:
            raise ConfigurationError("this ParallelEvaluator is closed: make a new one")
        xa = as_batch(x, "x", self.n_var)
        if xa.ndim != 2 or len(xa) < 1:
            raise InputShapeError(
                f"x must have shape (pop, {self.n_var}) with pop ≥ 1; got {xa.shape}"
            )
        if os.getpid() != self._pid:
            # A forked copy of the process that owns the workers (e.g. a process that
            # certifies front members): their pipes are not its own; it evaluates the
            # population itself (the same rows bit for bit).
            return self._evaluate(xa)
        # The main process takes the last chunk; workers beyond the chunks stay idle.
        chunks = np.array_split(xa, min(self.workers, len(xa)))
        try:
            if not self._processes:
                for _ in range(self.workers - 1):
                    self._processes.append(Worker(_serve, self._evaluate, note=_NOTE))
            used = self._processes[: len(chunks) - 1]
            for process, chunk in zip(used, chunks):
                process.send(np.ascontiguousarray(chunk))
            mine = self._evaluate(chunks[-1])
            parts = [process.recv() for process in used]
        except BaseException:  # a failed chunk, a dead worker, Ctrl-C: stop the workers
            self._stop()
            raise
        return concatenate_evaluations([*parts, mine])

    def close(self) -> None:
        """Stop the worker processes and wait for them to exit (idempotent)."""
        self._open = False
        self._stop()

    def _stop(self) -> None:
        """Stop the workers (idle or evaluating) and reap them."""
        processes, self._processes = self._processes, []
        for process in processes:
            process.close()

    def __enter__(self) -> ParallelEvaluator:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
