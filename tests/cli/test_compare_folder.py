"""``compare``'s output folder: an earlier compare's files are not replaced without
``--overwrite`` (and only they are), and one process at a time writes into the folder."""

from __future__ import annotations

import fcntl
import os
from pathlib import Path

import pytest

from adept_traj.cli.app import main

_TINY = ["compare", "--gens", "2", "--pop-nsga2", "8", "--pop-mode", "8", "--quiet"]


def _earlier_compare(out: Path) -> dict[Path, bytes]:
    """Files as an earlier compare leaves them, and two of the user's; their contents."""
    files = {
        out / "comparison.md": b"earlier table\n",
        out / "nsga2" / "result.json": b"{}",
        out / "mode" / "front.csv": b"x\n",
        out / "figures" / "pareto_matrix.png": b"png",
        out / "notes.txt": b"the user's\n",
        out / "nsga2" / "mine.txt": b"the user's too\n",
    }
    for path, data in files.items():
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    return files


def test_an_earlier_compare_is_refused_before_any_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "cmp"
    files = _earlier_compare(out)
    assert main([*_TINY, "--no-plots", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "holds files of an earlier compare" in err
    for named in ("comparison.md", "nsga2/result.json", "figures/pareto_matrix.png", "--overwrite"):
        assert named in err
    assert {p: p.read_bytes() for p in files} == files  # nothing touched


def test_overwrite_replaces_only_the_commands_files(tmp_path: Path) -> None:
    out = tmp_path / "cmp"
    files = _earlier_compare(out)
    assert main([*_TINY, "--no-plots", "--overwrite", "--out", str(out)]) == 0
    assert (out / "notes.txt").read_bytes() == files[out / "notes.txt"]
    assert (out / "nsga2" / "mine.txt").read_bytes() == files[out / "nsga2" / "mine.txt"]
    assert (out / "comparison.md").read_bytes() != files[out / "comparison.md"]
    assert (out / "nsga2" / "result.json").stat().st_size > 100  # the new run's
    # the earlier figure is gone (this run drew none): no stale figure beside new results
    assert not (out / "figures" / "pareto_matrix.png").exists()


def test_a_folder_in_use_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "cmp"
    out.mkdir()
    fd = os.open(out, os.O_RDONLY | os.O_DIRECTORY)  # held as another process would
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    try:
        code = main([*_TINY, "--no-plots", "--out", str(out)])
        study = main([*_TINY, "--seeds", "1", "--out", str(out)])
    finally:
        os.close(fd)
    assert code == study == 2
    assert capsys.readouterr().err.count("is in use by another adept-traj process") == 2
    assert list(out.iterdir()) == []


def test_overwrite_does_not_go_with_a_seed_study(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "study"
    assert main([*_TINY, "--seeds", "1", "--overwrite", "--out", str(out)]) == 2
    assert "--overwrite does not go with --seeds" in capsys.readouterr().err
    assert not out.exists()


def test_an_empty_out_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    assert main([*_TINY, "--out", ""]) == 2
    assert "--out is empty" in capsys.readouterr().err
