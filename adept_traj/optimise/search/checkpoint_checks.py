"""The checks of a checkpoint file's content, so that a damaged file is refused with
:class:`~adept_traj.errors.CheckpointFormatError` (naming the file and the array) before
anything is restored from it (the format: :mod:`adept_traj.optimise.search.checkpoint`).

Each function raises that error, named after ``path``, at the first fault it finds.
"""

from __future__ import annotations

import zipfile
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.errors import CheckpointFormatError

__all__ = ["check_layout", "check_listed", "check_meta", "described", "read_arrays"]

#: The bit generators of ``numpy.random`` whose state a checkpoint may hold.
_BIT_GENERATORS = ("MT19937", "PCG64", "PCG64DXSM", "Philox", "SFC64")
#: The first bytes of a zip archive (an ``.npz`` file).
_ZIP_MAGIC = b"PK\x03\x04"


def read_arrays(path: Path) -> dict[str, np.ndarray]:
    """Every array of the ``.npz`` file ``path`` (read whole: a truncated or altered member
    fails its CRC check here)."""
    with path.open("rb") as fh:
        head = fh.read(len(_ZIP_MAGIC))
    if not head:
        raise CheckpointFormatError(path, None, "the file is empty")
    if head != _ZIP_MAGIC:
        raise CheckpointFormatError(path, None, f"not an .npz archive (it starts with {head!r})")
    try:
        with np.load(path, allow_pickle=False) as data:
            return {k: data[k] for k in data.files}
    except zipfile.BadZipFile as exc:
        raise CheckpointFormatError(path, None, f"truncated or altered ({exc})") from None
    except (OSError, EOFError, ValueError, zlib.error, NotImplementedError) as exc:
        # e.g. a member that is not an .npy array, or holds pickled data (allow_pickle=False)
        raise CheckpointFormatError(path, None, f"unreadable ({exc})") from None


def described(a: np.ndarray) -> str:
    """``a``'s dtype and shape, for a message."""
    return f"dtype {a.dtype.str}, shape {a.shape}"


def check_meta(path: Path, name: str | None, meta: dict[str, Any]) -> None:
    """The metadata's values (of the file ``path``, its array ``name``: ``None`` for a
    file of its own) have their types: counters integers (``n_iter`` ≥ 1, ``n_eval`` ≥ 0),
    times numbers ≥ 0 [s], the history a list, the generator's state one that this
    ``numpy`` accepts, ``arrays`` (if there) ``{name: [dtype, shape]}``."""

    def integer(key: str, minimum: int) -> None:
        value = meta[key]
        if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
            raise CheckpointFormatError(
                path, name, f"'{key}' is {value!r}, not an integer ≥ {minimum}"
            )

    integer("n_iter", 1)
    integer("n_eval", 0)
    for key in ("total_s", "evaluation_s"):
        value = meta[key]
        if isinstance(value, bool) or not isinstance(value, int | float) or value < 0:
            raise CheckpointFormatError(path, name, f"'{key}' is {value!r}, not a time ≥ 0 [s]")
    if not isinstance(meta["history"], list):
        raise CheckpointFormatError(path, name, "'history' is not a list")
    rng = meta["rng"]
    kind = rng.get("bit_generator") if isinstance(rng, dict) else None
    try:
        if kind not in _BIT_GENERATORS:
            raise ValueError(f"bit generator {kind!r}")
        getattr(np.random, kind)().state = rng
    except (TypeError, ValueError, KeyError) as exc:
        raise CheckpointFormatError(
            path, name, f"'rng' is not a state of a numpy bit generator ({exc})"
        ) from None
    if "arrays" in meta and not (
        isinstance(meta["arrays"], dict)
        and all(
            isinstance(v, list)
            and len(v) == 2
            and isinstance(v[0], str)
            and isinstance(v[1], list)
            and all(isinstance(n, int) for n in v[1])
            for v in meta["arrays"].values()
        )
    ):
        raise CheckpointFormatError(path, name, "'arrays' is not a list of dtypes and shapes")


def check_listed(path: Path, arrays: dict[str, np.ndarray], listed: dict[str, list]) -> None:
    """``arrays`` are exactly those ``listed`` in the metadata, with their dtypes and
    shapes (``[dtype.str, shape]``)."""
    for name in sorted(set(listed) | set(arrays)):
        if name not in arrays:
            raise CheckpointFormatError(path, name, "missing (listed in the metadata)")
        if name not in listed:
            raise CheckpointFormatError(path, name, "not listed in the metadata")
        dtype, shape = listed[name]
        a = arrays[name]
        if (a.dtype.str, list(a.shape)) != (dtype, shape):
            raise CheckpointFormatError(
                path, name, f"{described(a)} where dtype {dtype}, shape {tuple(shape)} was written"
            )


def check_layout(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """The population's arrays have its layout: ``X``, ``F``, ``G``, ``CV`` float64 of
    ``pop`` rows (``CV`` (pop, 1)), ``n_iter`` a 0-d integer, ``data.<key>`` ``pop`` rows
    (numbers or booleans), ``absent.<key>`` bool (pop,) beside its ``data.<key>``."""
    pop = arrays["X"].shape[0] if arrays["X"].ndim == 2 else -1
    for name in ("X", "F", "G", "CV"):
        a = arrays[name]
        if a.dtype != np.float64 or a.ndim != 2 or a.shape[0] != pop or pop < 1:
            raise CheckpointFormatError(
                path,
                name,
                f"{described(a)} where float64 of shape (pop, n) is stored"
                + (f" (pop = {pop}, the rows of X)" if name != "X" else ""),
            )
    if arrays["CV"].shape[1] != 1:
        raise CheckpointFormatError(
            path, "CV", f"{described(arrays['CV'])} where float64 (pop, 1) is stored"
        )
    if arrays["n_iter"].shape != () or arrays["n_iter"].dtype.kind not in "iu":
        raise CheckpointFormatError(
            path, "n_iter", f"{described(arrays['n_iter'])} where a 0-d integer is stored"
        )
    for name, a in arrays.items():
        if name.startswith("data.") and (a.ndim < 1 or len(a) != pop or a.dtype.kind not in "biuf"):
            raise CheckpointFormatError(
                path, name, f"{described(a)} where {pop} rows of numbers are stored"
            )
        if name.startswith("absent."):
            key = name.removeprefix("absent.")
            if a.dtype != np.bool_ or a.shape != (pop,):
                raise CheckpointFormatError(
                    path, name, f"{described(a)} where bool of shape ({pop},) is stored"
                )
            if f"data.{key}" not in arrays:
                raise CheckpointFormatError(path, f"data.{key}", f"missing (beside {name})")
