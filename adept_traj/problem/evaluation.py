"""The evaluation of a population: objectives, constraints and diagnostics.

:class:`Evaluation` is what :meth:`~adept_traj.problem.TrajectoryProblem.evaluate_batch`
returns; objectives are reported as in :data:`~adept_traj.problem.objectives.OBJECTIVES`
(z4 positive, not pymoo's negated value).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Evaluation",
    "concatenate_evaluations",
    "timed_evaluation",
]


@dataclass(frozen=True)
class Evaluation:
    """Objectives, constraints and diagnostics of a population.

    Attributes
    ----------
    objectives: (pop, 6) z1…z6 as reported, z4 **positive** (units and sense:
        :data:`~adept_traj.problem.objectives.OBJECTIVES`; pymoo's ``F`` is
        :func:`~adept_traj.problem.objectives.to_pymoo` of them).
    constraints: (pop, 5·nq + 1) normalised g (feasible where all ≤ 0).
    min_distance: (pop, n_obstacles) smallest distance to each obstacle [m], clipped at
        ``influence`` (beyond it only a lower bound is known).
    n_narrow: coal distance calls made.
    seconds: wall time of the evaluation [s].
    """

    objectives: np.ndarray
    constraints: np.ndarray
    min_distance: np.ndarray
    n_narrow: int = 0
    seconds: float = 0.0

    @property
    def feasible(self) -> np.ndarray:
        """(pop,) bool: every constraint satisfied (at the evaluation's resolution)."""
        return np.all(self.constraints <= 0.0, axis=-1)


def concatenate_evaluations(parts: list[Evaluation]) -> Evaluation:
    """One evaluation of stacked populations.

    Parameters
    ----------
    parts:
        Evaluations of consecutive blocks of one population.

    Returns
    -------
    Evaluation
        Their rows in order; ``n_narrow`` summed.
    """
    return Evaluation(
        objectives=np.concatenate([e.objectives for e in parts]),
        constraints=np.concatenate([e.constraints for e in parts]),
        min_distance=np.concatenate([e.min_distance for e in parts]),
        n_narrow=sum(e.n_narrow for e in parts),
    )


def timed_evaluation(ev: Evaluation, start: float, single: bool) -> Evaluation:
    """An evaluation with its wall time.

    Parameters
    ----------
    ev:
        The evaluation of a population (pop, ...).
    start:
        ``time.perf_counter()`` [s] when it started.
    single:
        The caller gave one vector: keep the first row, without the population axis.

    Returns
    -------
    Evaluation
        ``ev`` with ``seconds`` set.
    """
    seconds = time.perf_counter() - start
    if single:
        return Evaluation(
            objectives=ev.objectives[0],
            constraints=ev.constraints[0],
            min_distance=ev.min_distance[0],
            n_narrow=ev.n_narrow,
            seconds=seconds,
        )
    return Evaluation(ev.objectives, ev.constraints, ev.min_distance, ev.n_narrow, seconds)
