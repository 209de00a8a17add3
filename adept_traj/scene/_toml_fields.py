"""Checked reading of the fields of a parsed TOML table, for :mod:`.scene_file`.

Each helper reads one field (a number, a list of numbers, a string, a table, an array of
tables), applies its default when the field is absent, and raises
:class:`~adept_traj.errors.SceneError` naming the source (file), the entry and the field,
with what was expected and what was found. TOML booleans are not numbers.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from adept_traj.errors import AdeptTrajError, SceneError

#: Marks a field without a default (it must be present).
_MISSING: Any = object()


class _Where:
    """Error context: the source (file) and the entry being read."""

    def __init__(self, source: str, entry: str = "") -> None:
        self.source = source
        self.entry = entry

    def error(self, message: str) -> SceneError:
        where = f"{self.entry}: " if self.entry else ""
        return SceneError(f"{self.source}: {where}{message}")

    def field_error(self, key: str, expected: str, got: Any) -> SceneError:
        return self.error(f"field {key!r} must be {expected}; got {got!r}")


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _check_keys(table: Mapping[str, Any], allowed: Sequence[str], w: _Where) -> None:
    for key in table:
        if key not in allowed:
            raise w.error(
                f"unknown field {key!r}; allowed fields: {', '.join(repr(a) for a in allowed)}"
            )


def _table(value: Any, key: str, w: _Where) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise w.field_error(key, f"a table ([{key}])", value)
    return value


def _field(table: Mapping[str, Any], key: str, w: _Where, expected: str, default: Any) -> Any:
    """The value of ``key``, or ``default`` when absent (an error when there is none)."""
    if key in table:
        return table[key]
    if default is _MISSING:
        raise w.error(f"missing field {key!r} ({expected})")
    return default


def _number(
    table: Mapping[str, Any],
    key: str,
    w: _Where,
    unit: str,
    *,
    sign: str = "positive",
    default: Any = _MISSING,
) -> float:
    article = {"positive": "a positive", "non-negative": "a non-negative"}.get(sign, "a")
    expected = f"{article} number {unit}"
    v = _field(table, key, w, expected, default)
    if not _is_number(v) or (sign == "positive" and v <= 0) or (sign == "non-negative" and v < 0):
        raise w.field_error(key, expected, v)
    return float(v)


def _numbers(
    table: Mapping[str, Any],
    key: str,
    w: _Where,
    n: int | None,
    unit: str,
    *,
    positive: bool = False,
    default: Any = _MISSING,
) -> list[float]:
    count = f"{n}" if n is not None else "a non-empty list of"
    kind = "positive numbers" if positive else "numbers"
    expected = f"{count} {kind} {unit}"
    v = _field(table, key, w, expected, default)
    if (
        not isinstance(v, list)
        or (n is not None and len(v) != n)
        or not v
        or not all(_is_number(x) for x in v)
        or (positive and not all(x > 0 for x in v))
    ):
        raise w.field_error(key, expected, v)
    return [float(x) for x in v]


def _string(
    table: Mapping[str, Any],
    key: str,
    w: _Where,
    default: Any = _MISSING,
    expected: str = "a non-empty string",
) -> str:
    v = _field(table, key, w, expected, default)
    if not isinstance(v, str) or not v:
        raise w.field_error(key, expected, v)
    return v


def _array_of_tables(data: Mapping[str, Any], key: str, w: _Where) -> list[Mapping[str, Any]]:
    if key not in data:
        return []
    v = data[key]
    if not isinstance(v, list) or not all(isinstance(x, Mapping) for x in v):
        raise w.field_error(key, f"an array of tables ([[{key}]] entries)", v)
    return v


def _entry_where(source: str, kind: str, index: int, entry: Mapping[str, Any]) -> _Where:
    name = entry.get("name")
    if isinstance(name, str) and name:
        return _Where(source, f"{kind} {name!r}")
    return _Where(source, f"{kind} #{index + 1} (in file order)")


def _build(w: _Where, make: Any, *args: Any, **kwargs: Any) -> Any:
    """Call a constructor, turning its input errors into SceneErrors with context."""
    try:
        return make(*args, **kwargs)
    except AdeptTrajError as exc:
        raise w.error(str(exc)) from None
