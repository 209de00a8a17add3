r"""NSGA-II's binary tournament (pymoo's ``binary_tournament``) on arrays.

pymoo's :func:`pymoo.algorithms.moo.nsga2.binary_tournament` decides each tournament
(a, b) in a Python loop, reading ``CV``, ``F``, ``rank`` and ``crowding`` member by member:

- if either is infeasible (:math:`\mathrm{CV} > 0`), the smaller CV wins;
- else the one that Pareto-dominates the other wins (``"comp_by_dom_and_crowding"``,
  NSGA-II's) or the smaller rank (``"comp_by_rank_and_crowding"``), and if that decides
  nothing, the larger crowding distance;
- a tie at the last comparison is broken by ``algorithm.random_state.choice([a, b])``.

:func:`binary_tournament` takes every decision at once on arrays (comparisons involving
NaN are ties, as in pymoo) and breaks the ties with the same draws, one per tie, in the
tournaments' order: the same winners and the same generator state.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.population import population_values

__all__ = ["binary_tournament"]


def binary_tournament(pop: Any, P: np.ndarray, algorithm: Any, **kwargs: Any) -> np.ndarray:
    """Winners (n, 1) (int) of the tournaments ``P`` (n, 2) (member indices into ``pop``),
    as pymoo's NSGA-II ``binary_tournament`` chooses them (see the module docstring).

    Raises
    ------
    ConfigurationError
        ``P`` is not (n, 2), or an unknown ``algorithm.tournament_type``.
    """
    P = np.asarray(P)
    if P.ndim != 2 or P.shape[1] != 2:
        raise ConfigurationError(f"binary tournaments need P of shape (n, 2); got {P.shape}")
    kind = algorithm.tournament_type
    if kind not in ("comp_by_dom_and_crowding", "comp_by_rank_and_crowding"):
        raise ConfigurationError(f"unknown tournament type {kind!r}")
    a, b = P[:, 0], P[:, 1]
    cv = population_values(pop, "CV")[:, 0]
    infeasible = (cv[a] > 0.0) | (cv[b] > 0.0)
    data = [ind.data for ind in pop]
    rank = [d.get("rank") for d in data]
    crowding = [d.get("crowding") for d in data]
    feasible_members = np.union1d(a[~infeasible], b[~infeasible])
    if any(crowding[i] is None or rank[i] is None for i in feasible_members):
        # A feasible member without survival data: pymoo's loop (and its errors). Its
        # module imports scipy.spatial: only here.
        from pymoo.algorithms.moo.nsga2 import binary_tournament as pymoo_tournament

        return pymoo_tournament(pop, P, algorithm, **kwargs)
    rank_arr = np.array([np.nan if r is None else r for r in rank], dtype=float)
    crowd_arr = np.array([np.nan if c is None else c for c in crowding], dtype=float)

    # Feasible pairs: Pareto dominance (or rank), then crowding (larger is better).
    if kind == "comp_by_dom_and_crowding":
        F = population_values(pop, "F")
        a_better = (F[a] < F[b]).any(axis=1)
        b_better = (F[b] < F[a]).any(axis=1)
        first = a_better & ~b_better
        second = b_better & ~a_better
    else:
        first = rank_arr[a] < rank_arr[b]
        second = rank_arr[a] > rank_arr[b]
    by_crowding = ~first & ~second
    crowd_first = by_crowding & (crowd_arr[a] > crowd_arr[b])
    crowd_second = by_crowding & (crowd_arr[a] < crowd_arr[b])
    feasible_a = first | crowd_first
    feasible_tie = by_crowding & ~crowd_first & ~crowd_second

    # Infeasible pairs: the smaller CV.
    cv_a, cv_b = cv[a] < cv[b], cv[a] > cv[b]
    winner = np.where(infeasible, np.where(cv_a, a, b), np.where(feasible_a, a, b))
    tie = np.where(infeasible, ~cv_a & ~cv_b, feasible_tie)
    rng = algorithm.random_state
    for i in np.flatnonzero(tie):  # pymoo's draws, one per tie, in order
        winner[i] = rng.choice([a[i], b[i]])
    return winner[:, None].astype(int, copy=False)
