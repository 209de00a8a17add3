"""The planning commands evaluate on every core available by default, with the same result
as one worker, and record the number they used."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pytest

import adept_traj.cli.arguments as arguments
from adept_traj.cli import main
from adept_traj.problem import available_cores
from adept_traj.results import PlanningResult


def test_available_cores_is_the_affinity_mask() -> None:
    assert available_cores() == len(os.sched_getaffinity(0))


def _front(folder: Path) -> tuple[np.ndarray, int]:
    result = PlanningResult.load(folder)
    workers = json.loads((folder / "result.json").read_text())["problem_settings"]["workers"]
    assert result.problem_settings.workers == workers
    return np.hstack([result.front.x, result.front.objectives]), workers


@pytest.mark.slow  # ~3.5 s: the default tier's budget
def test_plan_defaults_to_the_available_cores_with_the_serial_front(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """No --workers: as many workers as available_cores() says (2 here, whatever the
    machine), recorded in result.json and the summary; the front equals --workers 1's."""
    monkeypatch.setattr(arguments, "available_cores", lambda: 2)
    argv = ["plan", "--pop", "16", "--gens", "2", "--no-html", "--no-plots"]
    assert main([*argv, "--out", str(tmp_path / "default")]) == 0
    assert "evaluating, 2 workers)" in capsys.readouterr().out
    assert main([*argv, "--workers", "1", "--quiet", "--out", str(tmp_path / "one")]) == 0
    default, n_default = _front(tmp_path / "default")
    serial, n_serial = _front(tmp_path / "one")
    assert (n_default, n_serial) == (2, 1)
    np.testing.assert_array_equal(default, serial)
