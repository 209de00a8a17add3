"""The helper process of ``adept-traj plan`` (adept_traj.viz.finisher): forked with the run,
it imports at nice 19 in a thread, then writes the figures and playback.html at the caller's
priority while the caller saves result.json: the same files; its error is raised in the
caller (exit status not 0, run not complete); it is stopped by Ctrl-C, an error and the
caller's death (SIGKILL), reaped every time; none with --no-plots --no-html; a helper not
ready when the run ends is stopped and the caller writes the files. The optimiser is
replaced by a stored result, the drawings and imports by cheap fakes (forked processes
inherit them)."""

from __future__ import annotations

import argparse
import multiprocessing
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import adept_traj as at
import adept_traj.cli.plan as plan_command
import adept_traj.cli.report as report
import adept_traj.optimise as optimise  # cli.plan runs its plan (imported on use)
from adept_traj.cli import status
from adept_traj.cli.app import main
from adept_traj.errors import InvalidInputError
from adept_traj.process_pool import children
from adept_traj.results import PlanningResult, Replay
from adept_traj.viz import finisher, meshcat_scene
from adept_traj.viz.plots import all_figures
from tests.conftest import may_lower_niceness

DATA = Path(__file__).parents[1] / "data"
_DRAWINGS = ("pareto_matrix", "best_tradeoffs", "hypervolume_history", "joint_motion")


@pytest.fixture(scope="module")
def stored() -> PlanningResult:
    result = PlanningResult.load(DATA / "result_v1")
    assert not result.feasible  # so plan's exit status is NOT_CERTIFIED (1), not 0
    return result


def _nice() -> int:
    """The calling thread's niceness (per thread on Linux)."""
    return os.getpriority(os.PRIO_PROCESS, threading.get_native_id())


def _fake(name: str, error: BaseException | None = None):
    def draw(_results, path, **_kwargs):
        if error is not None:
            raise error
        Path(path).write_text(f"{name} {os.getpid()} {_nice()}")
        return Path(path)

    return draw


def _marking_preload(marker: Path, seconds: float = 0.0):
    """A fake import: writes "pid niceness" to ``marker`` (the figures' helper; the page's
    helper to ``marker.page``), then sleeps ``seconds``."""

    def preload(figures: bool, _html: bool) -> None:
        (marker if figures else marker.with_suffix(".page")).write_text(f"{os.getpid()} {_nice()}")
        time.sleep(seconds)

    return preload


def _gone(pid: int, within: float = 10.0) -> bool:
    """Whether process ``pid`` has ended (checked until ``within`` [s] have passed): no
    longer in ``/proc``, or a zombie of another parent than this process (init's, after
    its own parent was killed, reaped by init)."""
    stop = time.monotonic() + within
    while True:
        try:
            fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        except FileNotFoundError:
            return True
        if fields[0] == "Z" and int(fields[1]) != os.getpid():
            return True
        if time.monotonic() >= stop:
            return False
        time.sleep(0.02)


def _plan(monkeypatch, result, out: Path, *options: str, plan=None, **fakes) -> int:
    """``adept-traj plan --out out`` whose optimiser returns ``result`` (or runs ``plan``)."""
    monkeypatch.setattr(optimise, "plan", plan or (lambda *_a, **_k: result))
    for name in (*_DRAWINGS, "tool_path_3d"):
        monkeypatch.setattr(all_figures, name, fakes.get(name, _fake(name)))
    monkeypatch.setattr(all_figures, "load_matplotlib", lambda: None)  # the fakes need none
    argv = ["plan", "--workers", "1", "--quiet", *options, "--out", str(out)]
    return main(argv)


def _plan_marked(
    monkeypatch: pytest.MonkeyPatch, stored: PlanningResult, tmp_path: Path, *options: str
) -> tuple[int, Path]:
    """``plan`` into ``tmp_path/run`` with the helpers' imports replaced by
    :func:`_marking_preload` (waited for up to 30 s): its exit status and the marker."""
    marker = tmp_path / "preload"
    monkeypatch.setattr(finisher, "_preload", _marking_preload(marker))
    monkeypatch.setattr(finisher, "READY_TIMEOUT", 30.0)
    return _plan(monkeypatch, stored, tmp_path / "run", *options), marker


def test_a_time_optimal_run_has_its_helper_import_at_the_callers_priority(
    stored: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The time-optimal search is shorter than the imports: the figures' share the cores
    with the run from the start (``urgent``) rather than waiting at nice 19 for an idle
    one; the page's, a fraction of the figures' time, import at nice 19 (raised when the
    page is due)."""
    code, marker = _plan_marked(monkeypatch, stored, tmp_path, "--algorithm", "time-optimal")
    assert code == status.NOT_CERTIFIED
    helper, import_nice = map(int, marker.read_text().split())
    assert helper != os.getpid()
    assert import_nice == _nice() != finisher.IMPORT_NICENESS
    assert len(list((tmp_path / "run" / "figures").iterdir())) == 5
    pager, page_nice = map(int, marker.with_suffix(".page").read_text().split())
    assert pager not in {helper, os.getpid()}  # the page's imports in a helper of its own
    assert page_nice == finisher.IMPORT_NICENESS != _nice()
    assert (tmp_path / "run" / "playback.html").is_file()
    assert (tmp_path / "run" / "explorer.html").is_file()


def test_a_time_optimal_run_without_figures_imports_the_page_at_the_callers_priority(
    stored: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With ``--no-plots`` the page is the last output: its helper imports at once."""
    options = ("--algorithm", "time-optimal", "--no-plots")
    code, marker = _plan_marked(monkeypatch, stored, tmp_path, *options)
    assert code == status.NOT_CERTIFIED
    assert not marker.exists()  # no figures' helper
    pager, page_nice = map(int, marker.with_suffix(".page").read_text().split())
    assert pager != os.getpid()
    assert page_nice == _nice() != finisher.IMPORT_NICENESS
    assert (tmp_path / "run" / "playback.html").is_file()


def test_the_helper_writes_the_files_at_the_callers_priority_after_importing_at_nice_19(
    stored: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    code, marker = _plan_marked(monkeypatch, stored, tmp_path)
    assert code == status.NOT_CERTIFIED
    helper, import_nice = map(int, marker.read_text().split())
    assert helper != os.getpid()
    assert import_nice == finisher.IMPORT_NICENESS
    figures = sorted((tmp_path / "run" / "figures").iterdir())
    assert len(figures) == 5
    writers = [p.read_text().split() for p in figures]
    assert {int(w[1]) for w in writers} & {helper}  # the helper draws one share …
    assert os.getpid() not in {int(w[1]) for w in writers}  # … its fork the other
    assert {int(w[2]) for w in writers} == {_nice()}  # at the caller's priority
    assert not marker.with_suffix(".page").exists()  # one helper: figures and page
    # the same files as the caller writes itself
    plain = tmp_path / "plain"
    stored.save(plain)
    for name in ("result.json", "front.csv", "best_trajectory.csv"):
        assert (tmp_path / "run" / name).read_bytes() == (plain / name).read_bytes()
    scene = at.Scene.paper()
    replay = Replay.of(stored, robot=at.Robot.adept_one_xl(), scene=scene)
    page = meshcat_scene.static_html(stored, tmp_path / "page.html", replay=replay)
    assert (tmp_path / "run" / "playback.html").read_bytes() == page.read_bytes()
    assert not (tmp_path / "run" / "run.json").exists()  # marked complete
    assert _gone(helper, within=0.0)  # reaped
    assert children() == []


def test_an_error_of_the_helper_is_raised_and_the_run_not_completed(
    stored: PlanningResult,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    marker = tmp_path / "preload"
    monkeypatch.setattr(finisher, "_preload", _marking_preload(marker))
    monkeypatch.setattr(finisher, "READY_TIMEOUT", 30.0)
    full = OSError(28, "No space left on device", "joint_motion_nsga2.png")
    code = _plan(monkeypatch, stored, tmp_path / "run", "--no-html", joint_motion=_fake("j", full))
    assert code == 2
    err = capsys.readouterr().err
    assert re.search(r"adept-traj: error: .*No space left on device.*joint_motion_nsga2", err)
    assert (tmp_path / "run" / "result.json").is_file()  # written meanwhile
    assert (tmp_path / "run" / "run.json").is_file()  # not marked complete
    assert _gone(int(marker.read_text().split()[0]), within=0.0)


def test_a_helper_killed_while_drawing_has_its_work_done_by_the_caller(
    stored: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(finisher, "_preload", _marking_preload(tmp_path / "preload"))
    monkeypatch.setattr(finisher, "READY_TIMEOUT", 30.0)
    caller = os.getpid()

    def dies_unless_in_the_caller(_results, path, **_kwargs):
        if os.getpid() != caller:
            os.kill(os.getpid(), signal.SIGKILL)  # the helper (or a fork) killed outright
        Path(path).write_text(f"tool {os.getpid()}")
        return Path(path)

    out = tmp_path / "run"
    code = _plan(monkeypatch, stored, out, "--no-html", tool_path_3d=dies_unless_in_the_caller)
    assert code == status.NOT_CERTIFIED
    assert (out / "figures" / "tool_path_nsga2.png").read_text() == f"tool {caller}"
    assert len(list((out / "figures").iterdir())) == 5
    assert not (out / "run.json").exists()  # marked complete


@pytest.mark.parametrize("raised", [KeyboardInterrupt, RuntimeError])
def test_ctrl_c_or_an_error_during_the_run_stops_the_helper(
    raised: type[BaseException],
    stored: PlanningResult,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    marker = tmp_path / "preload"
    monkeypatch.setattr(finisher, "_preload", _marking_preload(marker, seconds=60.0))

    def interrupted(*_args, **_kwargs):
        while not marker.is_file() or not marker.read_text():
            time.sleep(0.01)  # the helper is importing
        raise raised("stop")

    if raised is KeyboardInterrupt:
        assert _plan(monkeypatch, stored, tmp_path / "run", plan=interrupted) == 130
    else:
        with pytest.raises(RuntimeError, match="stop"):
            _plan(monkeypatch, stored, tmp_path / "run", plan=interrupted)
    assert _gone(int(marker.read_text().split()[0]), within=0.0)
    assert children() == []


def test_no_helper_with_no_plots_and_no_html(
    stored: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    started = []
    monkeypatch.setattr(report, "start_finisher", lambda *a, **k: started.append(a))
    assert _plan(monkeypatch, stored, tmp_path / "run", "--no-plots", "--no-html") == 1
    assert started == []
    assert (tmp_path / "run" / "result.json").is_file()


def test_a_helper_not_ready_when_the_run_ends_is_stopped_and_the_caller_writes(
    stored: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    marker = tmp_path / "preload"
    monkeypatch.setattr(finisher, "_preload", _marking_preload(marker, seconds=60.0))
    monkeypatch.setattr(finisher, "HURRIED_TIMEOUT", 0.2)  # hurried, still not done

    out = tmp_path / "run"
    assert (
        _plan(monkeypatch, stored, out, "--no-html", plan=_ends_while_importing(marker, stored))
        == 1
    )
    helper = int(marker.read_text().split()[0])
    assert _gone(helper, within=0.0)
    writers = {int(p.read_text().split()[1]) for p in (out / "figures").iterdir()}
    assert len(writers) >= 1
    assert helper not in writers
    assert not (out / "run.json").exists()


def test_a_helper_still_importing_when_the_run_ends_is_hurried_and_used(
    stored: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    marker = tmp_path / "preload"

    def imports_until_hurried(_figures: bool, _html: bool) -> None:
        marker.write_text(f"{os.getpid()} {_nice()}")
        deadline = time.monotonic() + 60.0
        while _nice() == finisher.IMPORT_NICENESS and time.monotonic() < deadline:
            time.sleep(0.01)

    monkeypatch.setattr(finisher, "_preload", imports_until_hurried)

    out = tmp_path / "run"
    assert (
        _plan(monkeypatch, stored, out, "--no-html", plan=_ends_while_importing(marker, stored))
        == 1
    )
    helper = int(marker.read_text().split()[0])
    writers = {int(p.read_text().split()[1]) for p in (out / "figures").iterdir()}
    if may_lower_niceness():  # hurried: the helper (and its fork) drew, not the caller
        assert helper in writers
        assert os.getpid() not in writers
    else:  # refused: the caller drew
        assert helper not in writers
    assert _gone(helper, within=10.0)
    assert not (out / "run.json").exists()


def _ends_while_importing(marker: Path, result: PlanningResult):
    """An optimiser that returns ``result`` once the helper's imports have begun."""

    def run(*_args, **_kwargs):
        while not marker.is_file() or not marker.read_text():
            time.sleep(0.01)
        return result

    return run


def _caller(marker: Path, ready: bool) -> None:
    """A process that starts a helper (importing for 60 s, or ready) and sleeps."""
    finisher._preload = _marking_preload(marker, seconds=0.0 if ready else 60.0)
    scene = at.Scene.paper()
    helper = finisher.start_finisher(at.Robot.adept_one_xl(), scene, figures=False, html=True)
    if ready:
        assert helper.ready(30.0)
    (marker.parent / "started").write_text(str(helper.pid))
    time.sleep(60.0)


@pytest.mark.parametrize("ready", [False, True], ids=["importing", "waiting"])
def test_a_helper_dies_with_its_killed_caller(ready: bool, tmp_path: Path) -> None:
    caller = multiprocessing.get_context("fork").Process(
        target=_caller, args=(tmp_path / "preload", ready)
    )
    caller.start()
    stop = time.monotonic() + 30.0
    started = tmp_path / "started"
    # not empty: the file exists before its text is written (read in between, it failed)
    while not (started.is_file() and started.read_text()) and time.monotonic() < stop:
        time.sleep(0.01)
    helper = int(started.read_text())
    assert not _gone(helper, within=0.0)
    os.kill(caller.pid, signal.SIGKILL)
    caller.join()
    assert _gone(helper)


def test_a_script_that_never_cancels_its_helper_still_exits(tmp_path: Path) -> None:
    """A helper still waiting for its order is stopped at the interpreter's exit, so the
    interpreter exits."""
    script = (
        "import adept_traj as at\n"
        "from adept_traj.viz.finisher import start_finisher\n"
        "f = start_finisher(at.Robot.adept_one_xl(), at.Scene.paper(), figures=True, html=False)\n"
        "print(f.pid, flush=True)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=60, check=False
    )
    assert done.returncode == 0, done.stderr
    assert _gone(int(done.stdout.split()[-1]))


def test_start_and_wait_check_their_arguments(stored: PlanningResult, tmp_path: Path) -> None:
    scene = at.Scene.paper()
    robot = at.Robot.adept_one_xl()
    with pytest.raises(InvalidInputError, match="figures=True or html=True"):
        finisher.start_finisher(robot, scene, figures=False, html=False)
    with pytest.raises(InvalidInputError, match="scene"):
        finisher.start_finisher(robot, "paper", figures=True, html=False)
    with finisher.start_finisher(robot, scene, figures=False, html=True) as helper:
        with pytest.raises(InvalidInputError, match="without the output"):
            helper.start({"a": stored}, figures=tmp_path)
        with pytest.raises(InvalidInputError, match="one result"):
            helper.start({"a": stored, "b": stored}, html=tmp_path / "p.html")
        with pytest.raises(InvalidInputError, match="successful"):
            helper.wait()
        pid = helper.pid
    assert _gone(pid, within=0.0)


@pytest.mark.slow
def test_the_helper_writes_the_same_files_as_the_caller(
    stored: PlanningResult, tmp_path: Path
) -> None:
    """Real figures and page: with a ready helper and without one, byte for byte."""
    scene, robot = at.Scene.paper(), at.Robot.adept_one_xl()
    problem = argparse.Namespace(
        robot=robot, scene=scene, self_check=None
    )  # as a problem without self-collision
    opts = argparse.Namespace(
        no_html=False, no_plots=False, ros=None, allow_infeasible=False, algorithm="nsga2"
    )
    for name in ("helper", "caller"):
        (tmp_path / name).mkdir()
    with finisher.start_finisher(robot, scene, figures=True, html=True) as helper:
        assert helper.ready(120.0)
        assert plan_command._finish(stored, problem, tmp_path / "helper", opts, helper) == 1
    assert plan_command._finish(stored, problem, tmp_path / "caller", opts) == 1
    caller, helped = (_files(tmp_path / name) for name in ("caller", "helper"))
    assert len([f for f in caller if f.endswith(".png")]) == 5
    assert "playback.html" in caller
    assert helped == caller  # the same names, the same bytes


def _files(folder: Path) -> dict[str, bytes]:
    """{path relative to ``folder``: bytes} of every file below ``folder``."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}
