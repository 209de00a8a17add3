"""TOML reading with errors that name the file (private module)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = ["parse_toml", "read_toml"]


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
