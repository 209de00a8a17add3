"""Input checks shared by the public methods of every subpackage.

Public methods normalise their inputs with these helpers and then call private hooks that
assume clean, float64, finite arrays. Every failure raises an :mod:`adept_traj.errors`
exception whose message names the argument, the value found and what was expected.
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from adept_traj.errors import FrozenObjectError, InputShapeError, InvalidInputError

__all__ = [
    "DeepEqual",
    "DerivedData",
    "FrozenAttributes",
    "as_batch",
    "as_finite_array",
    "as_integer",
    "as_path",
    "as_scalar",
    "as_vector",
    "check_increasing",
    "check_type",
    "deep_equal",
    "describe_bad_values",
    "readonly_copy",
]

_Made = TypeVar("_Made")


def describe_bad_values(x: np.ndarray, bad: np.ndarray, limit: int = 3) -> str:
    """Name up to ``limit`` offending entries of ``x`` (where ``bad`` is true) by index."""
    idx = np.argwhere(bad)
    parts = [f"{tuple(int(i) for i in ix)}={x[tuple(ix)]!r}" for ix in idx[:limit]]
    more = f" and {len(idx) - limit} more" if len(idx) > limit else ""
    return ", ".join(parts) + more


def as_finite_array(value: Any, name: str) -> np.ndarray:
    """Return ``value`` as a new float64 array, raising if it is not numeric or not finite."""
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be numeric; got {value!r} ({exc})") from None
    bad = ~np.isfinite(arr)
    if bad.any():
        where = describe_bad_values(arr, bad) if arr.ndim else repr(float(arr))
        raise InvalidInputError(f"{name} must be finite (no NaN or inf); bad entries: {where}")
    return arr


def as_batch(value: Any, name: str, size: int, unit: str = "") -> np.ndarray:
    """Return ``value`` as a float64 array of shape ``(..., size)``.

    Leading axes are kept (batch-first); a scalar or a wrong last axis raises
    :class:`~adept_traj.errors.InputShapeError`.
    """
    arr = as_finite_array(value, name)
    if arr.ndim == 0 or arr.shape[-1] != size:
        units = f" {unit}" if unit else ""
        raise InputShapeError(f"{name} must have shape (..., {size}){units}; got shape {arr.shape}")
    return arr


def as_vector(value: Any, name: str, size: int, unit: str = "") -> np.ndarray:
    """Return ``value`` as a float64 vector of shape ``(size,)``."""
    arr = as_finite_array(value, name)
    if arr.shape != (size,):
        units = f" {unit}" if unit else ""
        raise InputShapeError(f"{name} must have shape ({size},){units}; got shape {arr.shape}")
    return arr


def check_increasing(t: np.ndarray, name: str = "times") -> None:
    """:class:`~adept_traj.errors.InvalidInputError` naming the first sample of ``t`` (n,)
    [s] that does not follow its predecessor strictly."""
    bad = np.flatnonzero(np.diff(t) <= 0.0)
    if len(bad):
        k = int(bad[0])
        raise InvalidInputError(
            f"{name} must be strictly increasing [s]; {name}[{k + 1}] = {t[k + 1]!r} "
            f"follows {name}[{k}] = {t[k]!r}"
        )


def readonly_copy(value: Any) -> np.ndarray:
    """A new float64 array with the values of ``value``, marked read-only (for the fields of
    frozen dataclasses: callers' arrays are never kept or mutated)."""
    out = np.array(value, dtype=np.float64, copy=True)
    out.setflags(write=False)
    return out


def as_scalar(
    value: Any,
    name: str,
    unit: str = "",
    *,
    minimum: float = -math.inf,
    strict: bool = False,
    error: type[InvalidInputError] = InvalidInputError,
) -> float:
    """Return ``value`` as a finite float ≥ ``minimum`` (> ``minimum`` when ``strict``).

    Booleans, strings, arrays of another shape than ``()`` and NaN/inf are refused with
    ``error`` (an :class:`~adept_traj.errors.InvalidInputError` subclass) naming ``name``,
    the value found, its ``unit`` (e.g. ``"[s]"``) and the valid range.
    """
    units = f" {unit}" if unit else ""
    bound = "" if minimum == -math.inf else f" {'>' if strict else '≥'} {minimum:g}"
    if isinstance(value, (bool, np.bool_, str, bytes)):
        raise error(f"{name} must be a finite number{bound}{units}; got {value!r}")
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise error(f"{name} must be a finite number{bound}{units}; got {value!r}") from None
    if arr.ndim != 0:
        raise InputShapeError(f"{name} must be a scalar{units}; got shape {arr.shape}")
    x = float(arr)
    if not math.isfinite(x) or x < minimum or (strict and x == minimum):
        raise error(f"{name} must be a finite number{bound}{units}; got {value!r}")
    return x


def as_integer(
    value: Any,
    name: str,
    *,
    minimum: int | None = None,
    maximum: int | None = None,
    error: type[InvalidInputError] = InvalidInputError,
) -> int:
    """Return ``value`` (a Python or numpy integer, not a bool) as an ``int`` in
    [``minimum``, ``maximum``]; raise ``error`` naming ``name``, the value and the range."""
    lo = "-∞" if minimum is None else str(minimum)
    hi = "∞" if maximum is None else str(maximum)
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise error(f"{name} must be an integer in [{lo}, {hi}]; got {value!r}")
    out = int(value)
    if (minimum is not None and out < minimum) or (maximum is not None and out > maximum):
        raise error(f"{name} must be an integer in [{lo}, {hi}]; got {out}")
    return out


def as_path(value: Any, name: str = "path") -> Path:
    """``value`` (a ``str`` or ``os.PathLike``) as a :class:`~pathlib.Path`; anything else
    raises :class:`~adept_traj.errors.InvalidInputError` naming ``name`` and its type."""
    try:
        return Path(os.fspath(value))
    except TypeError:
        raise InvalidInputError(f"{name} must be a file path; got {type(value).__name__}") from None


def check_type(value: Any, kind: type | tuple[type, ...], name: str) -> None:
    """Raise :class:`~adept_traj.errors.InvalidInputError` unless ``value`` is a ``kind``."""
    if not isinstance(value, kind):
        names = " or ".join(k.__name__ for k in (kind if isinstance(kind, tuple) else (kind,)))
        raise InvalidInputError(f"{name} must be of type {names}; got {type(value).__name__}")


def deep_equal(a: Any, b: Any) -> bool:
    """Deep equality for the frozen records of the package: arrays element-wise (same shape;
    NaN ≠ NaN as in numpy), dataclasses of the same type field by field, mappings and
    sequences item by item, anything else by ``==``."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (
            isinstance(a, np.ndarray)
            and isinstance(b, np.ndarray)
            and a.shape == b.shape
            and bool(np.array_equal(a, b))
        )
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        return type(a) is type(b) and all(
            deep_equal(getattr(a, f.name), getattr(b, f.name)) for f in dataclasses.fields(a)
        )
    if isinstance(a, Mapping):
        return (
            isinstance(b, Mapping)
            and a.keys() == b.keys()
            and all(deep_equal(a[k], b[k]) for k in a)
        )
    if isinstance(a, (list, tuple)):
        return (
            isinstance(b, (list, tuple))
            and len(a) == len(b)
            and all(deep_equal(x, y) for x, y in zip(a, b))
        )
    return bool(a == b)


class DeepEqual:
    """Equality by :func:`deep_equal` for the package's frozen dataclasses with array
    fields (declared ``eq=False``: a generated ``__eq__`` fails on arrays); a record of
    another type is not equal. Unhashable, as a dataclass with ``eq`` would be."""

    def __eq__(self, other: object) -> bool:
        return deep_equal(self, other) if type(other) is type(self) else NotImplemented

    __hash__ = None  # type: ignore[assignment]


class DerivedData:
    """Data derived from a frozen object alone, made once and kept on it: the one cache
    of the package's frozen objects (:class:`~adept_traj.problem.TrajectoryProblem`,
    :class:`~adept_traj.robot.Robot`, :class:`~adept_traj.scene.PointCloud`, a cloud's
    leaves). Nothing it is made from can change, so nothing is keyed by identity and
    nothing goes stale; a changed copy (``replace``) starts without it.
    """

    def derived(self, key: str, make: Callable[[Any], _Made]) -> _Made:
        """What ``make(self)`` returns, made on the first call for ``key`` only and the same
        object on every later one.

        Parameters
        ----------
        key:
            Names the data (by convention the module making it, e.g.
            ``"collision.collision_matrix"``).
        make:
            Makes it from this object.
        """
        kept = self.__dict__.setdefault("_derived", {})
        if key not in kept:
            kept[key] = make(self)
        return kept[key]

    def derived_made(self, prefix: str) -> dict[str, Any]:
        """The data :meth:`derived` has made so far whose key starts with ``prefix``, by
        key (e.g. to hand it to a process forked before it was made, which keeps it with
        ``derived(key, lambda _: value)``)."""
        kept = self.__dict__.get("_derived", {})
        return {k: v for k, v in kept.items() if k.startswith(prefix)}


class FrozenAttributes:
    """Public attributes fixed at construction, for the package's frozen classes that are
    not dataclasses (:class:`~adept_traj.problem.TrajectoryProblem`,
    :class:`~adept_traj.robot.Robot`): once :meth:`_freeze` has run, setting or deleting an
    attribute whose name does not start with ``_`` raises
    :class:`~adept_traj.errors.FrozenObjectError`; the class's ``replace(...)`` makes a
    changed copy. Private attributes stay the object's own working state (a worker pool, a
    cache of derived data), never an input.
    """

    def _freeze(self) -> None:
        """Fix the public attributes (the end of ``__init__``)."""
        object.__setattr__(self, "_frozen", True)

    def __setattr__(self, name: str, value: Any) -> None:
        if not name.startswith("_") and self.__dict__.get("_frozen", False):
            raise _frozen_error(self, name, "assign to")
        object.__setattr__(self, name, value)

    def __delattr__(self, name: str) -> None:
        if not name.startswith("_") and self.__dict__.get("_frozen", False):
            raise _frozen_error(self, name, "delete")
        object.__delattr__(self, name)


def _frozen_error(obj: object, name: str, what: str) -> FrozenObjectError:
    kind = type(obj).__name__
    return FrozenObjectError(
        f"cannot {what} {kind}.{name}: a {kind} is fixed at construction; make a changed "
        f"copy with .replace({name}=...)"
    )
