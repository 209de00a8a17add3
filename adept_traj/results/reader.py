"""Reading the files of a result folder, with errors that name the file and the field.

- ``_read_text(path)``: the UTF-8 text of a file (missing, unreadable or not UTF-8:
  :class:`~adept_traj.errors.ResultFormatError`).
- ``_Reader``: the one schema reader of ``result.json``. A node of the parsed JSON holds its
  value and its dotted path (``front[3].x``, ``certificate.velocity.dense``); its typed
  accessors (``string``, ``integer``, ``number``, ``array``, …) check the value and raise
  :class:`~adept_traj.errors.ResultFormatError` naming the file and that path.

Used by :mod:`~adept_traj.results.json_codec` and :mod:`~adept_traj.results.csv_codec`.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.errors import AdeptTrajError, ResultFormatError

__all__: list[str] = []


class _Reader:
    """One node of the parsed ``result.json``: its value and its dotted path (``where``),
    with typed accessors that raise :class:`ResultFormatError` naming file and field."""

    def __init__(self, file: Path, value: Any, where: str = "") -> None:
        self.file, self.value, self.where = file, value, where

    @classmethod
    def open(cls, path: Path) -> _Reader:
        """The top node of the JSON file at ``path`` (NaN and Infinity refused)."""

        def reject(constant: str) -> Any:
            raise ResultFormatError(path, None, f"holds {constant}, which JSON does not allow")

        try:
            return cls(path, json.loads(_read_text(path), parse_constant=reject))
        except json.JSONDecodeError as exc:
            raise ResultFormatError(
                path, None, f"not valid JSON: {exc.msg} (line {exc.lineno}, column {exc.colno})"
            ) from None

    def error(self, message: str, where: str | None = None) -> ResultFormatError:
        return ResultFormatError(self.file, where or self.where or None, message)

    def kind(self) -> str:
        """What the value is, for messages: ``"null"``, ``"a list"``, ``"the number 3"``."""
        v = self.value
        if v is None:
            return "null"
        names = {bool: "a boolean", str: "a string", list: "a list", dict: "an object"}
        for t, name in names.items():
            if isinstance(v, t):
                return f"{name} ({str(v)[:40]!r})" if t is str else name
        return f"the number {v!r}" if isinstance(v, (int, float)) else type(v).__name__

    # ------------------------------------------------------------------ structure
    def obj(self) -> dict[str, Any]:
        if not isinstance(self.value, dict):
            raise self.error(f"expected an object; got {self.kind()}", self.where or "(top level)")
        return self.value

    def child(self, key: str, *, optional: bool = False) -> _Reader:
        """The node at ``key`` (missing: an error, or a null node when ``optional``)."""
        table, path = self.obj(), f"{self.where}.{key}" if self.where else key
        if key not in table and not optional:
            raise self.error("missing", path)
        return _Reader(self.file, table.get(key), path)

    __getitem__ = child

    def items(self, what: str = "a list") -> list[_Reader]:
        if not isinstance(self.value, list):
            raise self.error(f"expected {what}; got {self.kind()}")
        return [_Reader(self.file, v, f"{self.where}[{i}]") for i, v in enumerate(self.value)]

    def build(self, make: Callable[..., Any], *args: Any, **kw: Any) -> Any:
        """Call a constructor, turning its input errors into ResultFormatError here."""
        try:
            return make(*args, **kw)
        except (AdeptTrajError, ValueError, TypeError) as exc:
            raise self.error(str(exc)) from None

    # ------------------------------------------------------------------ values
    def string(self, *, nullable: bool = False) -> Any:
        if self.value is None and nullable:
            return None
        if not isinstance(self.value, str):
            raise self.error(f"expected a string; got {self.kind()}")
        return self.value

    def strings(self) -> tuple[str, ...]:
        return tuple(item.string() for item in self.items("a list of strings"))

    def integer(self, *, nullable: bool = False) -> Any:
        v = self.value
        if v is None and nullable:
            return None
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.error(f"expected an integer; got {self.kind()}")
        return v

    def boolean(self) -> bool:
        if not isinstance(self.value, bool):
            raise self.error(f"expected true or false; got {self.kind()}")
        return self.value

    def number(self, *, null: float | None = None) -> Any:
        """A float; ``null`` maps JSON null to that value (``None``: null is an error)."""
        v = self.value
        if v is None:
            if null is None:
                raise self.error("expected a number; got null")
            return null
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise self.error(f"expected a number; got {self.kind()}")
        return float(v)

    def optional_number(self) -> float | None:
        return None if self.value is None else self.number()

    def array(self, shape: tuple[int | None, ...], *, null: float | None = None) -> np.ndarray:
        """A read-only float array of ``len(shape)`` (1 or 2) dimensions; None: any length.

        A well-formed list is converted in one step; anything else is walked item by item
        so that the error names the first bad entry."""
        arr = self._well_formed(shape, null)
        if arr is None:
            arr = self._walk(shape, null)
        arr.flags.writeable = False
        return arr

    def _walk(self, shape: tuple[int | None, ...], null: float | None) -> np.ndarray:
        """:meth:`array` item by item: raises at the first bad entry."""
        if len(shape) == 1:
            return np.array(self._row(shape[0], null), dtype=float)
        rows = self.items("a list of rows")
        if shape[0] is not None and len(rows) != shape[0]:
            raise self.error(f"expected {shape[0]} rows; got {len(rows)}")
        width, table = shape[1], []
        for row in rows:
            table.append(row._row(width, null))
            width = len(table[-1])
        return np.array(table, dtype=float).reshape(len(table), width or 0)

    def _well_formed(self, shape: tuple[int | None, ...], null: float | None) -> Any:
        """The array when the value is a list (of rows) of the expected shape holding only
        JSON numbers (and nulls when ``null`` is given); ``None`` otherwise."""
        if not isinstance(self.value, list):
            return None
        try:
            cells = np.array(self.value, dtype=object)
        except ValueError:  # ragged
            return None
        if cells.ndim != len(shape) or any(
            want is not None and got != want for got, want in zip(cells.shape, shape, strict=True)
        ):
            return None
        flat = cells.ravel()
        allowed = {int, float} if null is None else {int, float, type(None)}
        if not set(map(type, flat)) <= allowed:  # bool is a type of its own: refused
            return None
        if null is not None:
            flat = np.where(np.equal(flat, None), null, flat)
        return np.array(flat, dtype=float).reshape(cells.shape)

    def _row(self, size: int | None, null: float | None) -> list[float]:
        items = self.items("a list of numbers")
        if size is not None and len(items) != size:
            raise self.error(f"expected {size} numbers; got {len(items)}")
        return [item.number(null=null) for item in items]


def _read_text(path: Path) -> str:
    """The UTF-8 text of a file of the result folder (ResultFormatError if unreadable)."""
    try:
        return path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ResultFormatError(path, None, "missing file") from None
    except UnicodeDecodeError as exc:
        raise ResultFormatError(path, None, f"not UTF-8 text ({exc.reason})") from None
    except OSError as exc:
        raise ResultFormatError(path, None, f"cannot read: {exc.strerror or exc}") from None
