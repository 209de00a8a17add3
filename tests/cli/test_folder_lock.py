"""One process at a time in a run folder: ``plan`` holds the folder while it runs, so that
``plan --resume`` (or ``--overwrite``) of a run still going on is refused before it writes
anything."""

from __future__ import annotations

import fcntl
import os
from pathlib import Path

import pytest

from adept_traj.cli._run_folder import folder_lock
from adept_traj.cli.app import main
from adept_traj.errors import ConfigurationError
from adept_traj.testing.cycle_files import HOME, PLACE, cycle_text, write_cycle

_TINY = ["plan", "--pop", "8", "--gens", "2", "--quiet", "--no-html", "--no-plots"]


def _held_elsewhere(folder: Path) -> int:
    """A descriptor holding ``folder``'s lock as another process would (flock locks belong
    to the open file, so a second open in this process conflicts like another process)."""
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    return fd


def test_a_folder_in_use_is_refused_before_anything_is_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "run"
    out.mkdir()
    fd = _held_elsewhere(out)
    try:
        code = main([*_TINY, "--out", str(out)])
    finally:
        os.close(fd)
    assert code == 2
    assert "is in use by another adept-traj process" in capsys.readouterr().err
    assert list(out.iterdir()) == []


def test_the_lock_is_released_when_the_block_ends(tmp_path: Path) -> None:
    out = tmp_path / "new" / "run"
    with folder_lock(out):
        assert out.is_dir()
        with pytest.raises(ConfigurationError, match="in use"), folder_lock(out):
            pass
    os.close(_held_elsewhere(out))  # free again


_CYCLE = cycle_text(
    "one",
    scene="empty.toml",
    locations={"home": {"joints": HOME}, "place": {"joints": PLACE}},
    moves=[("home", "place")],
)


def test_cycle_holds_its_folder_too(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``cycle --resume`` started twice on one folder: the second is refused unwritten."""
    write_cycle(tmp_path, _CYCLE)
    out = tmp_path / "out"
    out.mkdir()
    fd = _held_elsewhere(out)
    try:
        code = main(["cycle", str(tmp_path / "c.toml"), "--out", str(out), "--resume", "--quiet"])
        empty = main(["cycle", str(tmp_path / "c.toml"), "--out", "", "--quiet"])
    finally:
        os.close(fd)
    assert code == empty == 2
    err = capsys.readouterr().err
    assert "is in use by another adept-traj process" in err
    assert "--out is empty" in err
    assert list(out.iterdir()) == []
