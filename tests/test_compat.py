"""A result folder written before the subpackage layout (commit 2ec18c4, flat modules) loads
and re-verifies after it: the on-disk format did not change."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

import adept_traj as at
from adept_traj.cli import main

OLD = Path(__file__).parent / "data" / "result_v1"


def test_result_saved_by_the_flat_layout_loads():
    raw = json.loads((OLD / "result.json").read_text(encoding="utf-8"))
    result = at.PlanningResult.load(OLD)
    assert result.algorithm == raw["algorithm"]["name"] == "nsga2"
    np.testing.assert_array_equal(result.front.x, [m["x"] for m in raw["front"]])
    np.testing.assert_array_equal(result.best_objectives, raw["best"]["objectives"])
    assert result.feasible is False  # the tiny run (pop 12, 3 generations) hits cube 1


def test_result_saved_by_the_flat_layout_reverifies(capsys):
    assert main(["verify", str(OLD)]) == 1  # not feasible, as stored
    out = capsys.readouterr().out
    assert "distance: -0.01492 m < margin 0.01 m at t = 0.684 s (link4/gripper – cube1)" in out


def test_result_saved_by_the_flat_layout_is_written_back_unchanged(tmp_path):
    """Load and save reproduce the three files: the CSVs byte for byte, result.json as the
    same JSON data (versions included: they record the run, not the reader)."""
    at.PlanningResult.load(OLD).save(tmp_path)
    for name in ("front.csv", "best_trajectory.csv"):
        assert (tmp_path / name).read_bytes() == (OLD / name).read_bytes(), name
    old = json.loads((OLD / "result.json").read_text(encoding="utf-8"))
    new = json.loads((tmp_path / "result.json").read_text(encoding="utf-8"))
    assert new == old
