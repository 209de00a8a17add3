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
(the same individuals removed, in the same order) without a distance matrix. A pair
within ε differs by at most ε in every variable, so its row sums differ by at most
:math:`n_{var}\,\varepsilon` plus the sums' rounding: the rows of Y sorted by their sum,
a binary search gives each row of X the few candidates whose sums are that close (for
a random population none but its copies). A candidate pair equal in every variable is
at distance 0; one differing by more than ε in a variable is farther than ε; only a
pair in between (a few ulps apart) has its distance computed, by the same scipy
``cdist`` as pymoo (imported then only: ``scipy.spatial`` is slow to import).
Candidate pairs are compared in blocks of at most :data:`BLOCK_PAIRS` / n_var pairs
(≈ 16 MB of differences), whatever N — also when many rows share a sum.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pymoo.core.duplicate import DefaultDuplicateElimination, default_attr

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.operators.population import population_values
from adept_traj.validation import as_integer, as_scalar

__all__ = ["BLOCK_PAIRS", "BlockedDuplicateElimination"]

#: Largest number of variable differences held at once (2²¹: 16 MiB of float64), i.e.
#: BLOCK_PAIRS / n_var candidate pairs.
BLOCK_PAIRS = 2**21


class BlockedDuplicateElimination(DefaultDuplicateElimination):
    """pymoo's default duplicate elimination without its distance matrix (see the module
    docstring).

    Parameters
    ----------
    epsilon:
        Largest Euclidean distance in decision space (the decision vector's own units:
        [rad] for control points, [s] for the travel time) at which two individuals are
        the same; pymoo's default 1e-16.
    block_pairs:
        Largest number of variable differences held at once (default
        :data:`BLOCK_PAIRS`); any value ≥ 1 gives the same decisions.
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
        X = np.asarray(X, dtype=float)
        own = Y is None
        Y = X if own else np.asarray(Y, dtype=float)
        marked = np.zeros(len(X), dtype=bool)
        if len(X) == 0 or len(Y) == 0:
            return marked
        lo, hi, order = self._windows(X, Y)
        counts = np.maximum(hi - lo, 0)
        budget = max(1, self.block_pairs // max(1, X.shape[1]))  # pairs compared at once
        ends = np.cumsum(counts)  # (n,) the last pair of each row, + 1
        start = 0
        while start < len(X):
            # Rows [start, stop): their candidate pairs fit the budget (at least one row).
            before = ends[start] - counts[start]
            stop = max(start + 1, int(np.searchsorted(ends, before + budget, side="right")))
            rows = np.arange(start, stop)
            i = np.repeat(rows, counts[rows])
            offset = np.repeat(lo[rows] - (ends[rows] - counts[rows] - before), counts[rows])
            j = order[np.arange(len(i)) + offset]
            if own:
                i, j = i[j < i], j[j < i]
            self._mark(X, Y, i, j, marked)
            start = stop
        return marked

    def _reach(self) -> float:
        """Largest difference [decision units] in one variable of a pair within
        ``epsilon``, with margin: their distance is at least that difference (squares and
        sums of non-negative terms only grow under rounding; 1e-150 where a square could
        underflow to 0)."""
        return max(self.epsilon * (1.0 + 1e-9), 1e-150)

    def _windows(self, X: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """For each row of ``X``, the range ``[lo, hi)`` of the rows of ``Y`` sorted by their
        sum (``order``) that can be within ``epsilon`` of it: every pair whose variables all
        differ by at most :meth:`_reach` has row sums within ``width`` (those differences
        plus both sums' rounding, at most n_var·2⁻⁵² times the sum of magnitudes each)."""
        n_var, reach = X.shape[1], self._reach()
        with np.errstate(invalid="ignore", over="ignore"):  # non-finite sums: below
            sx, sy = X.sum(axis=1), Y.sum(axis=1)
            scale = np.abs(X).sum(axis=1) + n_var * reach + 1.0
            width = 2.0 * n_var * reach + 8.0 * n_var * 2.0**-52 * scale
            order = np.argsort(sy, kind="stable")
            sorted_sums = sy[order]
            lo = np.searchsorted(sorted_sums, sx - width, side="left")
            hi = np.searchsorted(sorted_sums, sx + width, side="right")
        # A sum that is not finite (an overflow, an infinite or NaN variable) bounds
        # nothing: such a row is compared with every row of Y.
        wide = ~(np.isfinite(sx) & np.isfinite(width))
        lo[wide], hi[wide] = 0, len(Y)
        if not np.all(np.isfinite(sy)):
            lo[:], hi[:] = 0, len(Y)  # a non-finite sum of Y sorts anywhere: all pairs
        return lo, hi, order

    def _mark(self, X: np.ndarray, Y: np.ndarray, i: np.ndarray, j: np.ndarray, marked) -> None:
        """Mark the rows ``i`` of ``X`` within ``epsilon`` of the rows ``j`` of ``Y``."""
        with np.errstate(invalid="ignore"):  # inf − inf
            gap = np.abs(X[i] - Y[j]).max(axis=1, initial=0.0)  # NaN: never within
        # A pair differing by more than the reach in a variable is farther apart than
        # epsilon; a pair equal in every variable is at distance 0. Only pairs in between
        # (a few ulps apart) need the distance itself, as pymoo's cdist computes it.
        near = gap <= self._reach()
        marked[i[near & (gap == 0.0)]] = True
        for a, b in zip(i[near & (gap > 0.0)], j[near & (gap > 0.0)], strict=True):
            from scipy.spatial.distance import cdist  # rarely needed; heavy to import

            if cdist(X[a : a + 1], Y[b : b + 1])[0, 0] <= self.epsilon:
                marked[a] = True

    def _values(self, pop: Any) -> np.ndarray:
        """The decision vectors (n, n_var) of ``pop`` that ``func`` returns; pymoo's default
        ``func`` (``Population.get("X")``) read once per member (the same array)."""
        if self.func is default_attr:
            return np.asarray(population_values(pop, "X"), dtype=float)
        return np.asarray(self.func(pop), dtype=float)
