"""Atomic file writes (private module): no half-written file is ever left behind."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

__all__ = ["write_atomic", "write_text_atomic"]


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
