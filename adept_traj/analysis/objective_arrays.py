"""Objective arrays checked and put in one form: the input checks shared by
:mod:`~adept_traj.analysis.indicators`, :mod:`~adept_traj.analysis.decision` and
:mod:`~adept_traj.analysis.paper_measures`.

Objective arrays ``F`` have shape ``(n, m)``, one row per solution; the *sense* of each
objective is given by ``maximised`` (a bool, or one bool per column; the default
:data:`~adept_traj.problem.MAXIMISED` is the paper's six objectives with z4 maximised).
Inputs are never modified.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.validation import as_finite_array

__all__ = ["as_objectives", "as_sense", "fraction_towards", "minimisation_form"]


def as_objectives(value: ArrayLike, name: str = "F", min_rows: int = 1) -> np.ndarray:
    """Objective values checked: a new finite float64 array.

    Parameters
    ----------
    value:
        (n, m) objective values.
    name:
        Its name in error messages.
    min_rows:
        Fewest rows n accepted.

    Returns
    -------
    numpy.ndarray
        (n, m) float64, a copy.

    Raises
    ------
    InputShapeError, InvalidInputError
        Not (n, m), fewer than ``min_rows`` rows, or a non-finite value.
    """
    arr = as_finite_array(value, name)
    if arr.ndim != 2 or arr.shape[1] < 1:
        raise InputShapeError(
            f"{name} must have shape (n, m) (one row per solution); got shape {arr.shape}"
        )
    if arr.shape[0] < min_rows:
        raise InputShapeError(f"{name} must have at least {min_rows} row(s); got shape {arr.shape}")
    return arr


def as_sense(maximised: bool | Sequence[bool] | np.ndarray, m: int) -> np.ndarray:
    """Which objectives are maximised, as one bool per column.

    Parameters
    ----------
    maximised:
        One bool (every column) or (m,) bools (0/1 integers accepted).
    m:
        Number of objectives.

    Returns
    -------
    numpy.ndarray
        (m,) bool, a copy.

    Raises
    ------
    InputShapeError, InvalidInputError
        Not bools, or not one per objective.
    """
    if isinstance(maximised, (bool, np.bool_)):
        return np.full(m, bool(maximised))
    try:
        arr = np.asarray(maximised)
    except (TypeError, ValueError) as exc:  # pragma: no cover - exotic inputs
        raise InvalidInputError(f"maximised must be a bool or bools; got {maximised!r}") from exc
    if arr.dtype != np.bool_:
        if arr.dtype.kind in "iu" and np.isin(arr, (0, 1)).all():
            arr = arr.astype(bool)
        else:
            raise InvalidInputError(
                f"maximised must be a bool or a sequence of bools; got {maximised!r}"
            )
    if arr.shape != (m,):
        raise InputShapeError(
            f"maximised must be a bool or have one entry per objective ({m},); "
            f"got shape {arr.shape} (the default MAXIMISED is for the six objectives z1..z6)"
        )
    return arr.copy()


def minimisation_form(F: np.ndarray, sense: np.ndarray) -> np.ndarray:
    """The objectives with the maximised columns negated (every column minimised).

    Parameters
    ----------
    F:
        (n, m) objective values.
    sense:
        (m,) bool, True where maximised (:func:`as_sense`).

    Returns
    -------
    numpy.ndarray
        (n, m), a new array.
    """
    return np.where(sense, -F, F)


def fraction_towards(
    arr: np.ndarray, lo: np.ndarray, hi: np.ndarray, up: np.ndarray, flat: float
) -> np.ndarray:
    """Where each value lies between two bounds, as a fraction of the way.

    Shared by :func:`~adept_traj.analysis.indicators.to_unit_minimisation` and
    :func:`~adept_traj.analysis.decision.normalise`.

    Parameters
    ----------
    arr:
        (n, m) values.
    lo, hi:
        (m,) lower and upper bound of each column.
    up:
        (m,) bool: the fraction from ``lo`` up where True, from ``hi`` down elsewhere.
    flat:
        The value in a column where ``lo == hi``.

    Returns
    -------
    numpy.ndarray
        (n, m) fractions (0 at the bound measured from, 1 at the other).
    """
    span = hi - lo
    safe = np.where(span > 0, span, 1.0)
    frac = np.where(up, (arr - lo) / safe, (hi - arr) / safe)
    return np.where(span > 0, frac, flat)
