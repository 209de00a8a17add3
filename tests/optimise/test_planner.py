"""plan(): seeded fronts, verified best trade-off, never-empty results, metrics."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import adept_traj as at
from adept_traj.certification import certify
from adept_traj.optimise import planner
from adept_traj.results import NO_FEASIBLE_WARNING


@pytest.fixture(scope="module")
def small_run(problem: at.TrajectoryProblem) -> at.PlanningResult:
    return at.plan(problem, "nsga2", seed=2, pop_size=40, n_gen=25, polish=False)


def test_same_seed_same_front(problem: at.TrajectoryProblem, small_run) -> None:
    again = at.plan(problem, "nsga2", seed=2, pop_size=40, n_gen=25, polish=False)
    np.testing.assert_array_equal(again.front.x, small_run.front.x)
    np.testing.assert_array_equal(again.front.objectives, small_run.front.objectives)
    assert again.best.index == small_run.best.index


def test_result_is_verified_and_consistent(problem: at.TrajectoryProblem, small_run) -> None:
    res = small_run
    assert len(res.front) >= 1
    assert res.certificate.rate_hz >= 1000
    np.testing.assert_array_equal(res.certificate.x, res.front.x[res.best.index])
    # The certificate is the dense check of the chosen solution, as certify() makes it.
    assert at.certify(problem, res.best_x) == res.certificate
    assert res.timing.n_evaluations == 40 * 25
    assert 0 < res.timing.evaluation_s <= res.timing.total_s
    assert res.metrics.oo == pytest.approx(
        (res.timing.total_s - res.timing.evaluation_s) / res.timing.total_s
    )
    assert res.metrics.ae == pytest.approx(res.timing.total_s / res.timing.n_evaluations)
    assert 0 < res.metrics.rni <= 1
    assert res.gap == pytest.approx(res.best_objectives[0] / problem.lower_bound.T_min)
    assert res.best_objectives[0] >= problem.lower_bound.T_min
    # seed 2 with 40 x 25 finds feasible members, and the trade-off choice passes
    assert res.warning is None
    assert res.feasible
    assert res.front.feasible.all()
    # Front members do not dominate each other.
    assert at.analysis.non_dominated(res.front.objectives).all()


def test_least_infeasible_front_with_warning(problem: at.TrajectoryProblem, monkeypatch) -> None:
    certified = []

    def counting(problem, x, **kwargs):
        certified.append(x)
        return certify(problem, x, **kwargs)

    monkeypatch.setattr(planner, "certify", counting)
    # MODE with 12 x 2 finds no feasible member (seed 1); without the polish (whose global
    # stage finds one, below) the front is the least infeasible
    res = at.plan(problem, "mode", seed=1, pop_size=12, n_gen=2, polish=False)
    assert len(res.front) == 10  # never empty: the 10 least infeasible
    assert not res.front.feasible.any()
    assert res.warning == NO_FEASIBLE_WARNING
    assert not res.feasible
    # only the trade-off choice is certified: no other member is feasible at the samples
    assert len(certified) == 1
    np.testing.assert_array_equal(certified[0], res.best_x)


def test_the_global_stage_finds_a_move_the_search_did_not(problem: at.TrajectoryProblem) -> None:
    """The same search with the polish: no member of the search is feasible, the global
    stage's refinement is certified (issue #24), at the kinematic bound to 1 %."""
    res = at.plan(problem, "mode", seed=1, pop_size=12, n_gen=2)
    assert res.feasible
    assert res.warning is None
    fastest = res.front.x[res.front.feasible, 0].min()
    assert fastest <= 1.01 * problem.lower_bound.T_min
    assert certify(problem, res.front.x[np.argmin(res.front.x[:, 0])]).certified


@pytest.mark.parametrize(
    ("passes", "max_certify", "expected_tries", "certified", "reported"),
    [
        ({3}, None, [2, 1, 3], [3], 3),  # 0 is infeasible at the samples: not tried
        ({3}, 2, [2, 1], [], 2),  # out of tries: nothing certified, the trade-off choice
        ({2, 3}, None, [2, 1, 3], [2, 3], 2),  # the trade-off choice passes
        (set(), None, [2, 1, 3], [], 2),  # none passes
    ],
)
def test_every_feasible_member_is_certified(
    monkeypatch, passes, max_certify, expected_tries, certified, reported
) -> None:
    tried = []

    def fake_members(problem, x, members, rate_hz):
        out = [None] * len(x)
        for k in members:
            tried.append(k)
            out[k] = SimpleNamespace(feasible=k in passes)
        return tuple(out)

    def fake_certify(problem, x, rate_hz):
        return SimpleNamespace(index=int(x[0]))

    monkeypatch.setattr(planner, "certify_front_members", fake_members)
    monkeypatch.setattr(planner, "certify", fake_certify)
    front = SimpleNamespace(x=np.arange(4.0)[:, None], feasible=np.array([False, True, True, True]))
    order = np.array([2, 0, 1, 3])
    summaries = planner._certify_front(None, front, order, 1000.0, max_certify)
    mask = np.array([s is not None and s.feasible for s in summaries])
    assert tried == expected_tries
    np.testing.assert_array_equal(np.flatnonzero(mask), certified)
    front = SimpleNamespace(x=front.x, feasible=mask)
    certificate, index = planner._certified_choice(None, front, order, 1000.0)
    assert (index, certificate.index) == (reported, reported)


@pytest.mark.slow  # 10 kHz re-check of every member: ~7 s (slow tier, run by .ci/run)
def test_front_feasible_means_certified(problem: at.TrajectoryProblem, small_run) -> None:
    """Every member marked feasible passes an independent dense re-check at 10 kHz (the
    uniform grid only, no continuous bound); the count is stored in the front."""
    front = small_run.front
    assert front.n_certified == int(front.feasible.sum()) > 0
    for k in np.flatnonzero(front.feasible):
        dense = certify(problem, front.x[k], rate_hz=10_000.0, continuous=False, exact=False)
        assert dense.feasible
    assert small_run.certificate.certified


def test_save_load_verify_round_trip(small_run, tmp_path: Path) -> None:
    small_run.save(tmp_path)
    loaded = at.PlanningResult.load(tmp_path)
    assert loaded == small_run


def test_bad_seed(problem: at.TrajectoryProblem) -> None:
    with pytest.raises(at.ConfigurationError, match="seed"):
        at.plan(problem, seed=-1, pop_size=4, n_gen=1)


@pytest.mark.slow  # ≈ 3 s (the default tier measured 192 s after the merges)
def test_search_buffer_recorded_and_certificate_keeps_margin(
    problem: at.TrajectoryProblem, tmp_path: Path
) -> None:
    """The buffer tightens the search only: the result records it (and reloads it), the
    certificates check the true margin, and it is part of the checkpoint fingerprint."""
    buffered = at.TrajectoryProblem(
        problem.robot, problem.scene, problem.start, problem.goal, search_buffer=0.003
    )
    res = at.plan(buffered, "nsga2", seed=3, pop_size=20, n_gen=4)
    assert res.problem_settings.search_buffer == 0.003
    assert res.certificate.margin == problem.settings.margin == 0.01
    res.save(tmp_path)
    assert at.PlanningResult.load(tmp_path).problem_settings.search_buffer == 0.003
    settings = SimpleNamespace(to_dict=dict)
    with_buffer = planner._fingerprint(buffered, settings, 3)["problem_settings"]
    assert with_buffer["search_buffer"] == 0.003
    # A zero buffer is left out: checkpoints written before the field keep resuming.
    unbuffered = at.TrajectoryProblem(
        problem.robot, problem.scene, problem.start, problem.goal, search_buffer=0.0
    )
    assert "search_buffer" not in planner._fingerprint(unbuffered, settings, 3)["problem_settings"]
