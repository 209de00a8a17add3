"""Progress of a planning run, drawn on standard error (``--quiet``: nothing)."""

from __future__ import annotations

import sys
from collections.abc import Callable

from adept_traj.optimise import GenerationInfo

__all__ = ["progress_reporter"]


def progress_reporter(label: str, quiet: bool) -> Callable[[GenerationInfo], None] | None:
    """A progress callback for :func:`adept_traj.optimise.plan`, or ``None`` when ``quiet``."""
    if quiet:
        return None

    def show(info: GenerationInfo) -> None:
        width = 30
        done = int(width * info.generation / info.n_gen)
        best = f"{info.best_time:.3f} s" if info.best_time is not None else "-"
        sys.stderr.write(
            f"\r{label} [{'#' * done}{'.' * (width - done)}] gen {info.generation}/{info.n_gen}"
            f"  evals {info.n_evaluations}  feasible {info.n_feasible}  best T {best}"
            f"  {info.elapsed_s:.1f} s "
        )
        if info.generation == info.n_gen:
            sys.stderr.write("\n")
        sys.stderr.flush()

    return show
