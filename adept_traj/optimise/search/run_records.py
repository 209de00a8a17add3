"""What a run of the search reports: :class:`GenerationInfo`, the progress of each
generation, and :class:`RunState`, its final population and bookkeeping.

Apart from the loop (:mod:`adept_traj.optimise.search.loop`) so that the modes without an
evolutionary search (the time-optimal mode) make a :class:`RunState` without importing
pymoo.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["GenerationInfo", "RunState"]


@dataclass(frozen=True)
class GenerationInfo:
    """Progress of one finished generation (passed to the progress callback)."""

    generation: int
    n_gen: int
    n_evaluations: int
    n_feasible: int
    #: Smallest travel time z1 [s] among the feasible individuals (None if none is feasible).
    best_time: float | None
    #: Wall time [s] since the run started (a resumed run includes the earlier sessions).
    elapsed_s: float


@dataclass(frozen=True)
class RunState:
    """Final population and bookkeeping of a run.

    ``X`` (pop, n_var), ``F`` (pop, n_obj) as pymoo sees them (maximised columns negated:
    :func:`~adept_traj.problem.to_pymoo`), ``G`` (pop, n_constr), ``CV`` (pop,) total
    constraint violation; ``total_s`` and
    ``evaluation_s`` [s] the wall time of the run and the part spent evaluating (earlier
    sessions of a resumed run included); ``history`` one dict per generation.
    """

    X: np.ndarray
    F: np.ndarray
    G: np.ndarray
    CV: np.ndarray
    n_generations: int
    n_evaluations: int
    total_s: float
    evaluation_s: float
    history: list[dict[str, Any]] = field(default_factory=list)
    #: Per generation (restored on resume): the objectives (pymoo's sense) of the
    #: population's feasible non-dominated members, for the hypervolume history.
    fronts: list[np.ndarray] = field(default_factory=list)
