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
:func:`select_parents` is pymoo's ``TournamentSelection`` of it (pressure 2): pymoo's
random permutations of the members, paired, decided on :class:`TournamentArrays` read once
per generation for all of its mating rounds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from pymoo.util.misc import random_permutations

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.operators.population import population_values

__all__ = ["TournamentArrays", "binary_tournament", "select_parents"]


def binary_tournament(pop: Any, P: np.ndarray, algorithm: Any, **kwargs: Any) -> np.ndarray:
    """Winners (n, 1) (int) of the tournaments ``P`` (n, 2) (member indices into ``pop``),
    as pymoo's NSGA-II ``binary_tournament`` chooses them (see the module docstring).

    Raises
    ------
    ConfigurationError
        ``P`` is not (n, 2), or an unknown ``algorithm.tournament_type``.
    """
    return _decide(pop, TournamentArrays.of(pop), P, algorithm, **kwargs)


@dataclass(frozen=True)
class TournamentArrays:
    """What the tournaments read of a population, read once: ``cv`` (n,) the total
    constraint violations, ``F`` (n, m) the objectives, ``rank`` and ``crowding`` (n,)
    (NaN where a member has none) and ``missing`` (n,) bool (no rank or no crowding).
    Valid while the population's members do not change (one generation's mating)."""

    cv: np.ndarray
    F: np.ndarray
    rank: np.ndarray
    crowding: np.ndarray
    missing: np.ndarray

    @classmethod
    def of(cls, pop: Any) -> TournamentArrays:
        """The arrays of the members of ``pop``."""
        data = [ind.data for ind in pop]
        rank = [d.get("rank") for d in data]
        crowding = [d.get("crowding") for d in data]
        return cls(
            cv=population_values(pop, "CV")[:, 0],
            F=population_values(pop, "F"),
            rank=np.array([np.nan if r is None else r for r in rank], dtype=float),
            crowding=np.array([np.nan if c is None else c for c in crowding], dtype=float),
            missing=np.array([r is None or c is None for r, c in zip(rank, crowding)], bool),
        )


def select_parents(
    pop: Any,
    arrays: TournamentArrays,
    n_select: int,
    n_parents: int,
    algorithm: Any,
    random_state: np.random.Generator,
    **kwargs: Any,
) -> np.ndarray:
    """Parents (n_select, n_parents) (member indices into ``pop``) chosen by binary
    tournaments, as pymoo's ``TournamentSelection(func_comp=binary_tournament)`` (pressure
    2) chooses them from the same generator: ``ceil(2·n_select·n_parents / n)``
    permutations of the n members (pymoo's ``random_permutations``), cut and paired, each
    pair decided by :func:`binary_tournament` on ``arrays`` (read once per population)."""
    n_random = n_select * n_parents * 2
    n_perms = math.ceil(n_random / len(pop))
    P = random_permutations(n_perms, len(pop), random_state=random_state)[:n_random]
    P = np.reshape(P, (n_select * n_parents, 2))
    winners = _decide(pop, arrays, P, algorithm, random_state=random_state, **kwargs)
    return np.reshape(winners, (n_select, n_parents))


def _decide(
    pop: Any, arrays: TournamentArrays, P: np.ndarray, algorithm: Any, **kwargs: Any
) -> np.ndarray:
    """:func:`binary_tournament` with the members' values read already."""
    P = np.asarray(P)
    if P.ndim != 2 or P.shape[1] != 2:
        raise ConfigurationError(f"binary tournaments need P of shape (n, 2); got {P.shape}")
    kind = algorithm.tournament_type
    if kind not in ("comp_by_dom_and_crowding", "comp_by_rank_and_crowding"):
        raise ConfigurationError(f"unknown tournament type {kind!r}")
    a, b = P[:, 0], P[:, 1]
    cv = arrays.cv
    infeasible = (cv[a] > 0.0) | (cv[b] > 0.0)
    if arrays.missing[a[~infeasible]].any() or arrays.missing[b[~infeasible]].any():
        # A feasible member without survival data: pymoo's loop (and its errors). Its
        # module imports scipy.spatial: only here.
        from pymoo.algorithms.moo.nsga2 import binary_tournament as pymoo_tournament

        return pymoo_tournament(pop, P, algorithm, **kwargs)
    rank_arr, crowd_arr = arrays.rank, arrays.crowding

    # Feasible pairs: Pareto dominance (or rank), then crowding (larger is better).
    if kind == "comp_by_dom_and_crowding":
        F = arrays.F
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
