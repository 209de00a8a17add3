r"""NSGA-II's survival (pymoo's rank and crowding) with the bookkeeping done on arrays.

pymoo's :class:`~pymoo.operators.survival.rank_and_crowding.RankAndCrowding` keeps the
feasible members first (by non-dominated rank, then crowding distance), then the
infeasible ones by increasing total constraint violation CV. Before ranking, pymoo's
``Survival.do`` splits the merged parents and offspring (2N members) into feasible and
infeasible ones with ``Population.get("F", "CV", "FEAS")``: three properties per member,
each evaluated twice (``hasattr`` then ``getattr``) and ``FEAS`` compares a fresh array
each time — per member, and for MODE's 1 000 members about as long as the non-dominated
sorting itself.

:class:`RankAndCrowdingSurvival` takes the same decisions from one (2N, 1) array of CV:
member i is feasible when

.. math::
    \mathrm{CV}_i \le \varepsilon_{cv}

(pymoo's ``FEAS``, with the individuals' ``cv_eps``, 0 by default); the infeasible ones are
ordered by ``numpy.argsort`` of their CV as pymoo orders them, the feasible ones go to
pymoo's ranking (its non-dominated sorting and crowding distance, the last front cut by
its randomised argsort), with their objectives read once per member and ``rank`` and
``crowding`` written into each member's ``data`` directly. Same survivors in the same
order, same ``rank`` and ``crowding`` data, same draws from the random generator
(``tests/optimise/test_survival.py`` compares both on mixed populations).

The crowding distance of a front F (n, m), n > 2, is pymoo's ``calc_crowding_distance``
(:func:`crowding_distance`, the same operations in the same order, hence the same bits):
per objective k, with the members sorted by :math:`F_{\cdot k}` (stable) and
:math:`F^{(0)}_k = -\infty`, :math:`F^{(n+1)}_k = +\infty` around them,

.. math::
    d_i = \frac{1}{m} \sum_k \frac{F^{(i+1)}_k - F^{(i-1)}_k}
          {\max F_{\cdot k} - \min F_{\cdot k}}

(a term 0 where all values of objective k are equal; :math:`+\infty` at the ends), and
:math:`+\infty` for every member of a front of at most two. It is here rather than taken
from pymoo's ``rank_and_crowding.metrics`` because that module imports ``scipy.spatial``
(slow, at the start of every run) for other crowding measures; another
``crowding_func`` than ``"cd"`` is still pymoo's.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pymoo.core.population import Population
from pymoo.core.survival import Survival
from pymoo.util import default_random_state
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting
from pymoo.util.randomized_argsort import randomized_argsort

from adept_traj.errors import InputShapeError
from adept_traj.optimise.operators.population import population_values

__all__ = ["RankAndCrowdingSurvival", "crowding_distance"]


def crowding_distance(F: np.ndarray) -> np.ndarray:
    """(n,) crowding distances of the objective vectors ``F`` (n, m) of one front, as
    pymoo's ``"cd"`` crowding function returns them (see the module docstring; +inf for
    n ≤ 2)."""
    F = np.array(F, dtype=np.double)
    if F.ndim != 2 or F.shape[1] < 1:
        raise InputShapeError(f"F must have shape (n, m) with m ≥ 1 objectives; got {F.shape}")
    n_points, n_obj = F.shape
    if n_points <= 2:
        return np.full(n_points, np.inf)
    order = np.argsort(F, axis=0, kind="mergesort")
    F = F[order, np.arange(n_obj)]
    dist = np.vstack([F, np.full(n_obj, np.inf)]) - np.vstack([np.full(n_obj, -np.inf), F])
    norm = np.max(F, axis=0) - np.min(F, axis=0)
    norm[norm == 0] = np.nan
    to_last, to_next = dist[:-1] / norm, dist[1:] / norm
    to_last[np.isnan(to_last)] = 0.0
    to_next[np.isnan(to_next)] = 0.0
    back = np.argsort(order, axis=0)
    columns = np.arange(n_obj)
    return np.sum(to_last[back, columns] + to_next[back, columns], axis=1) / n_obj


class _CrowdingDistance:
    """pymoo's ``"cd"`` crowding function object (``do(F, n_remove)``) by
    :func:`crowding_distance`."""

    def do(self, F: np.ndarray, n_remove: int = 0) -> np.ndarray:
        return crowding_distance(F)


class RankAndCrowdingSurvival(Survival):
    """pymoo's rank-and-crowding survival (NSGA-II's, MODE's here) with the feasibility
    split on arrays (see the module docstring). Parameters as pymoo's
    :class:`~pymoo.operators.survival.rank_and_crowding.RankAndCrowding`: ``nds`` the
    non-dominated sorting (default pymoo's), ``crowding_func`` ``"cd"`` (the crowding
    distance, :func:`crowding_distance`) or any of pymoo's."""

    def __init__(self, nds: Any = None, crowding_func: Any = "cd") -> None:
        super().__init__(filter_infeasible=True)
        self.nds = nds if nds is not None else NonDominatedSorting()
        if isinstance(crowding_func, str) and crowding_func == "cd":
            self.crowding_func: Any = _CrowdingDistance()
        else:  # pymoo's other measures (their module imports scipy.spatial)
            from pymoo.operators.survival.rank_and_crowding.metrics import (
                get_crowding_function,
            )

            self.crowding_func = get_crowding_function(crowding_func)

    @default_random_state
    def do(
        self,
        problem: Any,
        pop: Population,
        *args: Any,
        n_survive: int | None = None,
        random_state: Any = None,
        return_indices: bool = False,
        **kwargs: Any,
    ) -> Any:
        """The ``n_survive`` survivors of ``pop`` (all of it by default), as pymoo's
        ``Survival.do`` chooses them; their indices in ``pop`` if ``return_indices``."""
        if len(pop) == 0:
            return pop
        n_survive = len(pop) if n_survive is None else min(n_survive, len(pop))
        if not (self.filter_infeasible and problem.has_constraints()):
            survivors = self._do(
                problem, pop, *args, n_survive=n_survive, random_state=random_state, **kwargs
            )
        else:
            # one pass over the members: CV (n, 1), its tolerance, the objectives
            members = [(ind.CV, ind.config.get("cv_eps", 0.0), ind.F) for ind in pop]
            cv = np.array([m[0] for m in members])
            eps = np.array([m[1] for m in members])
            feasible = np.flatnonzero(cv[:, 0] <= eps)
            infeasible = np.flatnonzero(~(cv[:, 0] <= eps))
            infeasible = infeasible[np.argsort(cv[infeasible, 0])]
            if len(feasible) == 0:
                survivors = Population()
            else:
                survivors = self._do(
                    problem,
                    pop[feasible],
                    *args,
                    n_survive=min(len(feasible), n_survive),
                    random_state=random_state,
                    objectives=np.array([members[i][2] for i in feasible]),
                    **kwargs,
                )
            n_remaining = n_survive - len(survivors)
            if n_remaining > 0:
                survivors = Population.merge(survivors, pop[infeasible[:n_remaining]])
        if return_indices:
            where = {ind: k for k, ind in enumerate(pop)}
            return [where[ind] for ind in survivors]
        return survivors

    def _do(
        self,
        problem: Any,
        pop: Population,
        *args: Any,
        random_state: Any = None,
        n_survive: int | None = None,
        objectives: np.ndarray | None = None,
        **kwargs: Any,
    ) -> Population:
        """pymoo's ranking of (feasible) members, F read once per member (or given:
        ``objectives``, the members' F stacked) and ``rank`` and ``crowding`` written
        straight into each member's ``data`` (what pymoo's ``Individual.set`` does for a
        key that is not an attribute)."""
        F = population_values(pop, "F") if objectives is None else objectives
        F = F.astype(float, copy=False)
        survivors: list[int] = []
        for k, front in enumerate(self.nds.do(F, n_stop_if_ranked=n_survive)):
            keep = np.arange(len(front))
            if len(survivors) + len(keep) > n_survive:
                n_remove = len(survivors) + len(front) - n_survive
                crowding = self.crowding_func.do(F[front, :], n_remove=n_remove)
                keep = randomized_argsort(
                    crowding, order="descending", method="numpy", random_state=random_state
                )[:-n_remove]
            else:
                crowding = self.crowding_func.do(F[front, :], n_remove=0)
            for j, i in enumerate(front):
                data = pop[i].data
                data["rank"] = k
                data["crowding"] = crowding[j]
            survivors.extend(front[keep])
        return pop[survivors]
