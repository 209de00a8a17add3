"""The adept-traj command: every sub-command, one-line errors, exit statuses, progress
output on a terminal and in logs, the --ros export guard and show's SIGTERM handling."""

from __future__ import annotations

import io
import json
import os
import re
import select
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from adept_traj import cli
from adept_traj.cli import main
from adept_traj.cli.progress import ProgressReporter
from adept_traj.optimise import GenerationInfo, plan
from adept_traj.problem import TrajectoryProblem
from adept_traj.results import PlanningResult
from adept_traj.robot import Robot
from adept_traj.scene import Scene

ROOT = Path(__file__).resolve().parents[2]
#: An obstacle out of every test robot's reach.
FAR_BOX = {"name": "box", "shape": "box", "min": [2.0, 2.0, 2.0], "max": [2.1, 2.1, 2.1]}


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
        (["robot", "--goal", "0,0,0.1"], r"--goal must hold 4 joint values for robot .*; got 3"),
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


@pytest.mark.slow  # ≥ 5 s (the default tier measured 192 s after the merges)
def test_plan_verify_and_resume(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run"
    # this tiny run's search finds no feasible member; the polish's global stage finds a
    # certified move (issue #24): exit 0
    assert main(["plan", "--pop", "12", "--gens", "3", "--out", str(out), "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "verified at 1000 Hz" in text
    assert (out / "result.json").is_file()
    assert not (out / "checkpoint").exists()  # cleaned up after the run completed
    assert PlanningResult.load(out).feasible
    assert main(["verify", str(out)]) == 0
    assert "re-verified at 1000 Hz" in capsys.readouterr().out
    # An interrupted run (simulated: a checkpoint and run.json left behind) resumes.
    interrupted = tmp_path / "interrupted"
    import adept_traj.cli.plan as plan_command

    class StopAfterTwo(plan_command.ProgressReporter):
        def __call__(self, info):
            if info.generation == 2:
                raise KeyboardInterrupt

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(plan_command, "ProgressReporter", StopAfterTwo)
        light = ["--no-plots", "--no-html"]  # the drawing is tested elsewhere
        argv = ["plan", "--pop", "12", "--gens", "4", *light, "--out", str(interrupted)]
        assert main(argv) == 130
    assert "--resume" in capsys.readouterr().err
    code = main(["plan", "--resume", str(interrupted), "--quiet"])
    resumed = PlanningResult.load(interrupted)
    assert code == (0 if resumed.feasible else 1)  # 0 only for a certified best trade-off
    argv = ["plan", "--pop", "12", "--gens", "4", *light, "--out", str(tmp_path / "u")]
    assert main([*argv, "--quiet"]) == code
    uninterrupted = PlanningResult.load(tmp_path / "u")
    np.testing.assert_array_equal(resumed.front.x, uninterrupted.front.x)


@pytest.mark.slow  # 5–15 s: kept out of the default tier (≤ 3 min)
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
        (["plan", "--pop", "1", "--out", "x"], "pop_size must be an integer in [2, ∞]; got 1"),
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


@pytest.mark.slow  # ~3 s: the default tier's budget
def test_show_serves_on_localhost_and_stops_on_ctrl_c(tmp_path: Path) -> None:
    import signal

    out = tmp_path / "run"
    assert (
        main(["plan", "--pop", "8", "--gens", "2", "--no-polish", "--out", str(out), "--quiet"])
        == 0
    )
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


# ------------------------------------------------------------------------------ progress
class _Terminal(io.StringIO):
    """A stream that says it is a terminal."""

    def isatty(self) -> bool:
        return True


def _generations(n_gen: int, first: int = 1) -> list[GenerationInfo]:
    return [
        GenerationInfo(
            generation=g,
            n_gen=n_gen,
            n_evaluations=10 * g,
            n_feasible=g,
            best_time=None if g < 3 else 1.5,
            elapsed_s=0.25 * g,
        )
        for g in range(first, n_gen + 1)
    ]


@pytest.mark.parametrize(
    ("n_gen", "printed"),
    [
        (100, list(range(10, 101, 10))),
        (3, [1, 2, 3]),
        (15, [2, 4, 6, 8, 10, 12, 14, 15]),
        (1, [1]),
    ],
)
def test_progress_in_a_log_is_about_ten_plain_lines(n_gen: int, printed: list[int]) -> None:
    stream = io.StringIO()
    reporter = ProgressReporter("nsga2", stream)
    for info in _generations(n_gen):
        reporter(info)
    reporter.close()
    text = stream.getvalue()
    assert "\r" not in text
    lines = text.splitlines()
    assert [line.split()[2] for line in lines] == [f"{g}/{n_gen}" for g in printed]
    g = printed[-1]
    best = "-" if g < 3 else "1.500 s"
    assert lines[-1] == (
        f"nsga2 gen {g}/{n_gen}  evals {10 * g}  feasible {g}  best T {best}  {0.25 * g:.1f} s"
    )


def test_progress_on_a_terminal_is_one_bar(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("COLUMNS", "160")  # the bar's width, whatever runs the tests
    stream = _Terminal()
    reporter = ProgressReporter("mode", stream)
    for info in _generations(5):
        reporter(info)
    text = stream.getvalue()
    assert text.count("\n") == 1  # one bar, redrawn in place, its line ended at the end
    assert text.endswith("\n")
    last = text.rstrip("\n").split("\r")[-1]
    assert last.startswith("mode")
    assert "5/5" in last
    assert "evals 50  feasible 5  best T 1.500 s" in last


@pytest.mark.skipif(not hasattr(os, "openpty"), reason="needs a pseudo-terminal (POSIX)")
def test_progress_bar_is_drawn_on_a_terminal_that_reports_no_size(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    master, slave = os.openpty()  # a new pty reports 0 columns × 0 rows
    try:
        with os.fdopen(slave, "w", closefd=False) as stream:
            monkeypatch.setattr(sys, "stderr", stream)  # tqdm sizes only stdout/stderr
            reporter = ProgressReporter("nsga2")
            for info in _generations(4):
                reporter(info)
        text = b""
        while select.select([master], [], [], 0.5)[0]:
            text += os.read(master, 65536)
    finally:
        os.close(slave)
        os.close(master)
    last = text.decode().rstrip("\r\n").split("\r")[-1]
    assert last.startswith("nsga2: 100%")
    assert "4/4" in last


def test_progress_bar_of_a_resumed_run_starts_part_way_and_ends_its_line() -> None:
    stream = _Terminal()
    with ProgressReporter("nsga2", stream) as reporter:
        reporter(_generations(10, first=4)[0])  # interrupted after one generation
    text = stream.getvalue()
    assert text.endswith("\n")
    assert "4/10" in text.split("\r")[-1]
    assert "1/10" not in text


def test_quiet_reports_nothing() -> None:
    for stream in (io.StringIO(), _Terminal()):
        with ProgressReporter("nsga2", stream, quiet=True) as reporter:
            for info in _generations(20):
                reporter(info)
        assert stream.getvalue() == ""


def test_plan_progress_in_a_log_has_no_carriage_returns(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["plan", "--pop", "8", "--gens", "3", "--no-html", "--no-plots", "--no-polish"]
    assert main([*argv, "--out", str(tmp_path / "log")]) == 0
    err = capsys.readouterr().err
    assert "\r" not in err
    assert [line.split()[:3] for line in err.splitlines()] == [
        ["nsga2", "gen", f"{g}/3"] for g in (1, 2, 3)
    ]
    assert main([*argv, "--out", str(tmp_path / "quiet"), "--quiet"]) == 0
    assert capsys.readouterr().err == ""


# ------------------------------------------------------------------------------ --ros
_BLOCKED_SCENE = """
name = "blocked"
[robot]
xyz = [1.45, 0.39, -0.25]
rpy = [0.0, 0.0, 3.141592653589793]
[task]
start = [0.1682, 1.3849, 0.08, -0.7555]
goal = [-0.7610, 0.2450, 0.20, 1.0095]
[[obstacle]]  # the whole reach of the arm between start and goal: no move is collision-free
name = "wall"
shape = "box"
min = [0.0, -1.0, -1.0]
max = [1.2, 2.0, 1.0]
"""
_TINY = ["plan", "--pop", "8", "--gens", "2", "--no-html", "--no-plots", "--quiet", "--no-polish"]


def test_plan_exports_an_uncertified_trajectory_only_when_allowed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    blocked = tmp_path / "blocked.toml"
    blocked.write_text(_BLOCKED_SCENE)  # the wall holds the start: refused before a search
    assert main([*_TINY, "--scene", str(blocked), "--out", str(tmp_path / "blocked")]) == 2
    err = capsys.readouterr().err
    assert "no move can be certified" in err
    assert re.search(r"start: link\S+ – obstacle wall -\d\.\d+ m", err)
    assert not (tmp_path / "blocked").exists()
    # the detour scene's fixed obstacles alone (no moving obstacle: no global-stage starts
    # in the initial population); 16 evaluations find no way round the post (seed 1)
    detour = (Path(cli.__file__).parents[1] / "data" / "scenes" / "detour.toml").read_text()
    scene = tmp_path / "post.toml"
    scene.write_text(detour[: detour.index("[[pendulum]]")])
    ros = tmp_path / "ros" / "best.json"
    out = tmp_path / "refused"
    assert main([*_TINY, "--scene", str(scene), "--out", str(out), "--ros", str(ros)]) == 1
    captured = capsys.readouterr()
    assert not ros.exists()
    assert not PlanningResult.load(out).feasible  # the folder is still written
    assert not (out / "run.json").exists()
    assert not (out / "checkpoint").exists()
    assert "NOT FEASIBLE" in captured.out
    err = captured.err.strip().splitlines()
    assert len(err) == 1
    assert err[0].startswith("adept-traj: error: the best trade-off is not verified feasible")
    assert str(ros) in err[0]
    assert "--allow-infeasible" in err[0]
    argv = [*_TINY, "--scene", str(scene), "--out", str(tmp_path / "allowed")]
    # exported as allowed, but the best trade-off is not certified: still exit 1
    assert main([*argv, "--ros", str(ros), "--allow-infeasible"]) == 1
    assert "ROS JointTrajectory written" in capsys.readouterr().out
    message = json.loads(ros.read_text())
    assert message["joint_names"] == ["joint1", "joint2", "joint3", "joint4"]


def test_plan_exports_a_certified_trajectory(tmp_path: Path) -> None:
    ros = tmp_path / "best.json"
    assert main([*_TINY, "--out", str(tmp_path / "run"), "--ros", str(ros)]) == 0
    assert PlanningResult.load(tmp_path / "run").feasible
    assert len(json.loads(ros.read_text())["points"]) > 1000  # 1 kHz over T > 1 s


@pytest.mark.parametrize(
    ("ros", "message"),
    [
        ("folder", "is a folder"),
        ("file.txt/best.json", "is not a folder"),
        ("bad\0name.json", "not a valid path"),
        ("run/result.json", "a file of the result folder"),
        ("run/run.json", "a file of the result folder"),
    ],
)
def test_plan_refuses_a_bad_ros_path_before_the_run(
    ros: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "folder").mkdir()
    (tmp_path / "file.txt").write_text("")
    out = tmp_path / "run"
    assert main([*_TINY, "--out", str(out), "--ros", str(tmp_path / ros)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert message in err
    assert not out.exists()  # refused before the run started


# ------------------------------------------------------------------------------ verify
def _limit_lines(out: str) -> dict[str, str]:
    """The limit lines of ``verify``'s output, by kind."""
    kinds = ("position", "velocity", "acceleration", "jerk", "torque")
    rows = [line.split(maxsplit=1) for line in out.splitlines() if line.startswith("  ")]
    return {row[0]: row[1] for row in rows if row[0] in kinds}


_WORST = r"worst -?\d+\.\d{4} \(bound [01]\)"


def _planar_verify(tmp_path: Path, joints: str, capsys: pytest.CaptureFixture[str]):
    """Plan a tiny run of the planar 2-link arm (parameter file: task rows, ``joints``),
    verify it with the command; the run's saved certificate and the limit lines."""
    params = tmp_path / "planar.toml"
    params.write_text(f'tool_frame = "hand"\ntask_rows = ["vx", "vz"]\n{joints}')
    robot = Robot.from_urdf(ROOT / "tests" / "data" / "planar_2link.urdf", params)
    assert np.isinf(robot.limits.jerk).all()
    scene = Scene.from_dict({"name": "far", "obstacle": [FAR_BOX]})
    problem = TrajectoryProblem(robot, scene, [0.0, 0.0], [1.0, 1.0])
    try:
        plan(problem, "nsga2", seed=1, pop_size=8, n_gen=2).save(tmp_path / "run")
    finally:
        problem.close()
    capsys.readouterr()
    saved = PlanningResult.load(tmp_path / "run").certificate
    assert saved.feasible  # nothing in reach, limits far: the tiny run's best passes
    assert main(["verify", str(tmp_path / "run")]) == 0
    lines = _limit_lines(capsys.readouterr().out)
    assert list(lines) == ["position", "velocity", "acceleration", "jerk", "torque"]
    for kind in ("position", "velocity", "torque"):
        assert re.fullmatch(_WORST, lines[kind]), lines
    return saved, lines


@pytest.mark.slow  # ≥ 3 s: kept out of the default tier (≤ 3 min)
def test_verify_says_no_limit_for_a_robot_without_acceleration_and_jerk_limits(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, lines = _planar_verify(tmp_path, "", capsys)
    assert lines["acceleration"] == "no limit"
    assert lines["jerk"] == "no limit"


def test_verify_names_the_joints_without_a_limit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    joints = '[[joint]]\nname = "shoulder"\nacceleration = 20.0\n'  # the elbow has none
    saved, lines = _planar_verify(tmp_path, joints, capsys)
    assert re.fullmatch(_WORST + "; no limit: elbow", lines["acceleration"]), lines
    worst = float(lines["acceleration"].split()[1].rstrip(";"))  # the shoulder's alone
    assert worst == pytest.approx(saved.acceleration.worst[0], abs=5e-5)
    assert lines["jerk"] == "no limit"


def test_verify_prints_every_limit_of_the_shipped_robot(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main([*_TINY, "--out", str(tmp_path)]) == 0
    capsys.readouterr()
    assert main(["verify", str(tmp_path)]) == 0  # this run's best is feasible
    lines = _limit_lines(capsys.readouterr().out)
    assert list(lines) == ["position", "velocity", "acceleration", "jerk", "torque"]
    for text in lines.values():
        assert re.fullmatch(_WORST, text), lines


# ------------------------------------------------------------------------------ show
def _children(pid: int) -> list[int]:
    """The processes whose parent is ``pid`` (Linux /proc)."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
        except OSError:  # the process ended while we looked
            continue
        if int(text.rsplit(")", 1)[1].split()[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def _alive(pid: int) -> bool:
    """``pid`` exists and is not a zombie (Linux /proc)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.slow  # default-tier time (≤ 3 min): the slow tier runs it in CI (.ci/run)
@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_show_stops_its_server_on_sigterm(tmp_path: Path) -> None:
    import signal

    out = tmp_path / "run"
    assert main([*_TINY, "--out", str(out)]) == 0
    proc = subprocess.Popen(
        [sys.executable, "-m", "adept_traj.cli", "show", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    servers: list[int] = []
    try:
        line = proc.stdout.readline()
        assert "http://127.0.0.1:" in line, line + proc.stderr.read()
        servers = _children(proc.pid)
        assert len(servers) == 1  # the meshcat server
        assert _alive(servers[0])
        proc.send_signal(signal.SIGTERM)
        status = proc.wait(timeout=30)
        assert not _alive(servers[0])
        assert status == 143
    finally:
        if proc.poll() is None:
            proc.kill()
        for pid in servers:  # a server left behind by a failing run of this test
            if _alive(pid):
                os.kill(pid, signal.SIGKILL)


def test_compare_interrupted_exits_130(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import adept_traj.cli.compare as compare_command

    class StopAtOnce(compare_command.ProgressReporter):
        def __call__(self, info):
            raise KeyboardInterrupt

    monkeypatch.setattr(compare_command, "ProgressReporter", StopAtOnce)
    argv = ["compare", "--gens", "2", "--pop-nsga2", "8", "--pop-mode", "8", "--no-plots"]
    assert main([*argv, "--out", str(tmp_path)]) == 130
    err = capsys.readouterr().err
    assert "interrupted after generation 1" in err
    assert "error" not in err
