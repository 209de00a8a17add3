"""T_best (``metrics.t_best``): the best travel time the local solver reached in a run,
recorded, printed beside the kinematic gap, saved, read back and audited (issue #12)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from adept_traj import TrajectoryProblem, plan
from adept_traj.certification.audit import audit
from adept_traj.cli.front import front_table
from adept_traj.cli.report import summary
from adept_traj.errors import InvalidInputError
from adept_traj.optimise import refine_minimum_time
from adept_traj.results import Metrics, PlanningResult

OLD = Path(__file__).parents[1] / "data" / "result_v1"


@pytest.fixture(scope="module")
def runs(problem: TrajectoryProblem) -> dict[str, PlanningResult]:
    """A small NSGA-II run without and with the polish of its fastest member (seed 1),
    and the time-optimal mode from one start."""
    options = {"seed": 1, "pop_size": 16, "n_gen": 4}
    return {
        "off": plan(problem, "nsga2", polish=False, **options),
        "fastest": plan(problem, "nsga2", polish="fastest", **options),
        "time-optimal": plan(problem, "time-optimal", seed=1, n_starts=1),
    }


def test_polished_run_records_the_polished_fastest_move(problem, runs) -> None:
    """T_best is the T of the certified refinement of the unpolished run's fastest feasible
    member (called directly), and the run's fastest certified member."""
    raw, polished = runs["off"], runs["fastest"]
    ok = np.flatnonzero(np.all(raw.front.constraints <= 0.0, axis=1))
    start = raw.front.x[ok[np.argmin(raw.front.x[ok, 0])]]
    expected = refine_minimum_time(problem, start)
    assert polished.metrics.t_best == expected.x[0]
    assert polished.metrics.t_best_source == "polish"
    assert polished.metrics.t_best == polished.front.x[polished.front.feasible, 0].min()
    assert polished.gap_best == polished.best_objectives[0] / expected.x[0]
    assert raw.metrics.t_best is None
    assert raw.metrics.t_best_source is None
    assert raw.gap_best is None


def test_time_optimal_mode_records_its_best_certified_move(runs) -> None:
    r = runs["time-optimal"]
    assert r.metrics.t_best_source == "time-optimal"
    assert r.metrics.t_best == pytest.approx(1.0765924346, abs=1e-7)  # issue #24: 4e-8 s above
    assert r.gap_best == r.best_objectives[0] / r.metrics.t_best


def test_summary_and_front_print_both_gaps(runs) -> None:
    r = runs["fastest"]
    text = summary(r, Path("out"))
    t_lb = r.lower_bound.T_min
    assert f"T = {r.best_objectives[0] / t_lb:.2f} × T_lb" in text
    assert f"T = {r.gap_best:.3f} × T_best ({r.metrics.t_best:.4f} s by polish)" in text
    # every objective with its unit (issue #29), z3 dimensionless
    z = r.best_objectives
    assert f"z2 = {z[1]:.4g} N²·m²·s, z3 = {z[2]:.4g}, z4 = {z[3]:.4g} m²" in text
    assert f"z5 = {z[4]:.4g} rad²/s⁵, z6 = {z[5]:.4g} rad²/s³" in text
    assert "T_best not computed" in summary(runs["off"], Path("out"))
    assert "T_best not computed" in summary(PlanningResult.load(OLD), Path("out"))
    lines = front_table(r).splitlines()
    header = lines[0].split()
    assert header[-4:] == ["T/T_lb", "[-]", "T/T_best", "[-]"]
    fastest = int(np.argmin(r.front.x[:, 0]))
    row = lines[1 + fastest].split()
    assert float(row[-1]) == pytest.approx(1.0, abs=1e-6)
    assert float(row[-2]) == pytest.approx(r.front.x[fastest, 0] / t_lb, rel=1e-5)
    assert front_table(runs["off"]).splitlines()[1].split()[-1] == "-"


def test_t_best_is_saved_read_back_and_audited(runs, tmp_path: Path) -> None:
    r = runs["fastest"]
    loaded = PlanningResult.load(r.save(tmp_path / "run"))
    assert loaded.metrics.t_best == r.metrics.t_best
    assert loaded.metrics.t_best_source == "polish"
    assert PlanningResult.load(OLD).metrics.t_best is None  # absent in old files
    assert audit(loaded).ok
    slower = dataclasses.replace(r.metrics, t_best=1.01 * r.metrics.t_best)
    found = audit(dataclasses.replace(loaded, metrics=slower))
    assert [m.field for m in found.mismatches] == ["metrics.T_best"]
    wrong = dataclasses.replace(r.metrics, t_best_source="time-optimal")
    found = audit(dataclasses.replace(loaded, metrics=wrong))
    assert [m.field for m in found.mismatches] == ["metrics.T_best_source"]


@pytest.mark.parametrize(
    "fields",
    [{"t_best": 1.1}, {"t_best_source": "polish"}, {"t_best": 1.1, "t_best_source": "guess"}],
)
def test_metrics_refuse_a_t_best_without_its_source(fields) -> None:
    with pytest.raises(InvalidInputError, match="t_best_source"):
        Metrics(**fields)
