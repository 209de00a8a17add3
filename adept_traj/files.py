"""File input and output shared by the subpackages: atomic, durable writes (no half-written
file is ever left behind, a finished file survives a crash), and bounded reading of TOML and
JSON with errors that name the file.

Every file the library reads goes through :func:`read_bytes_bounded` (at most
:data:`MAX_FILE_BYTES`, read in chunks, so ``/dev/zero`` or a 10 GB file is refused at
once) and its text through :func:`check_nesting` (at most :data:`MAX_NESTING` levels of
arrays and tables, counted without recursion) before a parser sees it: a hostile file gives
the caller's error naming the file and the limit, never a ``RecursionError`` or
``MemoryError``."""

from __future__ import annotations

import json
import math
import os
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

__all__ = [
    "MAX_FILE_BYTES",
    "MAX_NESTING",
    "check_nesting",
    "parse_json",
    "parse_toml",
    "read_bytes_bounded",
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
    """Parse TOML bytes; raise ``error`` naming ``source`` (and the line) on failure.

    ``raw`` longer than :data:`MAX_FILE_BYTES` or nested deeper than :data:`MAX_NESTING`
    (inline arrays and tables, or dotted keys and table headers) is refused with ``error``.
    """
    text = _decode(raw, source, error)
    check_nesting(text, source, error, kind="toml")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{source}: invalid TOML: {exc}") from None
    _check_depth(data, source, error)
    return data


def read_toml(
    path: str | Path,
    error: type[Exception],
    *,
    not_found: type[Exception] | None = None,
    what: str = "file",
) -> dict[str, Any]:
    """Read and parse the TOML file at ``path``; raise ``not_found`` (default ``error``) if it
    does not exist and ``error`` naming the file on any other failure (among them a file
    larger than :data:`MAX_FILE_BYTES` or nested deeper than :data:`MAX_NESTING`)."""
    raw = read_bytes_bounded(path, error, not_found=not_found, what=what)
    return parse_toml(raw, str(Path(path)), error)


# ============================================================================ bounded reading
#: Largest file the library reads [B] (64 MiB): a scene of :data:`~adept_traj.scene.MAX_OBSTACLES`
#: obstacles is about 2 MiB, the result.json of a population of 5 000 about 20 MiB.
MAX_FILE_BYTES = 64 * 2**20
#: Deepest nesting of arrays, objects and tables accepted in a JSON or TOML file: the
#: library's own files nest at most 5 levels; Python's parsers recurse per level.
MAX_NESTING = 64

_CHUNK_BYTES = 2**20

#: What is not structure: strings (JSON; TOML's four kinds) and TOML comments. Matched from
#: the left in one pass, so a bracket or ``#`` inside a string is never counted.
_JSON_SKIP = re.compile(rb'"(?:[^"\\]|\\.)*"', re.DOTALL)
_TOML_SKIP = re.compile(
    rb'"""(?:[^\\]|\\.)*?"""|\'\'\'.*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'|#[^\n]*',
    re.DOTALL,
)


def read_bytes_bounded(
    path: str | os.PathLike[str],
    error: type[Exception],
    *,
    not_found: type[Exception] | None = None,
    what: str = "file",
    limit: int = MAX_FILE_BYTES,
) -> bytes:
    """The bytes of the file at ``path``, read in chunks of 1 MiB and at most ``limit``
    [B] (default :data:`MAX_FILE_BYTES`).

    Raises ``not_found`` (default ``error``) if the file does not exist and ``error``
    naming the file on any other failure, among them a file (or a device such as
    ``/dev/zero``) longer than ``limit``: its size is checked before reading when the
    system knows it, and the reading stops at ``limit + 1`` bytes otherwise.
    """
    p = Path(path)
    too_big = f"{p}: {what} larger than the limit of {limit} bytes (MAX_FILE_BYTES); refused"
    try:
        with open(p, "rb") as f:
            if os.fstat(f.fileno()).st_size > limit:
                raise error(too_big)
            chunks, total = [], 0
            while chunk := f.read(min(_CHUNK_BYTES, limit + 1 - total)):
                chunks.append(chunk)
                total += len(chunk)
                if total > limit:
                    raise error(too_big)
    except FileNotFoundError:
        raise (not_found or error)(f"{p}: {what} not found") from None
    except IsADirectoryError:
        raise error(f"{p}: is a folder, not a {what}") from None
    except OSError as exc:
        raise error(f"{p}: cannot read {what}: {exc.strerror or exc}") from None
    return b"".join(chunks)


def check_nesting(
    text: str | bytes,
    source: str,
    error: type[Exception],
    *,
    kind: str = "json",
    limit: int = MAX_NESTING,
) -> int:
    """The deepest nesting of ``[``/``{`` in ``text`` outside strings (and, for
    ``kind="toml"``, comments); raise ``error`` naming ``source`` if it exceeds ``limit``
    (default :data:`MAX_NESTING`).

    A scan, not a parse: no recursion, and linear in the length of ``text`` (strings and
    comments are removed by one regular expression, the depth is a cumulative sum).
    """
    raw = text.encode("utf-8") if isinstance(text, str) else bytes(text)
    if len(raw) > MAX_FILE_BYTES:
        raise error(f"{source}: {len(raw)} bytes, more than the limit of {MAX_FILE_BYTES} bytes")
    skip = _TOML_SKIP if kind == "toml" else _JSON_SKIP
    code = np.frombuffer(skip.sub(b"", raw), dtype=np.uint8)
    step = np.isin(code, (ord("["), ord("{"))).astype(np.int64)
    step -= np.isin(code, (ord("]"), ord("}")))
    depth = int(np.cumsum(step).max(initial=0))
    if depth > limit:
        raise error(
            f"{source}: nested {depth} levels deep, more than the limit of {limit} (MAX_NESTING)"
        )
    return depth


def _check_depth(data: Any, source: str, error: type[Exception], limit: int = MAX_NESTING) -> None:
    """Raise ``error`` if the parsed ``data`` (dicts and lists) nests deeper than ``limit``
    (dotted TOML keys nest without brackets); an explicit stack, no recursion."""
    stack = [(data, 1)]
    while stack:
        node, depth = stack.pop()
        if depth > limit:
            raise error(f"{source}: nested more than {limit} levels deep (MAX_NESTING)")
        children = node.values() if isinstance(node, dict) else node
        stack.extend((c, depth + 1) for c in children if isinstance(c, dict | list))


def _decode(raw: bytes, source: str, error: type[Exception]) -> str:
    if len(raw) > MAX_FILE_BYTES:
        raise error(f"{source}: {len(raw)} bytes, more than the limit of {MAX_FILE_BYTES} bytes")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise error(f"{source}: not UTF-8 text ({exc})") from None


def parse_json(raw: bytes, source: str, error: type[Exception]) -> Any:
    """Parse JSON bytes (UTF-8); raise ``error`` naming ``source`` on failure.

    Refused: more than :data:`MAX_FILE_BYTES`, nesting deeper than :data:`MAX_NESTING`
    (checked by :func:`check_nesting` before parsing: no ``RecursionError``), ``NaN`` and
    ``Infinity``, and numbers that overflow to infinity (``1e400``): the library writes
    every infinite value as ``null``, so a non-finite number is never a value it wrote.
    """
    text = _decode(raw, source, error)
    check_nesting(text, source, error, kind="json")

    def constant(name: str) -> float:
        raise error(f"{source}: {name} is not a JSON number (the files write ±inf as null)")

    def finite(literal: str) -> float:
        value = float(literal)
        if not math.isfinite(value):
            raise error(f"{source}: the number {literal} is not finite (beyond ±1.8e308)")
        return value

    try:
        return json.loads(text, parse_constant=constant, parse_float=finite)
    except json.JSONDecodeError as exc:
        raise error(
            f"{source}: not valid JSON: {exc.msg} (line {exc.lineno}, column {exc.colno})"
        ) from None


# ============================================================================ durable writes
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
