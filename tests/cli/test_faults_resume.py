"""Faults of ``adept-traj plan``: interruptions at any instant, and a user's data.

An interrupted run is a real subprocess that stops itself with a real signal (SIGKILL or
SIGINT) at a chosen instant: the driver below wraps one function of the library in that
process only (the n-th evaluation, the certificate, a file write, the completion) so that
calling it sends the signal. ``plan --resume`` must then reach the same files as an
uninterrupted run with the same seed (``result.json`` modulo its timings, ``front.csv``,
``best_trajectory.csv``, the figures), or, if the run was complete, say so and change
nothing. The sweep over every evaluation and every phase is in the slow tier.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from adept_traj.cli import main
from adept_traj.files import write_atomic

#: A tiny run: 3 generations of 8 (about a second) with a feasible front (so a hypervolume
#: history); no html/figures unless asked for.
_RUN = ["plan", "--pop", "8", "--gens", "3", "--rate", "1500", "--quiet"]
_LIGHT = ["--no-html", "--no-plots"]

#: Run ``main(argv)`` in this process, but send ``signal`` to itself when the ``n``-th call
#: of the function named by ``where`` starts.
_DRIVER = r"""
import os, signal, sys
import adept_traj.cli._run_folder as run_folder
import adept_traj.cli.plan as plan_command
import adept_traj.optimise.planner as planner
import adept_traj.problem.trajectory_problem as trajectory_problem
import adept_traj.results.record as record
import adept_traj.viz.meshcat_scene as meshcat_scene
import adept_traj.viz.plots.all_figures as all_figures
from adept_traj.cli import main

how, where, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
owner, name = {
    "evaluate": (trajectory_problem.TrajectoryProblem, "_evaluate"),
    "certify": (planner, "certify"),
    "result_json": (record, "write_json"),  # the codecs' writers, as the record calls them
    "front_csv": (record, "write_front_csv"),
    "html": (meshcat_scene, "static_html"),
    "figures": (all_figures, "joint_motion"),
    "commit": (plan_command, "commit"),  # every file written, the run not marked complete
    "committed": (run_folder, "sync_folder"),  # run.json removed, the checkpoint not yet
}[where]
original, calls = getattr(owner, name), []
# The command's process: the signal goes to it even when the instant comes in a process
# it forked (the figures and playback.html are written by the finish's helper process),
# as a Ctrl-C at the terminal or a kill of the command would.
MAIN = os.getpid()


def stopping(*args, **kwargs):
    calls.append(1)
    if len(calls) == n:
        os.kill(MAIN, signal.SIGKILL if how == "kill" else signal.SIGINT)
    return original(*args, **kwargs)


setattr(owner, name, stopping)
sys.exit(main(sys.argv[4:]))
"""


def _interrupted(how: str, where: str, n: int, argv: list[str]) -> subprocess.CompletedProcess:
    """Run ``adept-traj argv`` in a subprocess that signals itself at ``where`` (n-th call)."""
    return subprocess.run(
        [sys.executable, "-c", _DRIVER, how, where, str(n), *argv],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )


def _comparable_result(folder: Path) -> dict:
    """``result.json`` without what depends on the wall clock, nor the number of workers
    (free on resume, and it changes no other number)."""
    result = json.loads((folder / "result.json").read_text())
    del result["timing"], result["problem_settings"]["workers"]
    del result["metrics"]["OO"], result["metrics"]["AE"]
    return result


def _files(folder: Path) -> dict[str, bytes]:
    """Every file of ``folder`` (relative name: bytes), result.json left out."""
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.name not in ("result.json", "playback.html")
    }


def _assert_same_run(folder: Path, reference: Path) -> None:
    """``folder`` holds the complete run ``reference`` holds (modulo timings); the
    playback page too (the same size: meshcat names its objects by fresh UUIDs)."""
    assert _comparable_result(folder) == _comparable_result(reference)
    assert _files(folder) == _files(reference)
    assert (folder / "playback.html").is_file() == (reference / "playback.html").is_file()
    assert not (folder / "run.json").exists()
    assert not (folder / "checkpoint").exists()


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The uninterrupted tiny run (no html/figures)."""
    folder = tmp_path_factory.mktemp("reference") / "run"
    assert main([*_RUN, *_LIGHT, "--out", str(folder)]) == 0
    history = json.loads((folder / "result.json").read_text())["history"]
    assert [h["hypervolume"] is not None for h in history] == [True, True, True]
    return folder


@pytest.mark.parametrize(
    ("how", "where", "n"),
    [
        ("kill", "evaluate", 2),  # during generation 2
        ("int", "certify", 1),  # after the last generation, during the certificate
        # the other phases run in the slow tier too (the sweep covers every instant)
        pytest.param("kill", "front_csv", 1, marks=pytest.mark.slow),  # result.json only
        pytest.param("kill", "commit", 1, marks=pytest.mark.slow),  # run.json not removed
    ],
)
def test_an_interrupted_run_resumes_to_the_same_result(
    how: str, where: str, n: int, reference: Path, tmp_path: Path
) -> None:
    out = tmp_path / "run"
    stopped = _interrupted(how, where, n, [*_RUN, *_LIGHT, "--out", str(out)])
    expected = -signal.SIGKILL if how == "kill" else 130
    assert stopped.returncode == expected, stopped.stderr
    assert (out / "run.json").is_file()
    if how == "int":
        assert "Traceback" not in stopped.stderr
        assert f"adept-traj plan --resume {out}" in stopped.stderr
    assert main(["plan", "--resume", str(out), "--quiet"]) == 0
    _assert_same_run(out, reference)


def test_ctrl_c_in_the_first_generation_promises_no_checkpoint(
    reference: Path, tmp_path: Path
) -> None:
    """Nothing is checkpointed before the first generation ends: the message says so and
    ``--resume`` starts the run again, to the same result."""
    out = tmp_path / "run"
    stopped = _interrupted("int", "evaluate", 1, [*_RUN, *_LIGHT, "--out", str(out)])
    assert stopped.returncode == 130, stopped.stderr
    assert "nothing checkpointed" in stopped.stderr
    assert "starts the run again" in stopped.stderr
    assert "resume from" not in stopped.stderr
    assert not (out / "checkpoint" / "checkpoint.npz").exists()
    assert main(["plan", "--resume", str(out), "--quiet"]) == 0
    _assert_same_run(out, reference)


def test_resume_of_a_complete_run_changes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Killed after run.json was removed (the run is complete) but before the checkpoint
    was: ``--resume`` says the run is complete and touches no file."""
    out = tmp_path / "run"
    stopped = _interrupted("kill", "committed", 1, [*_RUN, *_LIGHT, "--out", str(out)])
    assert stopped.returncode == -signal.SIGKILL, stopped.stderr
    assert not (out / "run.json").exists()
    before = {p: (p.read_bytes(), p.stat().st_mtime_ns) for p in out.rglob("*") if p.is_file()}
    assert main(["plan", "--resume", str(out), "--quiet"]) == 0
    assert "already complete" in capsys.readouterr().err
    after = {p: (p.read_bytes(), p.stat().st_mtime_ns) for p in out.rglob("*") if p.is_file()}
    assert after == before


@pytest.fixture(scope="module")
def interrupted_once(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run interrupted (Ctrl-C) after its first generation, made once for the module."""
    out = tmp_path_factory.mktemp("interrupted") / "run"
    stopped = _interrupted("int", "evaluate", 2, [*_RUN, *_LIGHT, "--out", str(out)])
    assert stopped.returncode == 130, stopped.stderr
    return out


@pytest.fixture
def in_progress(interrupted_once: Path, tmp_path: Path) -> Path:
    """A fresh copy of the interrupted run (each test may resume or change it)."""
    return Path(shutil.copytree(interrupted_once, tmp_path / "run"))


@pytest.mark.parametrize(
    ("option", "named"),
    [
        (["--pop", "12"], ("--pop 12", "--pop 8")),
        (["--seed", "4"], ("--seed 4", "--seed 1")),
        (["--rate", "1000"], ("--rate 1000.0", "--rate 1500.0")),  # the default, given
        (["--algorithm", "mode"], ("--algorithm mode", "--algorithm nsga2")),
        (["--scene", "tests/data/planar_2link.toml"], ("planar_2link.toml", "--scene paper")),
        (["--gens", "5"], ("--gens 5", "--gens 3")),
        (
            ["--weights", "1,1,1,1,1,1"],
            ("--weights 1.0,1.0,1.0,1.0,1.0,1.0", "--weights 0.25,0.25,0.1,"),
        ),
    ],
)
def test_resume_refuses_options_that_differ_from_the_run(
    option: list[str],
    named: tuple[str, str],
    in_progress: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    before = {p: p.read_bytes() for p in in_progress.rglob("*") if p.is_file()}
    code = main(["plan", "--resume", str(in_progress), *option, "--quiet"])
    err = capsys.readouterr().err
    assert code == 2
    assert "conflicts with the run being resumed" in err
    assert named[0] in err, err
    assert named[1] in err, err
    assert {p: p.read_bytes() for p in in_progress.rglob("*") if p.is_file()} == before


def test_resume_accepts_the_run_s_own_options(in_progress: Path, reference: Path) -> None:
    """Options given again with the run's values (and --workers, free on resume) are
    accepted; scene paths compare as absolute paths."""
    argv = ["plan", "--resume", str(in_progress), "--pop", "8", "--seed", "1", "--no-plots"]
    assert main([*argv, "--no-html", "--workers", "1", "--scene", "paper", "--quiet"]) == 0
    _assert_same_run(in_progress, reference)


#: Every instant of the sweep: each evaluation call (3 generations: the initial population,
#: then the offspring of generations 2 and 3) and each phase after the loop.
_INSTANTS = [("evaluate", n) for n in range(1, 4)] + [
    ("certify", 1),
    ("result_json", 1),
    ("front_csv", 1),
    ("html", 1),
    ("figures", 1),
    ("commit", 1),
]


@pytest.fixture(scope="module")
def full_reference(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The uninterrupted tiny run with the playback page and the figures."""
    folder = tmp_path_factory.mktemp("full") / "run"
    assert main([*_RUN, "--out", str(folder)]) == 0
    return folder


@pytest.mark.slow
@pytest.mark.parametrize("how", ["kill", "int"])
@pytest.mark.parametrize(("where", "n"), _INSTANTS)
def test_sweep_every_instant(
    how: str, where: str, n: int, full_reference: Path, tmp_path: Path
) -> None:
    """Killed or interrupted at each instant, the run resumes to the same files (figures
    byte for byte)."""
    out = tmp_path / "run"
    stopped = _interrupted(how, where, n, [*_RUN, "--out", str(out)])
    assert stopped.returncode == (-signal.SIGKILL if how == "kill" else 130), stopped.stderr
    assert "Traceback" not in stopped.stderr
    assert main(["plan", "--resume", str(out), "--quiet"]) == 0
    _assert_same_run(out, full_reference)


# ------------------------------------------------------------------ never destroy a user's data


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


@pytest.fixture
def finished(reference: Path, tmp_path: Path) -> Path:
    """A complete run with html and a figure of another algorithm, beside a user's files."""
    out = tmp_path / "run"
    shutil.copytree(reference, out)
    (out / "playback.html").write_text("old page")
    (out / "figures").mkdir()
    (out / "figures" / "joint_motion_mode.png").write_bytes(b"old figure")
    (out / "figures" / "my_sketch.png").write_bytes(b"the user's")
    (out / "notes.txt").write_text("the user's")
    return out


def test_plan_refuses_a_folder_holding_a_result(
    finished: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    before = _snapshot(finished)
    assert main([*_RUN, *_LIGHT, "--out", str(finished)]) == 2
    err = capsys.readouterr().err
    assert "holds files of another run" in err, err
    assert "--overwrite" in err
    assert _snapshot(finished) == before


def test_overwrite_removes_only_the_old_run_s_files(finished: Path, reference: Path) -> None:
    assert main([*_RUN, *_LIGHT, "--out", str(finished), "--overwrite"]) == 0
    assert not (finished / "playback.html").exists()  # the old run's, not rewritten
    assert not (finished / "figures" / "joint_motion_mode.png").exists()
    assert (finished / "figures" / "my_sketch.png").read_bytes() == b"the user's"
    assert (finished / "notes.txt").read_text() == "the user's"
    assert _comparable_result(finished) == _comparable_result(reference)


def test_plan_refuses_an_interrupted_run_s_folder_and_names_resume(
    in_progress: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    before = _snapshot(in_progress)
    assert main([*_RUN, *_LIGHT, "--out", str(in_progress)]) == 2
    assert f"--resume {in_progress} continues it" in capsys.readouterr().err
    assert _snapshot(in_progress) == before


def test_an_empty_out_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main([*_RUN, *_LIGHT, "--out", ""]) == 2
    assert "--out is empty" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("option", "message"),
    [
        (["--algorithm", "bogus"], "bogus"),
        (["--pop", "0"], "pop"),
        (["--seed", "-1"], "--seed"),
        (["--gens", "0"], "n_gen"),
        (["--rate", "10"], "--rate"),
    ],
)
def test_a_refused_option_leaves_nothing_behind(
    option: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "notes.txt").write_text("the user's")
    assert main([*_RUN, *_LIGHT, *option, "--out", str(tmp_path)]) == 2
    assert message in capsys.readouterr().err
    assert [p.name for p in tmp_path.iterdir()] == ["notes.txt"]


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda root: (root / "out").write_text(""), "is a file, not a folder"),
        (lambda root: (root / "out" / "result.json").mkdir(parents=True), "is in the way"),
        (lambda root: (root / "out" / "figures").parent.mkdir() or (root / "out" / "figures")
         .write_text(""), "is in the way"),
    ],
)  # fmt: skip
def test_output_paths_are_checked_before_the_run(
    make, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    make(tmp_path)
    before = _snapshot(tmp_path)
    assert main([*_RUN, "--no-html", "--out", str(tmp_path / "out")]) == 2
    assert message in capsys.readouterr().err
    assert _snapshot(tmp_path) == before
    assert not (tmp_path / "out" / "run.json").exists()


@pytest.mark.parametrize("step", ["task_from_arguments", "problem_from_task"])
def test_ctrl_c_while_the_problem_is_built_is_one_line(
    step: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Ctrl-C while the robot and scene are loaded, or (the finisher already forked)
    while the problem is built: one line, no folder, no helper process left."""
    import adept_traj.cli.plan as plan_command
    from adept_traj.process_pool import children

    def interrupted(*args):
        raise KeyboardInterrupt

    monkeypatch.setattr(plan_command, step, interrupted)
    assert main([*_RUN, *_LIGHT, "--out", str(tmp_path / "run")]) == 130
    assert capsys.readouterr().err == "adept-traj: plan interrupted\n"
    assert not (tmp_path / "run").exists()
    assert children() == []


# ------------------------------------------------------------------------ atomic writes


def test_a_failed_write_leaves_the_old_file_and_no_temporary_one(tmp_path: Path) -> None:
    path = tmp_path / "result.json"
    path.write_text("old")

    def half(tmp: Path) -> None:
        tmp.write_text("ne")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        write_atomic(path, half)
    assert [p.name for p in tmp_path.iterdir()] == ["result.json"]
    assert path.read_text() == "old"


def test_a_write_is_flushed_to_disk_before_it_counts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The file's content is flushed before the rename, the folder's entry after it."""
    events = []
    real_fsync, real_replace = os.fsync, os.replace
    monkeypatch.setattr(os, "fsync", lambda fd: events.append("fsync") or real_fsync(fd))
    monkeypatch.setattr(os, "replace", lambda a, b: events.append("rename") or real_replace(a, b))
    write_atomic(tmp_path / "a.txt", lambda tmp: tmp.write_text("x"))
    assert events == ["fsync", "rename", "fsync"]
