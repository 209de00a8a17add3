"""Python values as JSON stores them: the conversions shared by the record and the codecs
of :mod:`~adept_traj.results.json_codec` and :mod:`~adept_traj.results.certificate_codec`.

JSON has no NaN or infinity: NaN is refused and an infinite value becomes ``null``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from adept_traj.errors import InvalidInputError

__all__ = ["json_float", "json_floats", "jsonable"]


def jsonable(value: Any) -> Any:
    """A JSON-compatible deep copy of a value.

    Parameters
    ----------
    value:
        Any value.

    Returns
    -------
    object
        Mappings as dicts (str keys), sequences and arrays as lists, numpy scalars as Python
        numbers, non-finite floats as ``None``, other objects as their ``str``.
    """
    if isinstance(value, Mapping):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.generic):
        return jsonable(value.item())
    if value is None or isinstance(value, (bool, int, str)):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    return str(value)


def json_float(value: float) -> float | None:
    """A float as JSON stores it.

    Parameters
    ----------
    value:
        A float.

    Returns
    -------
    float or None
        ``value`` when finite, ``None`` for ±inf.

    Raises
    ------
    InvalidInputError
        NaN.
    """
    v = float(value)
    if math.isnan(v):
        raise InvalidInputError("NaN cannot be saved")
    return v if math.isfinite(v) else None


def json_floats(arr: Any) -> Any:
    """An array of floats as JSON stores it.

    Parameters
    ----------
    arr:
        An array of any shape.

    Returns
    -------
    list
        Nested lists of floats, ±inf as ``None``.

    Raises
    ------
    InvalidInputError
        A NaN.
    """
    a = np.asarray(arr, dtype=float)
    if np.isnan(a).any():
        raise InvalidInputError("NaN cannot be saved")
    return np.where(np.isinf(a), None, a).tolist() if np.isinf(a).any() else a.tolist()
