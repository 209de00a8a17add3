"""The adept-traj command: the robot demo, build-urdf, and one-line errors."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from adept_traj.cli import main

ROOT = Path(__file__).resolve().parents[1]


def test_robot_demo_prints_torque_ratios(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["robot", "--duration", "1.1", "--samples", "201"]) == 0
    out = capsys.readouterr().out
    lines = [line for line in out.splitlines() if line.strip().startswith("joint")]
    assert len(lines) == 5  # header + 4 joints
    ratios = [float(line.split()[-1]) for line in lines[1:]]
    assert all(0.01 < r < 1.0 for r in ratios), ratios  # same order as Table 2's UC
    assert "manipulability (paper z4)" in out


def test_build_urdf_writes_the_shipped_file(tmp_path: Path) -> None:
    out = tmp_path / "robot.urdf"
    assert main(["build-urdf", str(ROOT / "urdf" / "adept_one_xl.toml"), "-o", str(out)]) == 0
    assert out.read_text() == (ROOT / "urdf" / "adept_one_xl.urdf").read_text()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["robot", "--start", "0,0,0.5,0"], "joint 'joint3' = 0.5 m is outside its limits"),
        (["robot", "--goal", "0,0,0.1"], r"--goal must have shape \(\.\.\., 4\)"),
        (["robot", "--duration", "-1"], "--duration must be a positive number"),
        (["robot", "--urdf", "missing.urdf"], "URDF not found"),
        (["build-urdf", "missing.toml"], "file not found"),
    ],
)
def test_bad_input_is_one_line_without_traceback(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "Traceback" not in err
    assert re.search(message, err), err


def test_console_script_runs_in_a_subprocess() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "adept_traj.cli", "robot", "--samples", "50"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert "joint4" in result.stdout
