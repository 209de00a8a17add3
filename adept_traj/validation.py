"""Input checks shared by the public methods (private module).

Public methods normalise their inputs with these helpers and then call private hooks that
assume clean, float64, finite arrays. Every failure raises an :mod:`adept_traj.errors`
exception whose message names the argument, the value found and what was expected.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from adept_traj.errors import InputShapeError, InvalidInputError

__all__ = ["as_batch", "as_finite_array", "as_vector", "describe_bad_values", "readonly_copy"]


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


def readonly_copy(value: Any) -> np.ndarray:
    """A new float64 array with the values of ``value``, marked read-only (for the fields of
    frozen dataclasses: callers' arrays are never kept or mutated)."""
    out = np.array(value, dtype=np.float64, copy=True)
    out.setflags(write=False)
    return out
