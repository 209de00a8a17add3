"""TOML reading with errors that name the file (private module)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = ["read_toml"]


def read_toml(path: str | Path, error: type[Exception]) -> dict[str, Any]:
    """Parse the TOML file at ``path``; raise ``error`` naming the file on any failure."""
    p = Path(path)
    if not p.is_file():
        raise error(f"{p}: file not found")
    try:
        with p.open("rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{p}: not valid TOML: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise error(f"{p}: cannot be read: {exc}") from None
