r"""Arrays of a pymoo population's members, read once per member, and the per-member
values pymoo computes one member at a time, computed for the whole population at once.

pymoo's ``Population.get(key)`` asks each member ``hasattr(ind, key)`` then
``getattr(ind, key)``: every property (``CV``, ``FEAS``, …) is evaluated twice, through
two Python calls per member. The optimiser reads the population after every generation
(the loop's progress and fronts, the checkpoint, the fast-end search, the survival), so
:func:`population_values` reads each member's public attribute once and stacks the values
exactly as ``Population.get`` does (same array, bit for bit).

A member's total constraint violation CV is computed by pymoo lazily, on its first read,
by ``calc_cv`` — one Python call chain per member.
:func:`cache_violations` computes it for every freshly evaluated member at once, with the
same operations (hence the same bits) for pymoo's default configuration:

.. math::
    \mathrm{CV}_i = \sum_j \max(0,\ G_{ij} - 0) + 0 .

:func:`optimum` is pymoo's ``filter_optimum(pop, least_infeasible=True)`` (what every
algorithm stores as ``opt`` after each generation) on these arrays. :func:`ranked_optimum`
is the same filter of the survivors of a rank-and-crowding survival without sorting them
again: the survivors' feasible non-dominated members are those the survival ranked 0 (a
survivor of rank k > 0 is dominated by a member of rank k − 1, which survived too, since
the fronts are filled in rank order).

:class:`ArrayEvaluator` is pymoo's ``Evaluator`` (what the algorithms of
:func:`~adept_traj.optimise.make_algorithm` evaluate with) writing the evaluated rows
into the members itself — pymoo's ``Population.set`` checks every value and calls
``Individual.set`` (``hasattr``, then ``setattr``) for every member and key — and setting
the members' CV as :func:`cache_violations` does, in the same pass: the same values in the
same members (each its own copy of its row), in less time.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pymoo.core.evaluator import Evaluator
from pymoo.core.individual import Individual, default_config
from pymoo.core.population import Population
from pymoo.util.nds.non_dominated_sorting import NonDominatedSorting

__all__ = [
    "ArrayEvaluator",
    "cache_violations",
    "optimum",
    "population_values",
    "ranked_optimum",
]


def population_values(pop: Population, key: str) -> np.ndarray:
    """The attribute ``key`` of every member of ``pop``, stacked as pymoo's
    ``Population.get(key)`` stacks it: ``"X"`` (n, n_var), ``"F"`` (n, n_obj), ``"G"``
    (n, n_constr), ``"CV"`` (n, 1) for n members ((0,) for an empty population)."""
    return np.array([getattr(ind, key) for ind in pop])


def cache_violations(pop: Population) -> None:
    """Set the total constraint violation CV ((1,) per member) of the members of ``pop``
    whose CV pymoo would compute with its default configuration (no equality constraints,
    inequality constraints G of one common length): the same numbers, bit for bit, as the
    member's lazy ``CV`` property, computed for all of them at once. Other members are left
    to pymoo. The members' ``G`` must not change afterwards (pymoo caches CV likewise)."""
    _set_violations(list(pop), [ind.G for ind in pop])


def _set_violations(members: list[Individual], G_rows: list[Any]) -> None:
    """:func:`cache_violations` of ``members`` whose inequality constraints are ``G_rows``."""
    default = default_config()
    chosen = [
        (ind, g)
        for ind, g in zip(members, G_rows, strict=True)
        if ind.config == default
        and (ind.H is None or len(ind.H) == 0)
        and isinstance(g, np.ndarray)
        and g.ndim == 1
    ]
    if not chosen or len({len(g) for _, g in chosen}) != 1 or len(chosen[0][1]) == 0:
        return
    G = np.array([g for _, g in chosen], dtype=float)  # (n, n_constr)
    # pymoo: sum(max(0, G - eps)) with eps = 0, plus the equality part, 0.0 without H.
    cv = np.sum(np.maximum(0.0, G - 0.0), axis=1) + 0.0
    for (ind, _), value in zip(chosen, cv, strict=True):
        ind.CV = np.array([value])


class ArrayEvaluator(Evaluator):
    """pymoo's :class:`~pymoo.core.evaluator.Evaluator` that writes the evaluated values
    into the members at once and sets their CV (see the module docstring). Parameters as
    pymoo's."""

    def _eval(self, problem: Any, pop: Population, evaluate_values_of: list, **kwargs: Any):
        out = problem.evaluate(
            population_values(pop, "X"),
            return_values_of=evaluate_values_of,
            return_as_dictionary=True,
            **kwargs,
        )
        members = list(pop)
        # pymoo's Individual.set asks each member hasattr(ind, key): for plain members,
        # whether their class has the attribute (F, G, H, ...), asked once per key
        plain = all(type(ind) is Individual for ind in members)
        for key, values in out.items():
            if values is None:
                continue
            if not isinstance(values, np.ndarray) or values.ndim == 0 or len(values) != len(pop):
                pop.set(key, values)  # pymoo's own handling (and errors)
                continue
            # pymoo's Population.set: a view of a row is copied (no array kept alive by it)
            rows = [row.copy() for row in values] if values.ndim > 1 else list(values)
            if plain and isinstance(getattr(Individual, key, None), property):
                for ind, row in zip(members, rows, strict=True):
                    setattr(ind, key, row)
                continue
            for ind, row in zip(members, rows, strict=True):
                if hasattr(ind, key):
                    setattr(ind, key, row)
                else:
                    ind.data[key] = row
        keys = out.keys()
        for ind in members:
            ind.evaluated.update(keys)
        _set_violations(members, [ind.G for ind in members])


def optimum(pop: Population | None) -> Population | None:
    """pymoo's ``filter_optimum(pop, least_infeasible=True)``: the non-dominated feasible
    members of ``pop`` (in pymoo's order), the single best one for one objective, else the
    least infeasible member; ``None`` for an empty population."""
    if pop is None or len(pop) == 0:
        return None
    eps = np.array([ind.config.get("cv_eps", 0.0) for ind in pop])
    cv = population_values(pop, "CV")
    ret: Any = pop[cv[:, 0] <= eps]
    if len(ret) > 0:
        F = population_values(ret, "F")
        if F.shape[1] > 1:
            ret = ret[NonDominatedSorting().do(F, only_non_dominated_front=True)]
        else:
            ret = ret[np.argmin(F[:, 0])]
    else:
        ret = pop[np.argmin(cv)]
    if isinstance(ret, Individual):
        ret = Population().create(ret)
    return ret


def ranked_optimum(pop: Population | None) -> Population | None:
    """:func:`optimum` of the survivors ``pop`` of
    :class:`~adept_traj.optimise.RankAndCrowdingSurvival` (the same members in the same
    order): the feasible members with ``rank`` 0, read from each member's data instead of
    sorting the population again (see the module docstring). A population whose feasible
    members are not all ranked, or with one objective, goes to :func:`optimum`."""
    if pop is None or len(pop) < 2:
        return optimum(pop)
    feasible = np.empty(len(pop), dtype=bool)
    rank = np.empty(len(pop), dtype=object)
    for i, ind in enumerate(pop):  # one pass: CV, its tolerance and the survival's rank
        feasible[i] = ind.CV[0] <= ind.config.get("cv_eps", 0.0)
        rank[i] = ind.data.get("rank")
    n_obj = len(pop[0].F)
    if not feasible.any() or n_obj < 2 or any(r is None for r in rank[feasible]):
        return optimum(pop)
    return pop[feasible & (rank == 0)]
