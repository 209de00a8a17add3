"""File input and output shared by the subpackages: atomic writes (no half-written file is
ever left behind) and TOML reading with errors that name the file."""

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

__all__ = ["parse_toml", "read_toml", "write_atomic", "write_text_atomic"]


def write_atomic(path: Path, writer: Callable[[Path], None]) -> Path:
    """Call ``writer`` on a temporary file beside ``path`` (folders created), then rename it
    to ``path`` in one step; return ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    writer(tmp)
    os.replace(tmp, path)
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
