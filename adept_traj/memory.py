r"""The memory budget: how much memory a run may use, and the check that refuses an option
whose estimated need exceeds it, before any long work starts.

The budget is the smaller of :data:`MAX_MEMORY_BYTES` (a documented ceiling, 16 GiB) and the
memory the machine has available right now (``MemAvailable`` of ``/proc/meminfo`` on
Linux, else ``SC_AVPHYS_PAGES × SC_PAGE_SIZE``). The estimates themselves live beside what
they estimate (:func:`~adept_traj.certification.certificate.certificate_bytes`,
:meth:`~adept_traj.problem.TrajectoryProblem.run_bytes`, …); each gives its formula, fitted
to :mod:`tracemalloc` peaks measured on small sizes (``benchmarks/bench_memory.py``).
"""

from __future__ import annotations

import os
from pathlib import Path

from adept_traj.errors import ResourceLimitError

__all__ = ["MAX_MEMORY_BYTES", "available_memory", "check_memory", "format_bytes", "memory_budget"]

#: Ceiling of any single estimate [B] (16 GiB), whatever the machine has.
MAX_MEMORY_BYTES = 16 * 2**30

_MEMINFO = Path("/proc/meminfo")


def available_memory() -> int:
    """Memory the machine can give now [B]: ``MemAvailable`` of ``/proc/meminfo``, else
    ``SC_AVPHYS_PAGES × SC_PAGE_SIZE``; :data:`MAX_MEMORY_BYTES` when neither is known."""
    try:
        for line in _MEMINFO.read_text(encoding="ascii").splitlines():
            if line.startswith("MemAvailable:"):
                return int(line.split()[1]) * 1024  # the file gives kB
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):
        return MAX_MEMORY_BYTES


def memory_budget() -> int:
    """The largest estimate accepted [B]: ``min(MAX_MEMORY_BYTES, available_memory())``."""
    return min(MAX_MEMORY_BYTES, available_memory())


def format_bytes(n: float) -> str:
    """``n`` bytes in binary units, e.g. ``"1.5 GiB"``."""
    value, unit = float(n), "B"
    for bigger in ("KiB", "MiB", "GiB", "TiB", "PiB"):
        if abs(value) < 1024.0:
            break
        value, unit = value / 1024.0, bigger
    return f"{value:.0f} B" if unit == "B" else f"{value:.1f} {unit}"


def check_memory(estimate: float, option: str, value: object, budget: int | None = None) -> float:
    """Return ``estimate`` [B] if it fits the memory budget, else raise.

    Parameters
    ----------
    estimate: the bytes the option's value would need (from the estimate beside the code
        that allocates them).
    option: the option's name as the user wrote it (``"--pop"``, ``"rate_hz"``).
    value: the option's value, for the message.
    budget: the limit [B] (default :func:`memory_budget`).

    Raises
    ------
    ResourceLimitError
        ``estimate`` exceeds the budget; the message names the option, the value, the
        estimate and the limit (and whether the limit is the ceiling or the available memory).
    """
    limit = memory_budget() if budget is None else int(budget)
    if estimate > limit:
        why = (
            f"the ceiling MAX_MEMORY_BYTES = {format_bytes(MAX_MEMORY_BYTES)}"
            if limit >= MAX_MEMORY_BYTES
            else f"the memory available on this machine, {format_bytes(limit)}"
        )
        raise ResourceLimitError(
            f"{option} = {value} would need about {format_bytes(estimate)} of memory, more "
            f"than {why}; choose a smaller {option}"
        )
    return estimate
