"""The slow tier (``python -m pytest -m slow -n 0``, run by ``.ci/run`` after the default tier):
the README's main job as a user types it, and the paper's comparison, at full budget.

Every figure checked here is recomputed from the result folder with plain numpy and JSON,
not taken from the library's own summary.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.slow

#: The kinematic lower bound of the paper move's travel time [s] (docs/trajectory.md).
T_LOWER_BOUND = 1.0728


def _adept_traj(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, "-c", "import sys; from adept_traj.cli import main; sys.exit(main())"]
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    return subprocess.run(
        [*cmd, *args], cwd=cwd, capture_output=True, text=True, timeout=1800, env=env
    )


def test_readme_main_job_writes_a_certified_result(tmp_path: Path):
    proc = _adept_traj("plan", "--out", "out", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = tmp_path / "out"
    for name in ("result.json", "front.csv", "best_trajectory.csv", "playback.html"):
        assert (out / name).is_file(), name
    assert sorted(p.name for p in (out / "figures").glob("*.png")) == [
        "best_tradeoffs.png",
        "hypervolume_history.png",
        "joint_motion_nsga2.png",
        "pareto_matrix.png",
        "tool_path_nsga2.png",
    ]
    result = json.loads((out / "result.json").read_text(encoding="utf-8"))
    assert result["algorithm"]["name"] == "nsga2"
    assert result["certificate"]["feasible"] is True
    # The paper's budget: population 100, 100 generations.
    assert result["timing"]["n_evaluations"] >= 100 * 100
    best = result["front"][result["best"]["index"]]
    T = best["x"][0]
    assert best["objectives"][0] == pytest.approx(T)
    # The best trade-off (minimum f_c, not the fastest move) obeys the kinematic lower bound,
    # and the reported gap is its T over that bound.
    T_min = result["lower_bound"]["T_min"]
    assert T_min == pytest.approx(T_LOWER_BOUND, abs=1e-4)
    assert T_min <= T
    assert result["gap"] == pytest.approx(T / T_min, rel=1e-12)
    # The certified trajectory in the CSV starts and ends at rest at the scene's start/goal.
    table = np.loadtxt(out / "best_trajectory.csv", delimiter=",", skiprows=1)
    assert table[-1, 0] == pytest.approx(T)
    np.testing.assert_allclose(table[0, 1:5], result["start"], atol=1e-12)
    np.testing.assert_allclose(table[-1, 1:5], result["goal"], atol=1e-9)
    # verify re-certifies the saved result from the folder alone.
    proc = _adept_traj("verify", "out", cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "re-verified at 1000 Hz" in proc.stdout
    assert ": FEASIBLE; min distance" in proc.stdout  # "NOT FEASIBLE" does not match this


def test_paper_comparison_at_full_budget(tmp_path: Path):
    proc = _adept_traj("compare", "--out", "cmp", "--no-plots", "--quiet", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    budgets = {"nsga2": 100 * 100, "mode": 500 * 100}  # the paper's populations × generations
    for name, budget in budgets.items():
        result = json.loads((tmp_path / "cmp" / name / "result.json").read_text("utf-8"))
        assert result["algorithm"]["name"] == name
        assert result["timing"]["n_evaluations"] >= budget
        assert result["certificate"]["feasible"] is True, name
        T = result["front"][result["best"]["index"]]["x"][0]
        assert result["lower_bound"]["T_min"] <= T, (name, T)
    table = (tmp_path / "cmp" / "comparison.md").read_text(encoding="utf-8")
    assert "NSGA-II" in table
    assert "MODE" in table
