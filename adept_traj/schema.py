"""One reader for the parsed documents of the package: ``result.json``, robot parameter files
and scene files.

A :class:`Node` is one value of a parsed document (the tree of dicts and lists that ``json``
or ``tomllib`` returns) with the file it came from and its dotted path (``front[3].x``,
``joint[1].jerk``). Its typed accessors check the value and return it normalised (floats,
read-only arrays, tuples of strings). On failure they raise the caller's own exception
class, made by an :data:`ErrorFactory` from the file, the field path and a message that
says what was found and what is valid::

    scenes/my.toml: field 'obstacle[0].size[1]': must be a finite number > 0 [m];
    got -0.2 (in obstacle 'cube1')

(one line in a real message).

- ``node["key"]`` never fails on an absent key: it returns an *absent* node, and the
  accessor then raises ``missing`` unless it is given a ``default``.
- ``null`` (JSON only) is refused unless the accessor is told what it means (``null=``).
- Entries of an array of tables that have a ``name`` are labelled with it (``(in obstacle
  'cube1')``); the path still gives their 0-based position.

Used by :mod:`adept_traj.results.json_codec`, :mod:`adept_traj.robot.parameter_file` and
:mod:`adept_traj.scene.scene_file`, each with its own exception class
(:class:`~adept_traj.errors.ResultFormatError`, :class:`~adept_traj.errors.RobotModelError`,
:class:`~adept_traj.errors.SceneError`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Iterable, Mapping, Sequence
from typing import Any

import numpy as np

from adept_traj.errors import AdeptTrajError
from adept_traj.files import parse_json

__all__ = ["ErrorFactory", "Node", "error_factory"]

#: Makes the exception of a bad document from ``(file, field, message)``; ``field`` is the
#: dotted path of the offending value, or ``None`` when the whole file is at fault.
#: :class:`~adept_traj.errors.ResultFormatError` is one; :func:`error_factory` makes one
#: for an exception class that takes a single message.
ErrorFactory = Callable[[str, "str | None", str], Exception]


class _Absent:
    """The value of a key that the document does not have (and "no default given")."""

    def __repr__(self) -> str:
        return "<absent>"


_ABSENT: Any = _Absent()


def error_factory(cls: Callable[[str], Exception]) -> ErrorFactory:
    """The :data:`ErrorFactory` for an exception class whose constructor takes one message:
    ``cls("{file}: field '{field}': {message}")`` (``"{file}: {message}"`` without field)."""

    def make(file: str, field: str | None, message: str) -> Exception:
        where = f"{file}: field '{field}'" if field else file
        return cls(f"{where}: {message}")

    return make


class Node:
    """One value of a parsed document, with its file, dotted path and labels.

    Parameters
    ----------
    value:
        The parsed value (the whole document for the top node).
    file:
        The file (or source) named in error messages.
    error:
        The :data:`ErrorFactory` that makes the exceptions.
    syntax:
        ``"JSON"`` or ``"TOML"``: the words of messages (*object* or *table*).

    Attributes
    ----------
    path:
        Dotted path from the top (``""`` for the top node), e.g. ``front[3].x``.
    context:
        Labels of the named entries above (``("link 'link4'", "solid 'gripper'")``).
    """

    __slots__ = ("_error", "context", "file", "path", "syntax", "value")

    def __init__(self, value: Any, file: Any, error: ErrorFactory, *, syntax: str = "TOML") -> None:
        self.value, self.file, self._error, self.syntax = value, str(file), error, syntax
        self.path, self.context = "", ()

    @classmethod
    def from_json(cls, text: str, file: Any, error: ErrorFactory) -> Node:
        """The top node of the JSON document ``text``, parsed by
        :func:`adept_traj.files.parse_json` (size and nesting depth bounded; NaN, Infinity
        and numbers beyond ±1.8e308 refused)."""
        prefix = f"{file}: "

        def refuse(message: str) -> Exception:
            return error(str(file), None, message.removeprefix(prefix))

        return cls(parse_json(text.encode("utf-8"), str(file), refuse), file, error, syntax="JSON")

    # ------------------------------------------------------------------ errors
    @property
    def present(self) -> bool:
        """Whether the document has this value (``False`` for an absent key)."""
        return self.value is not _ABSENT

    def error_at(self, path: str, message: str) -> Exception:
        """The caller's exception for the field at dotted ``path`` below this node."""
        full = ".".join(p for p in (self.path, path) if p).replace(".[", "[")
        return self._error(self.file, full or None, message)

    def error(self, message: str) -> Exception:
        """The caller's exception for this node: file, path, ``message`` and labels."""
        labels = f" (in {', '.join(self.context)})" if self.context else ""
        return self._error(self.file, self.path or None, message + labels)

    def describe(self) -> str:
        """What the value is, for messages: ``null``, ``-0.2``, ``the string 'a'``, ``a list
        of 2: [0.4, 0.2]``."""
        v = self.value
        if v is None or isinstance(v, bool):
            return {None: "null", True: "true", False: "false"}[v]
        if isinstance(v, (int, float)):
            return repr(v)
        if isinstance(v, str):
            return f"the string {v[:40]!r}" + ("…" if len(v) > 40 else "")
        if isinstance(v, Mapping):
            return self._table_word
        if isinstance(v, list):
            text = repr(v)
            return f"a list of {len(v)}" + (f": {text}" if len(text) <= 60 else "")
        return repr(v) if v is _ABSENT else type(v).__name__

    def _fail(self, expected: str) -> Exception:
        if not self.present:
            return self.error(f"missing; must be {expected}")
        return self.error(f"must be {expected}; got {self.describe()}")

    # ------------------------------------------------------------------ structure
    @property
    def _table_word(self) -> str:
        return "an object" if self.syntax == "JSON" else "a table"

    def _child(self, value: Any, path: str) -> Node:
        node = Node.__new__(Node)
        node.value, node.file, node._error, node.syntax = value, self.file, self._error, self.syntax
        node.path, node.context = path, self.context
        return node

    def table(self) -> dict[str, Any]:
        """The value as a mapping (a table or JSON object)."""
        if not isinstance(self.value, Mapping):
            raise self._fail(self._table_word)
        return self.value  # type: ignore[return-value]

    def __getitem__(self, key: str) -> Node:
        """The node at ``key`` of this table; an absent node when the key is not there."""
        path = f"{self.path}.{key}" if self.path else key
        return self._child(self.table().get(key, _ABSENT), path)

    def check_keys(self, allowed: Collection[str]) -> Node:
        """Refuse the first key of this table that is not in ``allowed``; return ``self``."""
        for key in self.table():
            if key not in allowed:
                names = ", ".join(map(repr, allowed))
                raise self[key].error(f"unknown field; allowed fields: {names}")
        return self

    def items(self, *, min_items: int = 0, default: Any = _ABSENT) -> list[Node]:
        """The nodes of the items of this list (``default`` when absent)."""
        if not self.present and default is not _ABSENT:
            return default
        if not isinstance(self.value, list) or len(self.value) < min_items:
            least = {0: "a list", 1: "a non-empty list"}.get(min_items, f"a list of ≥ {min_items}")
            raise self._fail(least)
        return [self._child(v, f"{self.path}[{i}]") for i, v in enumerate(self.value)]

    def named_tables(self) -> list[tuple[str, Node]]:
        """``(name, node)`` of each table of this array of tables (none when absent), each
        node labelled ``"{key} '{name}'"`` (``joint 'elbow'``) for the messages."""
        if not self.present:
            return []
        key = self.path.rsplit(".", 1)[-1]
        if not isinstance(self.value, list) or not all(isinstance(v, Mapping) for v in self.value):
            toml = f"an array of tables ([[{key}]])"
            raise self._fail(toml if self.syntax == "TOML" else "a list of objects")
        out = []
        for item in self.items():
            name = item["name"].string(nonempty=True)
            out.append((name, item.labelled(f"{key} {name!r}")))
        return out

    def labelled(self, label: str) -> Node:
        """This node with ``label`` added to the labels its messages end with."""
        node = self._child(self.value, self.path)
        node.context = (*self.context, label)
        return node

    def build(self, make: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
        """``make(*args, **kwargs)``; the errors it raises on bad input (AdeptTrajError,
        ValueError, TypeError: e.g. a string compared with a number) as this node's error."""
        try:
            return make(*args, **kwargs)
        except (AdeptTrajError, ValueError, TypeError) as exc:
            raise self.error(str(exc)) from None

    # ------------------------------------------------------------------ values
    def _settled(self, default: Any, null: Any, expected: str) -> tuple[bool, Any]:
        """``(True, default)`` when absent, ``(True, null)`` for an allowed null, else
        ``(False, value)``; an absent value without default is an error."""
        if not self.present:
            if default is _ABSENT:
                raise self._fail(expected)
            return True, default
        if self.value is None and null is not _ABSENT:
            return True, null
        return False, self.value

    def string(
        self,
        *,
        choices: Sequence[str] | None = None,
        nonempty: bool = False,
        null: Any = _ABSENT,
        default: Any = _ABSENT,
    ) -> Any:
        """The value as a ``str`` (one of ``choices`` if given; not ``""`` if ``nonempty``)."""
        names = ", ".join(map(repr, choices or ()))
        expected = "a non-empty string" if nonempty else "a string"
        if choices is not None:
            expected = " or ".join(map(repr, choices)) if len(choices) < 3 else f"one of {names}"
        expected += "" if null is _ABSENT else " or null"
        done, v = self._settled(default, null, expected)
        if done:
            return v
        if not isinstance(v, str) or (nonempty and not v) or (choices and v not in choices):
            raise self._fail(expected)
        return v

    def strings(
        self,
        *,
        choices: Sequence[str] | None = None,
        distinct: bool = False,
        min_items: int = 0,
        default: Any = _ABSENT,
    ) -> Any:
        """The value as a tuple of strings (each one of ``choices`` if given)."""
        if not self.present and default is not _ABSENT:
            return default
        out = tuple(item.string(choices=choices) for item in self.items(min_items=min_items))
        twice = sorted({s for s in out if out.count(s) > 1}) if distinct else []
        if twice:
            raise self.error(f"must hold distinct strings; got {twice[0]!r} more than once")
        return out

    def integer(
        self,
        *,
        minimum: int | None = None,
        maximum: int | None = None,
        null: Any = _ABSENT,
        default: Any = _ABSENT,
    ) -> Any:
        """The value as an ``int`` in [``minimum``, ``maximum``] (booleans refused)."""
        lo = "-∞" if minimum is None else minimum
        hi = "∞" if maximum is None else maximum
        expected = "an integer" if minimum is maximum is None else f"an integer in [{lo}, {hi}]"
        expected += "" if null is _ABSENT else " or null"
        done, v = self._settled(default, null, expected)
        if done:
            return v
        if (
            isinstance(v, bool)
            or not isinstance(v, int)
            or (minimum is not None and v < minimum)
            or (maximum is not None and v > maximum)
        ):
            raise self._fail(expected)
        return v

    def boolean(self) -> bool:
        """The value as a ``bool`` (``true`` or ``false``; numbers refused)."""
        if not isinstance(self.value, bool):
            raise self._fail("true or false")
        return self.value

    def number(
        self,
        unit: str = "",
        *,
        minimum: float = -math.inf,
        strict: bool = False,
        null: Any = _ABSENT,
        default: Any = _ABSENT,
    ) -> Any:
        """The value as a finite ``float`` ≥ ``minimum`` (> when ``strict``) in ``unit``;
        ``null`` is what a JSON null means (refused when not given)."""
        expected = _number_text(unit, minimum, strict, None if null is not _ABSENT else _ABSENT)
        done, v = self._settled(default, null, expected)
        if done:
            return v
        usual = type(v) in (int, float) and math.isfinite(v)  # the common case, without numpy
        if usual and (v > minimum or (v == minimum and not strict)):
            return float(v)
        return float(self._numbers((), unit, minimum, strict, _ABSENT))  # raises

    def array(
        self,
        shape: tuple[int | None, ...],
        unit: str = "",
        *,
        minimum: float = -math.inf,
        strict: bool = False,
        null: Any = _ABSENT,
        nullable: bool = False,
        default: Any = _ABSENT,
    ) -> Any:
        """The value, a list (of lists) of numbers, as a read-only float array of ``shape``
        (``None``: any length). Each number is finite and ≥ ``minimum`` (> when
        ``strict``) in ``unit``; a JSON null entry stands for ``null`` (e.g. ``math.inf``)
        when given. ``nullable``: the whole value may be null (returns ``None``)."""
        expected = _shape_text(shape) + _number_text(unit, minimum, strict, null, plural=True)
        done, _ = self._settled(default, None if nullable else _ABSENT, expected)
        if done:
            return None if self.present else default
        arr = self._numbers(shape, unit, minimum, strict, null)
        arr.flags.writeable = False
        return arr

    def _numbers(
        self, shape: tuple[int | None, ...], unit: str, minimum: float, strict: bool, null: Any
    ) -> np.ndarray:
        """The float array of :meth:`array`, checked in one step when it is well formed;
        otherwise walked item by item so that the error names the first bad entry."""
        cells = self._cells(shape, null)
        if cells is None:
            self._walk(shape, unit, minimum, strict, null)
            raise self._fail(_shape_text(shape) + _number_text(unit, minimum, strict, null, True))
        is_null = np.equal(cells, None) if null is not _ABSENT else np.zeros(cells.shape, bool)
        values = np.where(is_null, 0.0, cells).astype(float)
        bad = ~np.isfinite(values) | (values < minimum) | (strict & (values == minimum))
        if bad.any():
            index = tuple(int(i) for i in np.argwhere(bad)[0])
            raise self._at(index)._fail(_number_text(unit, minimum, strict, null))
        if is_null.any():
            values[is_null] = null
        return values

    def _cells(self, shape: tuple[int | None, ...], null: Any) -> np.ndarray | None:
        """The value as an object array of ``shape`` holding only numbers (and nulls when
        ``null`` is given); ``None`` when it is not one."""
        try:
            cells = np.array(self.value, dtype=object)
        except ValueError:  # ragged
            return None
        if cells.ndim != len(shape) or any(
            want is not None and got != want for got, want in zip(cells.shape, shape, strict=True)
        ):
            return None
        allowed = {int, float} if null is _ABSENT else {int, float, type(None)}
        if not set(map(type, cells.ravel())) <= allowed:  # bool is a type of its own: refused
            return None
        return cells

    def _walk(
        self, shape: tuple[int | None, ...], unit: str, low: float, strict: bool, null: Any
    ) -> None:
        """Raise at the first entry that keeps the value from being a ``shape`` array of
        numbers (a length given as ``None`` below the top is set by the first item)."""
        v = self.value
        if not shape:
            if (isinstance(v, bool) or not isinstance(v, (int, float))) and not (
                v is None and null is not _ABSENT
            ):
                raise self._fail(_number_text(unit, low, strict, null))
            return
        if not isinstance(v, list) or (shape[0] is not None and len(v) != shape[0]):
            raise self._fail(_shape_text(shape) + _number_text(unit, low, strict, null, True))
        inner = list(shape[1:])
        for item in self.items():
            item._walk(tuple(inner), unit, low, strict, null)
            if inner and inner[0] is None:
                inner[0] = len(item.value)

    def _at(self, index: Iterable[int]) -> Node:
        """The node of the entry at ``index`` of this (nested) list."""
        node = self
        for i in index:
            node = node._child(node.value[i], f"{node.path}[{i}]")
        return node


def _number_text(unit: str, minimum: float, strict: bool, null: Any, plural: bool = False) -> str:
    """What a number must be: ``"a finite number > 0 [m]"`` (``plural``: ``"finite numbers
    > 0 [m]"``), with what null stands for."""
    bound = "" if minimum == -math.inf else f" {'>' if strict else '≥'} {minimum:g}"
    units = f" {unit}" if unit else ""
    if null is _ABSENT:
        nulls = ""
    elif null is None:
        nulls = " or null"
    else:
        nulls = f" (null for {null:g})"
    return ("finite numbers" if plural else "a finite number") + bound + units + nulls


def _shape_text(shape: tuple[int | None, ...]) -> str:
    """The lists of an array of ``shape``: ``""``, ``"a list of 3 "``, ``"a list of rows of
    4 "``."""
    out = ""
    for depth, size in enumerate(shape):
        count = "" if size is None else f"{size} "
        if depth == 0:
            out += f"a list of {count}"
        else:
            out += f"{'rows' if len(shape) == 2 else 'lists'} of {count}"
    return out
