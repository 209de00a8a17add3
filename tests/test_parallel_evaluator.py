"""ParallelEvaluator's failures: a worker's exception, a killed worker, Ctrl-C in the main
process' own chunk. Each is raised in the main process, the workers are stopped, and the
next population is evaluated by new workers."""

from __future__ import annotations

import multiprocessing
import os
import signal
from concurrent.futures.process import BrokenProcessPool

import numpy as np
import pytest

from adept_traj.errors import AdeptTrajError, InvalidInputError
from adept_traj.problem import Evaluation, ParallelEvaluator

#: First-variable values that make the evaluation function fail, by what they do.
_RAISE, _KILL, _INTERRUPT, _UNPICKLABLE = -1.0, -2.0, -3.0, -4.0


class _Unpicklable(Exception):
    def __init__(self, a: int, b: int) -> None:  # pickle calls __init__ with one argument
        super().__init__(f"{a} and {b}")


def _failing(main_pid: int):
    """An evaluation function whose chunk's first value says how it fails, and in which
    process (worker or main): rows are (x0, the process id)."""

    def evaluate(x: np.ndarray) -> Evaluation:
        in_worker = os.getpid() != main_pid
        if x[0, 0] == _RAISE and in_worker:
            raise InvalidInputError("bad chunk in the worker")
        if x[0, 0] == _UNPICKLABLE and in_worker:
            raise _Unpicklable(1, 2)
        if x[0, 0] == _KILL and in_worker:
            os.kill(os.getpid(), signal.SIGKILL)
        if x[-1, 0] == _INTERRUPT and not in_worker:
            raise KeyboardInterrupt
        k = len(x)
        return Evaluation(
            objectives=np.column_stack([x[:, 0], np.full(k, float(os.getpid()))]),
            constraints=np.zeros((k, 1)),
            min_distance=np.zeros((k, 0)),
            n_narrow=k,
        )

    return evaluate


def _workers() -> set:
    return {p.pid for p in multiprocessing.active_children()}


@pytest.mark.parametrize(
    ("first", "error", "match"),
    [
        (_RAISE, InvalidInputError, "bad chunk in the worker"),
        (_UNPICKLABLE, AdeptTrajError, "_Unpicklable: 1 and 2"),
        (_KILL, BrokenProcessPool, "ended abruptly"),
    ],
)
def test_a_failed_worker_is_raised_here_and_new_workers_follow(first, error, match) -> None:
    x = np.arange(8.0)[:, None] * np.ones((1, 2))
    before = _workers()
    with ParallelEvaluator(_failing(os.getpid()), workers=2, n_var=2) as evaluator:
        good = evaluator.evaluate(x)
        old = _workers() - before
        bad = x.copy()
        bad[0, 0] = first  # the worker's chunk (the main process takes the last one)
        with pytest.raises(error, match=match):
            evaluator.evaluate(bad)
        assert not (old & _workers())  # the old worker is stopped
        again = evaluator.evaluate(x)  # by a new worker
        assert (_workers() - before) - old
    np.testing.assert_array_equal(again.objectives[:, 0], good.objectives[:, 0])
    assert again.objectives[0, 1] != good.objectives[0, 1]


def test_a_worker_exception_carries_the_worker_traceback() -> None:
    x = np.arange(8.0)[:, None] * np.ones((1, 2))
    x[0, 0] = _RAISE
    evaluator = ParallelEvaluator(_failing(os.getpid()), workers=2, n_var=2)
    with evaluator, pytest.raises(InvalidInputError) as raised:
        evaluator.evaluate(x)
    (note,) = raised.value.__notes__
    assert note.startswith("raised in an evaluation worker process:")
    assert 'raise InvalidInputError("bad chunk in the worker")' in note


def test_ctrl_c_in_the_main_process_stops_the_busy_workers() -> None:
    x = np.arange(8.0)[:, None] * np.ones((1, 2))
    before = _workers()
    with ParallelEvaluator(_failing(os.getpid()), workers=3, n_var=2) as evaluator:
        bad = x.copy()
        bad[-1, 0] = _INTERRUPT
        with pytest.raises(KeyboardInterrupt):
            evaluator.evaluate(bad)
        assert _workers() == before  # terminated while they evaluated, and waited for
        np.testing.assert_array_equal(evaluator.evaluate(x).objectives[:, 0], x[:, 0])
