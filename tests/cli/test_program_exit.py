"""The ``adept-traj`` program (:func:`adept_traj.cli.run`): the command's status, its whole
output and the exit handlers, ending with the interpreter's normal exit, the cyclic
collector stopped and every object frozen first."""

from __future__ import annotations

import gc
import subprocess
import sys
from pathlib import Path

import pytest

import adept_traj.cli
from adept_traj.cli import main

DATA = Path(__file__).resolve().parents[1] / "data"

#: A program that registers an exit handler, then runs ``adept-traj`` with its arguments.
_PROGRAM = (
    "import atexit, sys, threading, time\n"
    "from adept_traj.cli import run\n"
    "atexit.register(lambda: sys.stdout.write('exit handler ran\\n'))\n"
    "if sys.argv[1] == 'thread':\n"
    "    del sys.argv[1]\n"
    "    late = lambda: (time.sleep(2.0), sys.stdout.write('thread ended\\n'))\n"
    "    threading.Thread(target=late, daemon=False).start()\n"
    "sys.exit(run())\n"
)


def _program(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", _PROGRAM, *args], capture_output=True, text=True, timeout=120
    )


def test_the_program_keeps_the_status_the_output_and_the_exit_handlers(tmp_path: Path) -> None:
    """``verify`` of an uncertified result: status 1 (as :func:`main` returns it), every
    line on the pipe, the exit handler run once."""
    assert main(["verify", str(DATA / "result_v1")]) == 1
    done = _program("verify", str(DATA / "result_v1"))
    assert done.returncode == 1
    lines = done.stdout.splitlines()
    assert lines[-1] == "exit handler ran"
    assert lines.count("exit handler ran") == 1
    assert any("NOT FEASIBLE" in line or "not feasible" in line.lower() for line in lines[:-1])
    bad = _program("verify", str(tmp_path / "missing"))
    assert bad.returncode == 2
    assert bad.stderr.startswith("adept-traj: error:")
    assert bad.stdout == "exit handler ran\n"


def test_the_console_script_is_the_program() -> None:
    import tomllib

    pyproject = tomllib.loads((DATA.parents[1] / "pyproject.toml").read_text())
    assert pyproject["project"]["scripts"]["adept-traj"] == "adept_traj.cli:run"
    assert adept_traj.cli.run is adept_traj.cli.app.run


def test_a_thread_still_running_gets_the_normal_exit(tmp_path: Path) -> None:
    """A thread of the caller's still running when the command returns is waited for (the
    interpreter's normal exit), not cut short."""
    done = _program("thread", "verify", str(tmp_path / "missing"))
    assert done.returncode == 2
    assert done.stdout.splitlines()[-2:] == ["thread ended", "exit handler ran"]


def test_the_program_ends_with_system_exit_and_the_collector_frozen(
    tmp_path: Path, monkeypatch
) -> None:
    """``run`` raises ``SystemExit`` with the command's status (the interpreter's normal
    exit follows), the collector stopped and the objects frozen."""
    monkeypatch.setattr(sys, "argv", ["adept-traj", "verify", str(tmp_path / "missing")])
    enabled, frozen = gc.isenabled(), gc.get_freeze_count()
    gc.collect()
    try:
        with pytest.raises(SystemExit) as info:
            adept_traj.cli.run()
        assert info.value.code == 2
        assert not gc.isenabled()
        assert gc.get_freeze_count() > frozen
    finally:
        gc.unfreeze()
        if enabled:
            gc.enable()
