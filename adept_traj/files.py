"""File input and output shared by the subpackages: atomic, durable writes (no half-written
file is ever left behind, a finished file survives a crash) and TOML reading with errors
that name the file."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = [
    "parse_toml",
    "read_toml",
    "sync_folder",
    "temp_path",
    "write_atomic",
    "write_text_atomic",
]


def write_atomic(path: Path, writer: Callable[[Path], None]) -> Path:
    """Call ``writer`` on a temporary file beside ``path`` (:func:`temp_path`; folders
    created), flush it to disk, then rename it to ``path`` in one step and flush the folder;
    return ``path``. If anything fails (Ctrl-C included), the temporary file is removed and
    ``path`` is left as it was."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = temp_path(path)
    try:
        writer(tmp)
        _sync_file(tmp)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    sync_folder(path.parent)
    return path


def write_text_atomic(path: Path, text: str) -> Path:
    """Write UTF-8 text (``\\n`` line ends) to ``path`` atomically; return ``path``."""
    return write_atomic(path, lambda tmp: tmp.write_text(text, encoding="utf-8", newline="\n"))


def parse_toml(raw: bytes, source: str, error: type[Exception]) -> dict[str, Any]:
    """Parse TOML bytes; raise ``error`` naming ``source`` (and the line) on failure."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(f"{source}: not UTF-8 text ({exc})") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{source}: invalid TOML: {exc}") from None


def read_toml(
    path: str | Path,
    error: type[Exception],
    *,
    not_found: type[Exception] | None = None,
    what: str = "file",
) -> dict[str, Any]:
    """Read and parse the TOML file at ``path``; raise ``not_found`` (default ``error``) if it
    does not exist and ``error`` naming the file on any other failure."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except FileNotFoundError:
        raise (not_found or error)(f"{p}: {what} not found") from None
    except OSError as exc:
        raise error(f"{p}: cannot read {what}: {exc.strerror or exc}") from None
    return parse_toml(raw, str(p), error)


def temp_path(path: Path) -> Path:
    """The temporary file :func:`write_atomic` writes before renaming it to ``path``
    (``.<name>.tmp`` beside it)."""
    return path.with_name(f".{path.name}.tmp")


def _sync_file(path: Path) -> None:
    """Flush the content of the file at ``path`` to disk (``fsync``)."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def sync_folder(folder: Path) -> None:
    """Flush the entries of ``folder`` (renames, new and removed files) to disk, where the
    system allows it (POSIX; a no-op on Windows)."""
    if os.name != "posix":  # pragma: no cover - folders cannot be opened on Windows
        return
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
