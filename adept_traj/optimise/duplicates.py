r"""Duplicate elimination in blocks of bounded memory.

pymoo's :class:`~pymoo.core.duplicate.DefaultDuplicateElimination` (what
``eliminate_duplicates=True`` switches on) marks an individual :math:`i` of a population
:math:`X` (N, n_var) as a duplicate when

.. math::
    \exists\, j < i:\ \lVert x_i - x_j \rVert_2 \le \varepsilon
    \qquad\text{or, against other populations } Y:\qquad
    \exists\, j:\ \lVert x_i - y_j \rVert_2 \le \varepsilon ,

with :math:`\varepsilon = 10^{-16}` and NaN distances never equal. It builds the whole
(N, N) distance matrix and the indices of its upper triangle: about 17.5 B per pair,
≈ 440 MB at N = 5 000. :class:`BlockedDuplicateElimination` takes the same decisions
(the same individuals removed, in the same order — each distance is the same scipy
``cdist`` value of the same pair) from blocks of rows whose distance matrix holds at most
:data:`BLOCK_PAIRS` pairs (≈ 16 MB for the matrix and ≈ 4 MB of masks), whatever N.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pymoo.core.duplicate import DefaultDuplicateElimination, default_attr
from scipy.spatial.distance import cdist

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.population import population_values
from adept_traj.validation import as_integer, as_scalar

__all__ = ["BLOCK_PAIRS", "BlockedDuplicateElimination"]

#: Largest number of (row, column) pairs whose distances are held at once: 2²¹ pairs,
#: 16 MiB of float64 distances.
BLOCK_PAIRS = 2**21


class BlockedDuplicateElimination(DefaultDuplicateElimination):
    """pymoo's default duplicate elimination with the distances computed in row blocks.

    Parameters
    ----------
    epsilon:
        Largest Euclidean distance in decision space (the decision vector's own units:
        [rad] for control points, [s] for the travel time) at which two individuals are
        the same; pymoo's default 1e-16.
    block_pairs:
        Largest number of distances held at once (default :data:`BLOCK_PAIRS`); any
        value ≥ 1 gives the same decisions.
    """

    def __init__(self, epsilon: float = 1e-16, block_pairs: int = BLOCK_PAIRS, **kwargs: Any):
        bad = ConfigurationError
        super().__init__(epsilon=as_scalar(epsilon, "epsilon", minimum=0.0, error=bad), **kwargs)
        self.block_pairs = as_integer(block_pairs, "block_pairs", minimum=1, error=bad)

    def _do(self, pop: Any, other: Any, is_duplicate: np.ndarray) -> np.ndarray:
        X = self._values(pop)
        Y = None if other is None else self._values(other)
        is_duplicate[self.duplicates(X, Y)] = True
        return is_duplicate

    def duplicates(self, X: np.ndarray, Y: np.ndarray | None = None) -> np.ndarray:
        """(n,) bool: which rows of the decision vectors ``X`` (n, n_var) duplicate an earlier
        row of ``X`` (``Y`` None) or any row of ``Y`` (m, n_var) — the decisions of
        :meth:`_do` on arrays (the module's definition, ε = ``epsilon``)."""
        n, own = len(X), Y is None
        Y = X if Y is None else Y
        marked = np.zeros(n, dtype=bool)
        rows = max(1, self.block_pairs // max(1, len(Y)))
        for start in range(0, n, rows):
            stop = min(n, start + rows)
            if own:
                # Only the columns j < i count: those of rows [start, stop) end before stop.
                D = cdist(X[start:stop], X[:stop])
                j = np.arange(stop)
                D[j[None, :] >= np.arange(start, stop)[:, None]] = np.inf
            else:
                D = cdist(X[start:stop], Y)
            D[np.isnan(D)] = np.inf
            marked[start:stop] = np.less_equal(D, self.epsilon).any(axis=1)
        return marked

    def _values(self, pop: Any) -> np.ndarray:
        """The decision vectors (n, n_var) of ``pop`` that ``func`` returns; pymoo's default
        ``func`` (``Population.get("X")``) read once per member (the same array)."""
        if self.func is default_attr:
            return np.asarray(population_values(pop, "X"), dtype=float)
        return np.asarray(self.func(pop), dtype=float)
