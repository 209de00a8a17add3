"""plan(): seeded fronts, verified best trade-off, never-empty results, metrics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import adept_traj as at
from adept_traj.results import NO_FEASIBLE_WARNING


@pytest.fixture(scope="module")
def small_run(problem: at.TrajectoryProblem) -> at.PlanningResult:
    return at.plan(problem, "nsga2", seed=2, pop_size=40, n_gen=25)


def test_same_seed_same_front(problem: at.TrajectoryProblem, small_run) -> None:
    again = at.plan(problem, "nsga2", seed=2, pop_size=40, n_gen=25)
    np.testing.assert_array_equal(again.front.x, small_run.front.x)
    np.testing.assert_array_equal(again.front.objectives, small_run.front.objectives)
    assert again.best.index == small_run.best.index


def test_result_is_verified_and_consistent(problem: at.TrajectoryProblem, small_run) -> None:
    res = small_run
    assert len(res.front) >= 1
    assert res.certificate.rate_hz >= 1000
    np.testing.assert_array_equal(res.certificate.x, res.front.x[res.best.index])
    # The certificate is an independent dense check of the chosen solution.
    again = at.certify(problem, res.best_x)
    assert again.feasible == res.feasible
    assert res.timing.n_evaluations == 40 * 25
    assert 0 < res.timing.evaluation_s <= res.timing.total_s
    assert res.metrics.oo == pytest.approx(
        (res.timing.total_s - res.timing.evaluation_s) / res.timing.total_s
    )
    assert res.metrics.ae == pytest.approx(res.timing.total_s / res.timing.n_evaluations)
    assert 0 < res.metrics.rni <= 1
    assert res.gap == pytest.approx(res.best_objectives[0] / problem.lower_bound.T_min)
    assert res.best_objectives[0] >= problem.lower_bound.T_min
    if res.warning is None:
        assert res.front.feasible.all()
        # Front members do not dominate each other.
        assert at.analysis.non_dominated(res.front.objectives).all()


def test_least_infeasible_front_with_warning(problem: at.TrajectoryProblem) -> None:
    res = at.plan(problem, "mode", seed=1, pop_size=12, n_gen=2)
    assert len(res.front) >= 1  # never empty
    if not res.front.feasible.any():
        assert res.warning == NO_FEASIBLE_WARNING
        assert not res.feasible


def test_save_load_verify_round_trip(small_run, tmp_path: Path) -> None:
    small_run.save(tmp_path)
    loaded = at.PlanningResult.load(tmp_path)
    assert loaded == small_run


def test_bad_seed(problem: at.TrajectoryProblem) -> None:
    with pytest.raises(at.ConfigurationError, match="seed"):
        at.plan(problem, seed=-1, pop_size=4, n_gen=1)
