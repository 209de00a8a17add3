"""plan's phases after the search on forked processes (issue #15): the polish's solves, the
front's certificates made meanwhile and the reported solution's certificate are those of
the serial phases, bit for bit; no member is certified twice and none is left out; an
error of a forked process is raised here with its traceback."""

from __future__ import annotations

import dataclasses
import json
import time
from pathlib import Path

import numpy as np
import pytest

from adept_traj import TrajectoryProblem
from adept_traj.analysis import PAPER_WEIGHTS, best_tradeoff
from adept_traj.errors import ConfigurationError, InputShapeError, InvalidInputError
from adept_traj.optimise import RampSampling, kinematic_time, planner, post_search
from adept_traj.optimise.forks import ProblemTasks
from adept_traj.optimise.polish_step import GRADIENT_COST, POLISH_SHARE, _polish_run
from adept_traj.validation import deep_equal

#: Three members of a paper-budget NSGA-II front (see the file's "source").
MEMBERS = Path(__file__).parent / "data" / "paper_front_members.json"

#: The certificates' rate [Hz] (lower than plan's 1 kHz: cheaper, the same code).
RATE = 400.0


def _budget(budget: int) -> int:
    """The search's evaluations whose ``"front"`` polish may spend ``budget`` gradient
    evaluations."""
    return int(np.ceil(budget * GRADIENT_COST / POLISH_SHARE))


@pytest.fixture(scope="module")
def population(problem: TrajectoryProblem) -> np.ndarray:
    """The three paper-front members and eight ramps at 1.2 × their kinematic minimum time
    (some feasible and on the front: certified while the members are polished)."""
    ramps = RampSampling().ramps(problem, 8, np.random.default_rng(3))
    ramps[:, 0] = np.clip(1.2 * kinematic_time(problem, ramps), problem.xl[0], problem.xu[0])
    return np.concatenate([np.array(json.loads(MEMBERS.read_text())["x"]), ramps])


def _phases(problem, state, processes, records=None, started=None):
    """plan's phases after the search on ``processes`` processes: the polished state, the
    front, its summaries, the reported certificate and its row; ``records`` and ``started``
    receive the ``(kind, what)`` of each task that ended, and of each task started."""
    with post_search.PostSearch(problem, RATE, processes, True) as post:
        if started is not None:
            submit = post._submit

            def starting(kind, what, *args):
                started.append((kind, what))
                submit(kind, what, *args)

            post._submit = starting
        if records is not None:
            real = post._record

            def recording(ticket, result):
                records.append(post._flight[ticket])
                real(ticket, result)

            post._record = recording
        polished, made = post.polish(state, "front", PAPER_WEIGHTS)
        front = planner._front(polished)[0]
        order = best_tradeoff(front.objectives, PAPER_WEIGHTS).order
        summaries, certificate, index = post.certificates(front.x, front.feasible, order, None)
    return polished, made, front, summaries, certificate, index


def _same(got: tuple, expected: tuple) -> None:
    """The same results of :func:`_phases`, every field and bit (not the measured times)."""
    timing = {"total_s": 0.0, "evaluation_s": 0.0}
    assert deep_equal(
        dataclasses.replace(got[0], **timing), dataclasses.replace(expected[0], **timing)
    )
    for a, b in zip(got[1:], expected[1:]):
        assert deep_equal(a, b)  # summaries, front, certificate


#: Gradient evaluations of the polish in the default-tier tests: the fastest member's solve
#: and one ε-step (6 and 9–33 on paper members, measured).
ONE_STEP = 30


@pytest.fixture(scope="module")
def serial(problem, population, run_state):
    state = run_state(problem, population, _budget(ONE_STEP))
    return state, _phases(problem, state, 1)


@pytest.mark.slow  # a third polish: ~1 s
def test_serial_phases_are_the_polish_and_certificates_of_plan(problem, serial) -> None:
    """One process: the polish of polish_run and a summary per feasible front member."""
    state, (polished, made, front, summaries, _, _) = serial
    again, again_made = _polish_run(problem, state, RATE, "front", PAPER_WEIGHTS)
    _same((again, again_made), (polished, made))
    assert len(polished.X) > len(state.X)  # the polish kept moves
    assert all((s is not None) == bool(f) for s, f in zip(summaries, front.feasible))


@pytest.mark.slow  # two full polishes (the fastest member and two steps): ~3 s
def test_two_processes_give_the_serial_results_with_every_step(
    problem, population, run_state
) -> None:
    state = run_state(problem, population, _budget(10_000))
    _same(_phases(problem, state, 2), _phases(problem, state, 1))


def test_two_processes_give_the_serial_results(problem, serial) -> None:
    state, expected = serial
    records: list = []
    got = _phases(problem, state, 2, records)
    _same(got, expected)  # state, summaries, certificate: every field, every bit
    # No member certified twice, none dropped: each summary made once, by the polish (its
    # moves) or by a certificate task (the others), and the front's are among them.
    _, made, front, summaries, _, _ = got
    certified = [key for kind, keys in records if kind == "certify" for key in keys]
    assert len(certified) == len(set(certified))
    assert not set(certified) & set(made)
    for row, summary in zip(front.x, summaries):
        if summary is not None:
            assert (row.tobytes() in made) != (row.tobytes() in certified)
    assert sum(kind == "exact" for kind, _ in records) == 1


@pytest.mark.slow  # three polishes: ~3 s
def test_a_step_started_early_and_not_run_is_discarded(
    problem, population, monkeypatch, run_state
) -> None:
    """Every step started as soon as a process is free (as if each solve spent nothing);
    the budget lets the fastest member's solve and one step run: the second step's result
    is dropped and the state is the serial one."""
    monkeypatch.setattr(post_search, "_LIKELY", 0)
    probe = run_state(problem, population, _budget(10_000))
    chosen = post_search._polish_plan(problem, probe, "front", PAPER_WEIGHTS)
    assert len(chosen.members) >= 2
    with post_search.PostSearch(problem, RATE, 1, False) as post:
        post.polish(probe, "front", PAPER_WEIGHTS)
        used = post._used(chosen)
    budget = used[0] + used[1] + 19  # one step fits, not two
    state = run_state(problem, population, _budget(budget))
    expected = _polish_run(problem, state, RATE, "front", PAPER_WEIGHTS)
    started: list = []
    got = _phases(problem, state, 2, started=started)
    assert ("solve", 1) in started  # the second step was started
    _same(got[:2], expected)
    assert len(got[0].X) <= len(state.X) + 2
    assert got[0].n_evaluations == state.n_evaluations + used[0] + used[1]


def test_an_error_of_a_forked_solve_is_raised_with_its_traceback(
    problem, population, run_state
) -> None:
    state = run_state(problem, population, _budget(ONE_STEP))
    x = np.array(state.X, dtype=float)
    fastest = int(np.argmin(x[:, 0]))
    x[fastest, 1] = problem.xu[1] + 1.0  # refused by minimum_time, in the forked process
    broken = dataclasses.replace(state, X=x)
    with pytest.raises(ConfigurationError, match="decision bounds") as info:
        _phases(problem, broken, 2)
    notes = "\n".join(info.value.__notes__)
    assert "raised by the polish's solve 'fastest' in a forked process" in notes
    assert "minimum_time" in notes  # the forked process' traceback


def _fail(problem: TrajectoryProblem, value: float) -> None:
    raise InvalidInputError(f"bad value {value}")


def _sleep(problem: TrajectoryProblem, seconds: float) -> float:
    time.sleep(seconds)
    return seconds


def test_problem_tasks(problem) -> None:
    with ProblemTasks(problem, 1) as inline:  # in this process, in order, when waited for
        first = inline.submit(_sleep, 0.0)
        inline.submit(_fail, 2.0, name="the fail")
        assert inline.wait() == (first, 0.0)
        with pytest.raises(InvalidInputError, match=r"bad value 2\.0"):
            inline.wait()
        with pytest.raises(ConfigurationError, match="no task"):
            inline.wait()
    started = time.perf_counter()
    with ProblemTasks(problem, 2) as forked:
        forked.submit(_sleep, 60.0)  # still running when the block ends: stopped at once
        ticket = forked.submit(_fail, 3.0, name="the failing task")
        with pytest.raises(InvalidInputError, match=r"bad value 3\.0") as info:
            forked.wait()
        assert "raised by the failing task in a forked process" in info.value.__notes__[0]
        assert ticket == 1
    assert time.perf_counter() - started < 10.0
    with pytest.raises(ConfigurationError, match="processes"):
        ProblemTasks(problem, 0)


def _interrupted(tasks: ProblemTasks, processes: list) -> None:
    """Start two long tasks, then Ctrl-C (a KeyboardInterrupt while waiting); the forked
    processes are appended to ``processes``."""
    tasks.submit(_sleep, 60.0)
    tasks.submit(_sleep, 60.0)
    processes.extend(tasks._pool._pool)
    raise KeyboardInterrupt


def test_ctrl_c_stops_the_forked_processes(problem) -> None:
    started = time.perf_counter()
    forked, processes = ProblemTasks(problem, 2), []
    with pytest.raises(KeyboardInterrupt), forked:
        _interrupted(forked, processes)
    assert len(processes) == 2
    assert not any(p.is_alive() for p in processes)
    assert time.perf_counter() - started < 10.0


def test_bad_input_is_refused_before_any_work(problem) -> None:
    with pytest.raises(InvalidInputError, match="rate_hz"):
        post_search.PostSearch(problem, 0.0, 2, True)
    with pytest.raises(InvalidInputError, match="problem"):
        post_search.PostSearch(None, RATE, 2, True)
    x = np.zeros((3, problem.n_var))
    with post_search.PostSearch(problem, RATE, 2, True) as post:
        with pytest.raises(InputShapeError, match="permutation"):
            post.certificates(x, np.ones(3, bool), np.array([0, 1, 1]), None)
        with pytest.raises(InputShapeError, match="shape"):
            post.certificates(x[:, :4], np.ones(3, bool), np.arange(3), None)
        assert post._tasks._pool is None  # nothing forked
