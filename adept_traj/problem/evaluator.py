"""Parallel evaluation of a population on worker processes that the evaluator owns.

A :class:`~adept_traj.problem.TrajectoryProblem` with ``workers > 1`` creates one
:class:`ParallelEvaluator` when a population first needs it. The evaluator owns

- a :class:`concurrent.futures.ProcessPoolExecutor` whose ``workers`` processes are forked
  (Linux ``fork`` start method) at its first population, and
- the evaluation function the workers run, in practice a snapshot of the problem (a shallow
  copy without the evaluator). The pool's ``initializer`` stores it, once, in a global of
  each worker process (:data:`_WORKER_EVALUATE`): fork hands the function over by copying
  the parent's memory, nothing is pickled, and only the population chunks and their
  :class:`~adept_traj.problem.Evaluation` travel between the processes. In the parent
  process that global stays ``None``: there is no registry of live problems.

A population ``x`` (pop, n_var) is split into ``workers`` contiguous chunks (pop ≥ workers);
each worker evaluates its chunk exactly as the serial evaluation would, so the results are
identical, bit for bit, to evaluating ``x`` in one process. Because the workers hold a
snapshot, edits of the problem after the first parallel population (e.g. of
``robot.model``) are not seen by them until the evaluator is closed and a new one made.

The pool stops on :meth:`ParallelEvaluator.close`, on leaving a ``with`` block, and when the
evaluator's ``owner`` (the problem) is garbage-collected (:func:`weakref.finalize`; the
snapshot is a different object, so the pool does not keep its owner alive).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import weakref
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from adept_traj.errors import ConfigurationError, InputShapeError
from adept_traj.problem.evaluation import Evaluation, _concatenate
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


#: The evaluation function of this worker process, set once by the pool's initializer
#: (:func:`_start_worker`); ``None`` in every process that is not a pool worker.
_WORKER_EVALUATE: Callable[[np.ndarray], Evaluation] | None = None


def _start_worker(evaluate: Callable[[np.ndarray], Evaluation]) -> None:
    """Pool initializer, run once in each forked worker: keep the evaluation function, and
    leave Ctrl-C to the parent (which checkpoints and stops the run)."""
    global _WORKER_EVALUATE
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _WORKER_EVALUATE = evaluate


def _evaluate_chunk(x: np.ndarray) -> Evaluation:
    """Run in a worker: evaluate one chunk (k, n_var) of the population."""
    if _WORKER_EVALUATE is None:  # only a pool started by ParallelEvaluator calls this
        raise ConfigurationError("_evaluate_chunk runs in a ParallelEvaluator worker only")
    return _WORKER_EVALUATE(x)


class ParallelEvaluator:
    """Evaluates populations in contiguous chunks on ``workers`` forked processes it owns.

    Parameters
    ----------
    evaluate:
        Function of a population (k, n_var) returning its :class:`Evaluation` (k rows);
        the workers receive it once, when they are forked. It must not refer to ``owner``,
        or the owner is never collected.
    workers:
        Number of worker processes, an integer ≥ 2.
    n_var:
        Length of a decision vector (the population's last axis).
    owner:
        The pool also stops when this object is garbage-collected (default: the evaluator
        itself).

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
        self._pool = ProcessPoolExecutor(
            max_workers=self.workers,
            mp_context=multiprocessing.get_context("fork"),
            initializer=_start_worker,
            initargs=(evaluate,),
        )
        # Collected owner: stop without waiting (a finalizer must not block on the workers).
        self._finalizer = weakref.finalize(
            self if owner is None else owner, self._pool.shutdown, wait=False, cancel_futures=True
        )

    @property
    def running(self) -> bool:
        """Whether the pool is open (not yet closed nor finalised)."""
        return self._finalizer.alive

    def evaluate(self, x: np.ndarray) -> Evaluation:
        """Evaluate a population ``x`` (pop, n_var), pop ≥ ``workers``, on the workers.

        Returns the rows of the chunks' evaluations in the order of ``x`` (``seconds`` 0:
        the caller times the call). If a chunk fails, the other chunks are cancelled and
        the worker's exception is raised here.
        """
        if not self.running:
            raise ConfigurationError("this ParallelEvaluator is closed: make a new one")
        xa = as_batch(x, "x", self.n_var)
        if xa.ndim != 2 or len(xa) < self.workers:
            raise InputShapeError(
                f"x must have shape (pop, {self.n_var}) with pop ≥ workers = {self.workers}; "
                f"got {xa.shape}"
            )
        chunks = np.array_split(xa, self.workers)
        futures = [self._pool.submit(_evaluate_chunk, c) for c in chunks]
        try:
            parts = [f.result() for f in futures]
        except BaseException:
            for f in futures:
                f.cancel()
            raise
        return _concatenate(parts)

    def close(self) -> None:
        """Stop the worker processes and wait for them to exit (idempotent)."""
        if self._finalizer.detach() is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)

    def __enter__(self) -> ParallelEvaluator:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
