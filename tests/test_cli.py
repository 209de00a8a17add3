"""The adept-traj command: the robot demo, build-urdf, and one-line errors."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from adept_traj.cli import main
from adept_traj.results import PlanningResult

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


def test_plan_verify_and_resume(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    assert main(["plan", "--pop", "12", "--gens", "3", "--out", str(out), "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "verified at 1000 Hz" in text
    assert (out / "result.json").is_file()
    assert not (out / "checkpoint").exists()  # cleaned up after success
    status = main(["verify", str(out)])
    assert status in (0, 1)  # 1: the (tiny) run's best is not feasible
    assert "re-verified at 1000 Hz" in capsys.readouterr().out
    # An interrupted run (simulated: a checkpoint and run.json left behind) resumes.
    interrupted = tmp_path / "interrupted"
    import adept_traj.cli.plan as plan_command

    def stop_after_two(label, quiet):
        def progress(info):
            if info.generation == 2:
                raise KeyboardInterrupt

        return progress

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(plan_command, "progress_reporter", stop_after_two)
        argv = ["plan", "--pop", "12", "--gens", "4", "--out", str(interrupted)]
        assert main(argv) == 130
    assert "--resume" in capsys.readouterr().err
    assert main(["plan", "--resume", str(interrupted), "--quiet"]) == 0
    resumed = PlanningResult.load(interrupted)
    assert (
        main(["plan", "--pop", "12", "--gens", "4", "--out", str(tmp_path / "u"), "--quiet"]) == 0
    )
    uninterrupted = PlanningResult.load(tmp_path / "u")
    np.testing.assert_array_equal(resumed.front.x, uninterrupted.front.x)


def test_compare_writes_tables(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["compare", "--gens", "2", "--pop-nsga2", "8", "--pop-mode", "8"]
    assert main([*argv, "--out", str(tmp_path), "--quiet"]) == 0
    table = (tmp_path / "comparison.md").read_text()
    for heading in ("Table 3", "Table 4", "Table 5", "0.683650", "0.852519", "0.497040"):
        assert heading in table
    assert (tmp_path / "nsga2" / "result.json").is_file()
    assert (tmp_path / "mode" / "result.json").is_file()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["plan", "--algorithm", "foo", "--out", "x"], "unknown algorithm 'foo'"),
        (["plan", "--pop", "1", "--out", "x"], "pop_size must be an integer ≥ 2"),
        (["plan", "--weights", "1,1,1,1,1,-1", "--out", "x"], "--weights must be 6"),
        (["plan", "--weights", "1,1,1", "--out", "x"], "--weights must be 6"),
        (["plan", "--start", "0,0,0.3,0", "--out", "x"], "outside its limits"),
        (["plan", "--scene", "missing.toml", "--out", "x"], "scene file not found"),
        (["plan"], "give --out DIR"),
        (["plan", "--resume", "nothing-here"], "no interrupted run"),
        (["verify", "nothing-here"], "nothing-here"),
    ],
)
def test_plan_bad_input(argv, message, capsys: pytest.CaptureFixture[str], tmp_path) -> None:
    argv = [str(tmp_path / a) if a in ("x", "nothing-here", "missing.toml") else a for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert message in err


def test_console_script_runs_in_a_subprocess() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "adept_traj.cli", "robot", "--samples", "50"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    assert "joint4" in result.stdout


def test_show_serves_on_localhost_and_stops_on_ctrl_c(tmp_path: Path) -> None:
    import signal

    out = tmp_path / "run"
    assert main(["plan", "--pop", "8", "--gens", "2", "--out", str(out), "--quiet"]) == 0
    assert (out / "playback.html").is_file()  # plan writes the static playback page
    proc = subprocess.Popen(
        [sys.executable, "-m", "adept_traj.cli", "show", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        line = proc.stdout.readline()
        assert "http://127.0.0.1:" in line, line + proc.stderr.read()
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=30) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
