"""Every script in examples/ runs (small budgets) and prints what it promises."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize(
    ("script", "args", "expect"),
    [
        ("robot_dynamics.py", [], "kinematic lower bound on T: 1.073 s"),
        pytest.param(
            "plan_paper.py",
            ["--gens", "2", "--small"],
            "mode: 42 evaluations",
            marks=pytest.mark.slow,  # ~3.5 s: the default tier's budget
        ),
        pytest.param(
            "custom_scene.py",
            ["--gens", "2", "--pop", "12"],
            "best trade-off T =",
            marks=pytest.mark.slow,  # ~7 s: the polish's global stage on a blocked scene
        ),
        ("other_robot.py", ["--gens", "2", "--pop", "12"], "planned T ="),
        ("ur5_around_a_box.py", ["--gens", "2", "--pop", "12"], "certified feasible"),
        pytest.param(
            "plan_cell.py",
            ["--gens", "4", "--pop", "16"],
            "distance continuous",
            marks=pytest.mark.slow,  # ~8 s: plans, certifies and verifies the example cell
        ),
    ],
)
def test_example_runs(script: str, args: list[str], expect: str, tmp_path: Path) -> None:
    if script in ("plan_paper.py", "plan_cell.py"):
        args = [*args, "--out", str(tmp_path / "out")]
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / script), *args],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert expect in result.stdout, result.stdout


def test_every_example_is_tested() -> None:
    scripts = {p.name for p in EXAMPLES.glob("*.py")}
    assert scripts == {
        "robot_dynamics.py",
        "plan_paper.py",
        "custom_scene.py",
        "other_robot.py",
        "ur5_around_a_box.py",
        "plan_cell.py",
        "make_cell.py",  # writes the shipped meshes: tests/scene/test_example_cell.py runs it
    }
