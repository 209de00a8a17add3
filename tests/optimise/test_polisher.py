"""start_polisher: the polish run by a helper process forked before the search gives the
population and certificates of the polish in the caller (polish_run called directly);
a helper that is not ready or is killed leaves the polish to the caller; its error is
raised in the caller; no helper outlives its block."""

from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path

import numpy as np
import pytest

import adept_traj.optimise as optimise_package  # cli.plan runs its plan (imported on use)
import adept_traj.optimise.parallel.early_certificates as early_module
import adept_traj.optimise.parallel.polish_worker as polisher_module
from adept_traj import Robot, Scene, TrajectoryProblem, plan
from adept_traj.analysis import PAPER_WEIGHTS
from adept_traj.certification import certify_members
from adept_traj.cli.app import main
from adept_traj.errors import ConfigurationError, FrozenObjectError, InvalidInputError
from adept_traj.optimise import (
    feasible_front,
    make_algorithm,
    optimise,
    polish_run,
    polish_with_certificates,
    start_early_certificates,
    start_polisher,
)
from adept_traj.process_pool import children
from adept_traj.results import PlanningResult

RATE = 400.0
DATA = Path(__file__).parents[1] / "data"


@pytest.fixture(scope="module")
def searched(problem: TrajectoryProblem):
    """A small NSGA-II search's final population (no polish yet)."""
    alg, settings = make_algorithm("nsga2", 16, 4)
    return optimise(problem, alg, settings.n_gen, 1)


@pytest.fixture(scope="module")
def serial(problem: TrajectoryProblem, searched):
    """The polish of the fastest member in this process, and its certificate."""
    state = polish_run(problem, searched, RATE, "fastest", PAPER_WEIGHTS)
    new = state.X[len(searched.X) :]
    assert len(new) >= 1  # the polish kept a move: the test compares something
    ok = np.flatnonzero(np.all(searched.G <= 0.0, axis=1))
    start = ok[np.argmin(searched.X[ok, 0])]  # the local solver's first start (a member)
    rows = [*range(len(searched.X), len(state.X)), int(start)]
    summaries = certify_members(problem, state.X, rows, rate_hz=RATE)
    return state, {k: summaries[k] for k in rows}  # by population row


def _same(state, certified, serial) -> None:
    expected_state, expected_certified = serial
    for name in ("X", "F", "G", "CV"):
        np.testing.assert_array_equal(getattr(state, name), getattr(expected_state, name))
    assert state.n_evaluations == expected_state.n_evaluations
    assert state.history == expected_state.history
    assert certified == expected_certified  # every field of every summary, exactly


def _polish(problem, searched, polisher):
    with start_early_certificates(problem, searched.X, [], rate_hz=RATE) as early:
        return polish_with_certificates(
            problem, searched, RATE, "fastest", PAPER_WEIGHTS, early=early, polisher=polisher
        )


def test_the_helper_polishes_as_the_caller(problem, searched, serial, process_gone) -> None:
    with start_polisher(problem) as polisher:
        pid = polisher.pid
        assert polisher.ready(60.0)
        state, certified = _polish(problem, searched, polisher)
        assert polisher.pid is None  # reaped once its polish is collected
    _same(state, certified, serial)
    assert process_gone(pid)


def test_a_helper_not_ready_leaves_the_polish_to_the_caller(problem, searched, serial) -> None:
    polisher = start_polisher(problem)
    polisher.cancel()  # stopped: never ready
    assert not polisher.start(searched, RATE, "fastest", PAPER_WEIGHTS)
    _same(*_polish(problem, searched, polisher), serial)


def test_a_helper_still_preparing_is_killed_without_waiting_for_its_end(
    problem, searched, serial, monkeypatch, process_gone
) -> None:
    """Its preparing thread at nice 19 may wait long for a core on a busy machine: the
    caller kills the helper and polishes at once, the helper is reaped at the block's end."""
    monkeypatch.setattr(polisher_module, "_prepare", lambda _problem: time.sleep(60.0))
    with start_polisher(problem) as polisher:
        pid = polisher.pid
        assert not polisher.start(searched, RATE, "fastest", PAPER_WEIGHTS)
        assert polisher.pid == pid  # not waited for
        assert not polisher.ready()
        _same(*_polish(problem, searched, polisher), serial)
    assert polisher.pid is None
    assert process_gone(pid)


def test_a_killed_helper_leaves_the_polish_to_the_caller(
    problem, searched, serial, monkeypatch, child_fault
) -> None:
    faulty = child_fault(polisher_module.polish_run_with_certificates, "killed")
    monkeypatch.setattr(polisher_module, "polish_run_with_certificates", faulty)
    with start_polisher(problem) as polisher:
        assert polisher.ready(60.0)
        _same(*_polish(problem, searched, polisher), serial)


def test_an_error_of_the_helper_is_raised_in_the_caller_with_its_traceback(
    problem,
    searched,
    monkeypatch,
    process_gone,
) -> None:
    def fails(*args, **kwargs):
        raise RuntimeError(f"polish broken in {os.getpid()}")

    monkeypatch.setattr(polisher_module, "polish_run_with_certificates", fails)
    with start_polisher(problem) as polisher:
        pid = polisher.pid
        assert polisher.ready(60.0)
        with pytest.raises(RuntimeError, match=f"broken in {pid}") as caught:
            _polish(problem, searched, polisher)
    (note,) = caught.value.__notes__
    assert note.startswith("raised while polishing in the polisher's worker process:")
    assert "in fails" in note  # the helper's traceback
    assert process_gone(pid)


def test_a_polisher_of_another_problem_is_refused_before_the_search(problem, searched) -> None:
    scene = Scene.paper()
    other = TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)
    with start_polisher(other) as polisher:
        with pytest.raises(ConfigurationError, match="another problem"):
            _polish(problem, searched, polisher)
        with pytest.raises(ConfigurationError, match="another problem"):
            plan(problem, "nsga2", pop_size=10**9, polisher=polisher)  # no search starts
    with pytest.raises(InvalidInputError, match="polisher"):
        plan(problem, "nsga2", pop_size=10**9, polisher="helper")


def test_a_used_polisher_leaves_the_next_polish_to_the_caller(problem, searched, serial) -> None:
    """A helper serves one search: handed a second one, the caller polishes it (it raised
    AttributeError after the search before)."""
    with start_polisher(problem) as polisher:
        assert polisher.ready(60.0)
        _same(*_polish(problem, searched, polisher), serial)
        assert not polisher.ready()
        _same(*_polish(problem, searched, polisher), serial)


def test_a_polisher_of_a_problem_changed_since_is_refused(searched) -> None:
    """Its helper would polish and certify the problem as it was when it was forked (e.g.
    the old margin). The problem is frozen (issue #27): a change is a copy, another problem,
    refused before the search."""
    scene = Scene.paper()
    original = TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)
    with start_polisher(original) as polisher:
        with pytest.raises(FrozenObjectError):
            original.settings = dataclasses.replace(original.settings, margin=0.02)
        changed = original.replace(margin=0.02)
        with pytest.raises(ConfigurationError, match="started for another problem"):
            _polish(changed, searched, polisher)
        with pytest.raises(ConfigurationError, match="started for another problem"):
            plan(changed, "nsga2", pop_size=10**9, polisher=polisher)  # no search starts


def test_a_failing_certificate_of_a_member_still_on_the_front_is_raised(
    problem, searched, monkeypatch
) -> None:
    """The early certificates keep a failure until the polish says which members stay on
    the front: one that stays is raised (not swallowed)."""
    rows = feasible_front(searched.F, searched.G, PAPER_WEIGHTS)
    stays = int(rows[-1])  # the polish of the fastest member leaves the others on the front
    real = early_module.certify_members

    def fails(problem, x, members, **kwargs):
        if stays in list(members):
            raise RuntimeError("this member cannot be certified")
        return real(problem, x, members, **kwargs)

    monkeypatch.setattr(early_module, "certify_members", fails)
    with (
        start_polisher(problem) as polisher,
        start_early_certificates(problem, searched.X, rows, rate_hz=RATE, fork=False) as early,
    ):
        assert polisher.ready(60.0)
        with pytest.raises(RuntimeError, match="cannot be certified"):
            polish_with_certificates(
                problem, searched, RATE, "fastest", PAPER_WEIGHTS, early=early, polisher=polisher
            )


def test_plan_with_a_polisher_and_two_workers_gives_the_serial_result(problem) -> None:
    """The polisher and the early certificates (workers > 1) change nothing in the result:
    the same as one worker without a helper."""
    kwargs = {"seed": 1, "pop_size": 16, "n_gen": 4, "polish": "front"}
    alone = plan(problem, "nsga2", **kwargs)
    scene = Scene.paper()
    with (
        TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal, workers=2) as two,
        start_polisher(two) as polisher,
    ):
        assert polisher.ready(60.0)  # its imports done: plan hands it the polish
        helped = plan(two, "nsga2", polisher=polisher, **kwargs)
    assert helped.metrics.t_best_source == "polish"  # the polish kept a move
    np.testing.assert_array_equal(helped.front.x, alone.front.x)
    np.testing.assert_array_equal(helped.front.objectives, alone.front.objectives)
    assert helped.front.certificates == alone.front.certificates
    assert helped.certificate.min_distance == alone.certificate.min_distance
    assert helped.timing.n_evaluations == alone.timing.n_evaluations
    assert helped.metrics.ssm == alone.metrics.ssm


@pytest.mark.parametrize("end", ["done", "error", "ctrl-c"])
def test_adept_traj_plan_leaves_no_helper_behind(
    end: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    process_gone,
) -> None:
    """The command starts the polisher before the search and reaps it however it ends."""
    stored = PlanningResult.load(DATA / "result_v1")
    seen = []

    def fake_plan(*_args, polisher=None, **_kwargs):
        seen.append(polisher.pid)
        if end == "error":
            raise RuntimeError("stop")
        if end == "ctrl-c":
            raise KeyboardInterrupt
        return stored

    monkeypatch.setattr(optimise_package, "plan", fake_plan)
    argv = ["plan", "--workers", "1", "--quiet", "--no-plots", "--no-html"]
    argv += ["--out", str(tmp_path / "run")]
    if end == "error":
        with pytest.raises(RuntimeError, match="stop"):
            main(argv)
    else:
        # the stored result's best is not certified: exit 1 when the run completes
        assert not stored.feasible
        assert main(argv) == (1 if end == "done" else 130)
    assert seen[0] is not None
    assert process_gone(seen[0])
    assert children() == []


def test_no_polisher_without_a_polish(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    stored = PlanningResult.load(DATA / "result_v1")
    seen = []
    monkeypatch.setattr(
        optimise_package, "plan", lambda *a, polisher=None, **k: seen.append(polisher) or stored
    )
    argv = ["plan", "--workers", "1", "--quiet", "--no-plots", "--no-html", "--no-polish"]
    assert main([*argv, "--out", str(tmp_path / "run")]) == 1  # (its best: not certified)
    assert seen == [None]
