"""Damaged checkpoints: ``plan --resume`` and ``plan(..., resume=True)`` refuse them.

Each checkpoint is real: written by a small run (NSGA-II, population 8, 2 generations)
stopped by Ctrl-C after its first generation, then damaged here with NumPy and plain file
writes (truncated, not a zip file, an array of the wrong shape or dtype, an array
missing). The run must end with :class:`CheckpointFormatError` naming the file (the
command: one line, exit status 2, no traceback) before any generation runs: the checkpoint
is left as it was and no result is written.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import adept_traj.optimise as optimise  # cli.plan runs its plan (imported on use)
from adept_traj import plan
from adept_traj.cli import main
from adept_traj.errors import CheckpointFormatError, ConfigurationError, PlanningInterrupted

_RUN = ["plan", "--pop", "8", "--gens", "2", "--rate", "1500", "--quiet", "--no-html"]


def _stop_after_first(progress: Callable | None) -> Callable:
    """A progress callback that reports to ``progress`` and presses Ctrl-C after the first
    generation."""

    def stopping(info) -> None:
        if progress is not None:
            progress(info)
        if info.generation == 1:
            raise KeyboardInterrupt

    return stopping


@pytest.fixture(scope="module")
def cli_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run folder of ``adept-traj plan`` stopped after generation 1 of 2."""
    folder = tmp_path_factory.mktemp("cli") / "run"
    real = optimise.plan

    def stopped(*args, progress=None, **kwargs):
        return real(*args, progress=_stop_after_first(progress), **kwargs)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(optimise, "plan", stopped)
        assert main([*_RUN, "--no-plots", "--out", str(folder)]) == 130
    assert (folder / "checkpoint" / "checkpoint.npz").is_file()
    assert (folder / "run.json").is_file()
    return folder


@pytest.fixture(scope="module")
def library_run(problem, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A checkpoint folder of ``adept_traj.plan`` stopped after generation 1 of 2."""
    folder = tmp_path_factory.mktemp("library") / "checkpoint"
    with pytest.raises(PlanningInterrupted, match="after generation 1"):
        _plan(problem, folder, resume=False, progress=_stop_after_first(None))
    # a mixed population: ranks for the feasible members only (data.rank with absent.rank)
    assert {"data.rank", "absent.rank", "loop.fronts"} <= set(_arrays(folder / "checkpoint.npz"))
    return folder


def _plan(problem, folder: Path, resume: bool, progress: Callable):
    return plan(
        problem, "nsga2", seed=1, pop_size=8, n_gen=2, checkpoint=folder, resume=resume,
        progress=progress, polish="off",
    )  # fmt: skip


def _arrays(path: Path) -> dict[str, np.ndarray]:
    with np.load(path, allow_pickle=False) as data:
        return {key: data[key] for key in data.files}


def _rewritten(change: Callable[[dict[str, np.ndarray]], None]) -> Callable[[Path], None]:
    """A damage: the file's arrays read, changed in place by ``change``, written back."""

    def damage(path: Path) -> None:
        arrays = _arrays(path)
        change(arrays)
        with path.open("wb") as fh:
            np.savez(fh, **arrays)

    return damage


def _truncated(path: Path) -> None:
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])


def _cut_tail(path: Path) -> None:
    path.write_bytes(path.read_bytes()[:-100])  # the zip's central directory lost


def _garbage(path: Path) -> None:
    path.write_bytes(b"this is not a checkpoint\n" * 40)


def _empty(path: Path) -> None:
    path.write_bytes(b"")


def _set(key: str, value: Callable[[np.ndarray], np.ndarray]):
    return _rewritten(lambda a: a.__setitem__(key, value(a[key])))


def _drop(key: str):
    return _rewritten(lambda a: a.pop(key))


#: (damage, the array the error must name, or None for the whole file)
DAMAGES = {
    "truncated": (_truncated, None),
    "tail cut off": (_cut_tail, None),
    "garbage": (_garbage, None),
    "empty": (_empty, None),
    "X has too few columns": (_set("X", lambda x: x[:, :-3]), "X"),
    "F has too few rows": (_set("F", lambda f: f[:-2]), "F"),
    "G is 1-D": (_set("G", lambda g: g[:, 0]), "G"),
    "data.rank is short": (_set("data.rank", lambda r: r[:3]), "data.rank"),
    "loop.fronts is 1-D": (_set("loop.fronts", lambda f: f.ravel()), "loop.fronts"),
    "X is float32": (_set("X", lambda x: x.astype(np.float32)), "X"),
    "CV is int": (_set("CV", lambda c: c.astype(np.int64)), "CV"),
    "absent.rank is float": (_set("absent.rank", lambda m: m.astype(float)), "absent.rank"),
    "n_iter is text": (_set("n_iter", lambda n: np.array(str(n))), "n_iter"),
    "meta is bytes": (_set("meta", lambda m: np.array(str(m).encode())), "meta"),
    "X missing": (_drop("X"), None),
    "data.rank missing": (_drop("data.rank"), "data.rank"),
    "absent.rank missing": (_drop("absent.rank"), "absent.rank"),
    "loop.front_sizes missing": (_drop("loop.front_sizes"), "loop.front_sizes"),
    "meta missing": (_drop("meta"), "meta"),
}


@pytest.mark.parametrize("kind", list(DAMAGES))
def test_plan_refuses_a_damaged_checkpoint(kind: str, problem, library_run: Path, tmp_path):
    damage, array = DAMAGES[kind]
    folder = tmp_path / "checkpoint"
    shutil.copytree(library_run, folder)
    npz = folder / "checkpoint.npz"
    damage(npz)
    before = npz.read_bytes()
    ran: list[int] = []
    with pytest.raises(CheckpointFormatError) as caught:
        _plan(problem, folder, resume=True, progress=lambda info: ran.append(info.generation))
    assert isinstance(caught.value, ConfigurationError)  # what callers caught before
    assert caught.value.file == str(npz)
    assert str(npz) in str(caught.value)
    assert caught.value.array == array
    assert ran == []  # no generation ran
    assert npz.read_bytes() == before
    assert [p.name for p in folder.iterdir()] == ["checkpoint.npz"]


@pytest.mark.parametrize("kind", ["truncated", "garbage", "X has too few columns",
                                  "X is float32", "data.rank missing"])  # fmt: skip
def test_plan_resume_refuses_a_damaged_checkpoint_in_one_line(
    kind: str, cli_run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = tmp_path / "run"
    shutil.copytree(cli_run, folder)
    npz = folder / "checkpoint" / "checkpoint.npz"
    DAMAGES[kind][0](npz)
    before = sorted((p.name, p.read_bytes()) for p in folder.rglob("*") if p.is_file())
    capsys.readouterr()
    assert main(["plan", "--resume", str(folder), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert err.startswith(f"adept-traj: error: {npz}: damaged checkpoint"), err
    assert "Traceback" not in err
    after = sorted((p.name, p.read_bytes()) for p in folder.rglob("*") if p.is_file())
    assert after == before  # nothing ran: no result, the checkpoint and run.json as they were


def test_the_undamaged_checkpoint_resumes(problem, library_run: Path, tmp_path: Path) -> None:
    """The same checkpoint, not damaged, resumes to the end (the refusals above are due to
    the damage alone)."""
    folder = tmp_path / "checkpoint"
    shutil.copytree(library_run, folder)
    ran: list[int] = []
    _plan(problem, folder, resume=True, progress=lambda info: ran.append(info.generation))
    assert ran == [2]


@pytest.mark.slow
def test_the_undamaged_run_folder_resumes(cli_run: Path, tmp_path: Path) -> None:
    run = tmp_path / "run"
    shutil.copytree(cli_run, run)
    assert main(["plan", "--resume", str(run), "--quiet"]) == 0
    assert (run / "result.json").is_file()
    assert not (run / "checkpoint").exists()
