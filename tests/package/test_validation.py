"""The shared input checks: each names the argument, the value and the valid range."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from adept_traj.errors import ConfigurationError, InputShapeError, InvalidInputError
from adept_traj.validation import as_integer, as_scalar, check_type, deep_equal


def test_as_scalar_accepts_numbers_and_numpy_scalars():
    assert as_scalar(2, "T") == 2.0
    assert as_scalar(np.float32(0.5), "T") == 0.5
    assert as_scalar(np.array(3.0), "T", minimum=3.0) == 3.0


@pytest.mark.parametrize("bad", [True, "1", None, np.nan, np.inf, [1.0]])
def test_as_scalar_refuses_non_numbers(bad):
    with pytest.raises(InvalidInputError, match="T"):
        as_scalar(bad, "T", "[s]")


def test_as_scalar_names_range_and_unit():
    with pytest.raises(InvalidInputError, match=r"T must be a finite number > 0 \[s\]; got 0"):
        as_scalar(0, "T", "[s]", minimum=0.0, strict=True)
    with pytest.raises(ConfigurationError, match="≥ 1"):
        as_scalar(0.5, "rate", minimum=1.0, error=ConfigurationError)
    with pytest.raises(InputShapeError, match=r"shape \(2,\)"):
        as_scalar(np.ones(2), "T")


def test_as_integer():
    assert as_integer(np.int64(4), "pop", minimum=1) == 4
    with pytest.raises(InvalidInputError, match=r"pop must be an integer in \[1, 10\]; got 11"):
        as_integer(11, "pop", minimum=1, maximum=10)
    for bad in (True, 2.0, "3"):
        with pytest.raises(InvalidInputError, match="pop"):
            as_integer(bad, "pop")


def test_check_type():
    assert check_type(1.0, (int, float), "x") is None
    with pytest.raises(InvalidInputError, match="x must be of type int or float; got str"):
        check_type("1", (int, float), "x")


@dataclass(frozen=True, eq=False)
class _Pair:
    a: np.ndarray
    b: dict


def test_deep_equal():
    one = _Pair(np.arange(3.0), {"k": [1, (2.0, np.ones(2))]})
    assert deep_equal(one, _Pair(np.arange(3.0), {"k": [1, (2.0, np.ones(2))]}))
    assert not deep_equal(one, _Pair(np.arange(3.0), {"k": [1, (2.0, np.zeros(2))]}))
    assert not deep_equal(one, _Pair(np.arange(4.0), one.b))
    assert not deep_equal(np.ones((1, 2)), np.ones(2))  # shapes differ
    assert not deep_equal(np.ones(2), [1.0, 1.0])  # an array is not a list
    assert not deep_equal({"a": 1}, {"a": 1, "b": 2})
