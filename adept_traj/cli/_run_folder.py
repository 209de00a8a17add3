"""The result folder of ``adept-traj plan``: which files are the command's, whether a folder
may be written, and the saved arguments of a run in progress.

A folder goes through three states, told apart by two files:

- **in progress** — ``run.json`` (the run's arguments) is present; ``checkpoint/`` holds
  the last finished generation (none before the first), and result files may be present
  from a save that was interrupted. ``plan --resume DIR`` continues it.
- **complete** — ``run.json`` is absent and ``result.json`` present. Removing ``run.json``
  (flushed to disk) is the last step of a run, after every other file is written, so a
  complete folder has all its files.
- **new** — none of the command's files.

Only the files listed here are ever removed (``--overwrite``); anything else in the folder
is the user's and is left alone.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from adept_traj.errors import ConfigurationError, InvalidInputError
from adept_traj.files import (
    parse_json,
    read_bytes_bounded,
    sync_folder,
    temp_path,
    write_text_atomic,
)
from adept_traj.results import FRONT_FILE, RESULT_FILE, TRAJECTORY_FILE

__all__ = [
    "CHECKPOINT",
    "EXPLORER_FILE",
    "FIGURES",
    "HTML_FILE",
    "RUN_FILE",
    "TOP_FILES",
    "as_path",
    "check_folder",
    "check_ros_path",
    "commit",
    "is_complete",
    "read_arguments",
    "remove_written",
    "write_arguments",
    "written_files",
]

#: The arguments of a run in progress, in its result folder (removed when it completes).
RUN_FILE = "run.json"
#: The folder of the last finished generation's checkpoint.
CHECKPOINT = "checkpoint"
#: The static meshcat playback.
HTML_FILE = "playback.html"
#: The front explorer, written with ``playback.html`` (:mod:`adept_traj.viz.explorer`).
EXPLORER_FILE = "explorer.html"
#: The folder of the figures.
FIGURES = "figures"
#: The files ``plan`` writes at the top of its folder.
TOP_FILES = (
    RESULT_FILE,
    FRONT_FILE,
    TRAJECTORY_FILE,
    HTML_FILE,
    EXPLORER_FILE,
    RUN_FILE,
    "collision_matrix.srdf",
)
#: The names of the figures ``plan`` writes (``<name>``: the algorithm).
_FIGURE_NAMES = (
    "pareto_matrix.png",
    "best_tradeoffs.png",
    "hypervolume_history.png",
    "joint_motion_*.png",
    "tool_path_*.png",
)


def as_path(text: str | None, option: str) -> Path | None:
    """The path of a folder or file option (``None`` stays ``None``), refused if empty or
    with a NUL character (:class:`InvalidInputError`: ``Path("")`` would be the current
    folder)."""
    if text is None:
        return None
    if not str(text).strip():
        raise InvalidInputError(f"{option} is empty; give a path, e.g. {option} results/run1")
    if "\0" in str(text):
        raise InvalidInputError(f"{option} {str(text)!r} is not a valid path (NUL character)")
    return Path(text)


def written_files(folder: Path) -> list[Path]:
    """The files and folders of ``folder`` that ``plan`` writes (with their temporary
    files), those that exist, sorted."""
    found: set[Path] = set()
    for name in TOP_FILES:
        found.update(p for p in (folder / name, temp_path(folder / name)) if p.exists())
    if (folder / CHECKPOINT).is_dir():
        found.add(folder / CHECKPOINT)
    if (folder / FIGURES).is_dir():
        for pattern in _FIGURE_NAMES:
            for path in (folder / FIGURES).glob(pattern):
                found.add(path)
            for path in (folder / FIGURES).glob(f".{pattern}.tmp"):
                found.add(path)
    return sorted(found)


def check_folder(folder: Path, *, overwrite: bool, html: bool, figures: bool) -> None:
    """Refuse a result folder before anything is written into it.

    Raises
    ------
    ConfigurationError
        ``folder`` holds files of an earlier run and ``overwrite`` is false.
    InvalidInputError
        ``folder`` is a file, cannot be created or written, or one of its output paths is
        taken by something else (e.g. a folder named ``result.json``).
    """
    if folder.exists() and not folder.is_dir():
        raise InvalidInputError(f"--out {folder} is a file, not a folder")
    existing = folder
    while not existing.exists():  # the run creates the missing folders
        existing = existing.parent
    if not existing.is_dir():
        raise InvalidInputError(f"--out {folder}: {existing} is not a folder")
    if not _writable(existing):
        raise InvalidInputError(f"--out {folder}: cannot write in {existing}")
    outputs = [
        folder / name for name in TOP_FILES if html or name not in (HTML_FILE, EXPLORER_FILE)
    ]
    taken = [p for p in outputs if p.exists() and not p.is_file()]
    if (folder / CHECKPOINT).exists() and not (folder / CHECKPOINT).is_dir():
        taken.append(folder / CHECKPOINT)
    if figures and (folder / FIGURES).exists() and not (folder / FIGURES).is_dir():
        taken.append(folder / FIGURES)
    if taken:
        raise InvalidInputError(f"--out {folder}: {', '.join(map(str, taken))} is in the way")
    written = written_files(folder)
    if written and not overwrite:
        names = ", ".join(str(p.relative_to(folder)) for p in written)
        hint = f"--resume {folder} continues it, " if (folder / RUN_FILE).is_file() else ""
        raise ConfigurationError(
            f"--out {folder} holds files of another run ({names}); {hint}--overwrite replaces "
            "them, or choose another folder"
        )


def _writable(folder: Path) -> bool:
    return os.access(folder, os.W_OK | os.X_OK)


def remove_written(folder: Path) -> list[Path]:
    """Remove the files of an earlier run from ``folder`` (:func:`written_files`, and the
    figures folder if that leaves it empty); return what was removed."""
    removed = written_files(folder)
    for path in removed:
        if path.is_dir():
            shutil.rmtree(path)
        else:
            path.unlink()
    figures = folder / FIGURES
    if figures.is_dir() and not any(figures.iterdir()):
        figures.rmdir()
    if removed:
        sync_folder(folder)
    return removed


def is_complete(folder: Path) -> bool:
    """Whether ``folder`` holds a complete run (``result.json`` and no ``run.json``)."""
    return (folder / RESULT_FILE).is_file() and not (folder / RUN_FILE).exists()


def write_arguments(folder: Path, saved: dict[str, Any]) -> None:
    """Start a run: write its arguments (JSON-ready) as :data:`RUN_FILE`, atomically."""
    write_text_atomic(folder / RUN_FILE, json.dumps(saved, indent=1))


def read_arguments(folder: Path) -> dict[str, Any]:
    """The arguments of the run in progress in ``folder``.

    Raises
    ------
    ConfigurationError
        No run in progress there, or an unreadable :data:`RUN_FILE` (among them one larger
        than :data:`~adept_traj.files.MAX_FILE_BYTES`, nested deeper than
        :data:`~adept_traj.files.MAX_NESTING`, or holding a non-finite number).
    """
    run_file = folder / RUN_FILE
    if not run_file.is_file():
        raise ConfigurationError(f"{folder}: no interrupted run here ({RUN_FILE})")
    raw = read_bytes_bounded(run_file, ConfigurationError, what="run arguments")
    saved = parse_json(raw, str(run_file), ConfigurationError)
    if not isinstance(saved, dict):
        raise ConfigurationError(f"{run_file}: not the arguments of a run")
    return saved


def commit(folder: Path) -> None:
    """Mark the run in ``folder`` complete: remove :data:`RUN_FILE` (flushed to disk), then
    the checkpoint. Call it after every other file is written."""
    (folder / RUN_FILE).unlink(missing_ok=True)
    sync_folder(folder)
    shutil.rmtree(folder / CHECKPOINT, ignore_errors=True)


@contextlib.contextmanager
def folder_lock(folder: Path) -> Iterator[None]:
    """Hold the run folder ``folder`` (made if missing) for one process while the block
    runs: another ``adept-traj`` process on it (``plan --resume`` or ``--overwrite`` while
    the run goes on) gets a :class:`~adept_traj.errors.ConfigurationError` instead of
    writing beside it. An advisory ``flock(2)`` on the folder itself (nothing is written
    into it), released when the block ends and every process forked in it has ended."""
    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise ConfigurationError(
                f"{folder} is in use by another adept-traj process (its run is still going "
                "on): wait for it to end, or stop it, then try again"
            ) from None
        yield
    finally:
        os.close(fd)


def check_ros_path(path: Path, folder: Path) -> None:
    """Refuse a ``--ros`` file that cannot be written, before the run starts."""
    if path.is_dir():
        raise InvalidInputError(f"--ros {path} is a folder; give a file, e.g. {path}/best.json")
    parent = path.parent
    while not parent.exists():  # the export creates missing folders
        parent = parent.parent
    if not parent.is_dir():
        raise InvalidInputError(f"--ros {path}: {parent} is not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InvalidInputError(f"--ros {path}: cannot write in {parent}")
    target, root = path.resolve(), folder.resolve()
    if target in {root / name for name in TOP_FILES} or root / CHECKPOINT in target.parents:
        raise InvalidInputError(f"--ros {path} is a file of the result folder {folder}")
