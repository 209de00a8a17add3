"""Timing helper shared by the benchmark scripts."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from pathlib import Path


def best_of(fn: Callable[[], object], repeat: int = 3) -> float:
    """Best wall time [s] of ``repeat`` calls of ``fn`` (the least disturbed by other load)."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def compile_package(root: Path | None = None) -> None:
    """Write the bytecode of the package at ``root`` (default: the one imported), as
    ``pip install`` does: a timed command then runs what a user's installed package runs,
    also where the environment sets ``PYTHONDONTWRITEBYTECODE`` (without it, every run
    compiles the package's modules again, about 0.1–0.2 s of CPU)."""
    import compileall

    if root is None:
        import adept_traj

        root = Path(adept_traj.__file__).parent
    compileall.compile_dir(str(root), quiet=1)


def compared_codes(here: Path, baseline: Path | None) -> dict[str, Path]:
    """The copies of the code a paired benchmark runs: ``{"this": here}``, preceded by
    ``"baseline"`` when one is given (run first in each pair)."""
    if baseline is None:
        return {"this": here}
    return {"baseline": baseline.resolve(), "this": here}


def load_average() -> str:
    """The machine's load averages over 1, 5 and 15 minutes, as text."""
    return ", ".join(f"{x:.1f}" for x in os.getloadavg())


def pair_order(labels: Sequence[str], i: int) -> list[str]:
    """The order in which pair ``i`` of a paired benchmark runs the compared codes: as
    given for an even ``i``, reversed for an odd one (neither version always runs first,
    in the warmer or the cooler state of the machine)."""
    return list(labels) if i % 2 == 0 else list(reversed(labels))
