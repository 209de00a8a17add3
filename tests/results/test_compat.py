"""A result folder written before the subpackage layout (commit 2ec18c4, flat modules) loads
and re-verifies after it: the on-disk format did not change (but best_trajectory.csv, which
issue #29 moved to a fixed step: the old file still loads)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

import adept_traj as at
from adept_traj.cli import main
from adept_traj.export import export_member

OLD = Path(__file__).parents[1] / "data" / "result_v1"


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
    """Load and save reproduce front.csv byte for byte and result.json as the same JSON data
    (versions included: they record the run, not the reader); best_trajectory.csv, on the
    certificate's grid before issue #29, is written as the fixed-step file of adept-traj
    export (and the folder loads again)."""
    result = at.PlanningResult.load(OLD)
    result.save(tmp_path)
    assert (tmp_path / "front.csv").read_bytes() == (OLD / "front.csv").read_bytes()
    assert (OLD / "best_trajectory.csv").read_text().startswith("t,q_joint1,")
    new_csv = (tmp_path / "best_trajectory.csv").read_bytes()
    exported = export_member(result, tmp_path / "e.csv", allow_uncertified=True).read_bytes()
    assert new_csv == exported
    assert new_csv.startswith(b"t [s],q_joint1 [rad],")
    assert at.PlanningResult.load(tmp_path) == result
    old = json.loads((OLD / "result.json").read_text(encoding="utf-8"))
    new = json.loads((tmp_path / "result.json").read_text(encoding="utf-8"))
    assert new == old
