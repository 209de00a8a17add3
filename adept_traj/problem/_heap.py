"""The process heap kept between evaluation blocks (glibc's ``malloc``).

An evaluation block of about 4 000 samples allocates and frees a few MB of numpy
temporaries. glibc gives the free top of its heap back to the kernel once it exceeds its
trim threshold (by default twice the largest array it has mapped and freed, so a few
MB here), and the next block faults those pages in again. Whether that happens depends
on where the few long-lived objects of the process lie in the heap — on the exact code,
even on the length of its path — so the same evaluation cost from 0 to about 27 000 page
faults per population of 500 (a noticeable share of system CPU time, issue #15;
``benchmarks/results/notebook.md``), from one process to the next.

:func:`keep_heap` sets two ``malloc`` parameters for the whole process, once:
``M_MMAP_THRESHOLD`` = 32 MiB (glibc's own ceiling of its dynamic threshold) and
``M_TRIM_THRESHOLD`` = 512 MiB. Freed memory up to that much stays in the process and
serves the next block; the process keeps its peak heap (arrays of 32 MiB or more are
still mapped and unmapped on their own).
Where ``malloc`` is not glibc's, or the environment sets ``malloc`` parameters itself
(``GLIBC_TUNABLES``, ``MALLOC_*_``), nothing is changed. Worker processes forked after
the call inherit the parameters.

Who calls it: the processes that are adept_traj's own — the ``adept-traj`` command (when
it builds its problem) and the evaluation workers a problem forks
(:class:`~adept_traj.problem.ParallelEvaluator`). A program that uses the library is left
as it is (a library does not change its host's ``malloc`` behind its back): call
:func:`keep_heap` once to get the same speed, if keeping the peak heap suits it.
"""

from __future__ import annotations

import os
import sys

__all__ = ["heap_environment", "keep_heap"]

#: Arrays of at least this many bytes [B] are mapped on their own (32 MiB).
_MMAP_THRESHOLD = 32 * 2**20
#: Free memory at the top of the heap beyond this [B] is given back to the kernel (512 MiB).
_TRIM_THRESHOLD = 512 * 2**20

#: mallopt's parameter numbers (glibc's malloc.h).
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
#: Environment variables through which a user sets malloc's parameters: then left alone.
_USER_SETTINGS = (
    "GLIBC_TUNABLES",
    "MALLOC_MMAP_THRESHOLD_",
    "MALLOC_TOP_PAD_",
    "MALLOC_TRIM_THRESHOLD_",
)

_kept: bool | None = None  # the outcome of the first call in this process (or its parent)


def keep_heap() -> bool:
    """Keep freed memory in the process between evaluation blocks (module docstring).

    Returns
    -------
    bool
        True when the parameters are set (by this call or an earlier one), False where
        they are left as they are (``malloc`` is not glibc's, or the environment sets
        them). Only the first call in a process does anything.
    """
    global _kept
    if _kept is None:
        _kept = _set_parameters()
    return _kept


def heap_environment() -> dict[str, str]:
    """The environment variables that give a process started afresh (not forked) the
    ``malloc`` parameters of :func:`keep_heap`: glibc reads them at the process's start.

    Returns
    -------
    dict
        ``{"MALLOC_MMAP_THRESHOLD_": "33554432", "MALLOC_TRIM_THRESHOLD_": "536870912"}``
        (32 MiB and 512 MiB, in bytes).
    """
    return {
        "MALLOC_MMAP_THRESHOLD_": str(_MMAP_THRESHOLD),
        "MALLOC_TRIM_THRESHOLD_": str(_TRIM_THRESHOLD),
    }


def _set_parameters() -> bool:
    if not sys.platform.startswith("linux") or any(k in os.environ for k in _USER_SETTINGS):
        return False
    import ctypes  # only here: nothing to load for an import of the package

    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):  # no C library to load, or one without mallopt
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(
        mallopt(_M_MMAP_THRESHOLD, _MMAP_THRESHOLD) == 1
        and mallopt(_M_TRIM_THRESHOLD, _TRIM_THRESHOLD) == 1
    )
