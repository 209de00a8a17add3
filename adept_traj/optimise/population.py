"""Arrays of a pymoo population's members, read once per member.

pymoo's ``Population.get(key)`` asks each member ``hasattr(ind, key)`` then
``getattr(ind, key)``: every property (``CV``, ``FEAS``, …) is evaluated twice, through
two Python calls per member. The optimiser reads the population after every generation
(the loop's progress and fronts, the checkpoint, the fast-end search, the survival), so
:func:`population_values` reads each member's public attribute once and stacks the values
exactly as ``Population.get`` does (same array, bit for bit).
"""

from __future__ import annotations

import numpy as np
from pymoo.core.population import Population

__all__ = ["population_values"]


def population_values(pop: Population, key: str) -> np.ndarray:
    """The attribute ``key`` of every member of ``pop``, stacked as pymoo's
    ``Population.get(key)`` stacks it: ``"X"`` (n, n_var), ``"F"`` (n, n_obj), ``"G"``
    (n, n_constr), ``"CV"`` (n, 1) for n members ((0,) for an empty population)."""
    return np.array([getattr(ind, key) for ind in pop])
