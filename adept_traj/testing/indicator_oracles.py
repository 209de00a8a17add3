"""Independent references for the indicator tests: plain numpy, no code shared with
:mod:`adept_traj.analysis` (which calls moocore and pymoo).

* :func:`wfg_hypervolume` — the exact WFG hypervolume (While, Bradstreet & Barone, IEEE
  TEVC 16(1), 2012) with last-objective sorting; grid slicing for d ≤ 4 and small sets, a
  sorted sweep in 2-D. It was the library's own implementation until moocore replaced it
  (``benchmarks/bench_indicators.py`` measures both).
* :func:`dominated_mask` — the O(n² m) pairwise Pareto-dominance test, written out.
* :func:`igd_loop` — the IGD formula as a double loop.

Every function works in minimisation form on float arrays.
"""

from __future__ import annotations

import numpy as np

# Cells per block of the grid-slicing hypervolume (also its threshold for d >= 5).
_GRID_CELLS = 2_000_000


def dominated_mask(P: np.ndarray) -> np.ndarray:
    """(n,) bool: row i is dominated by some row of ``P`` (n, m) (duplicates are not
    dominated by each other)."""
    le = (P[None, :, :] <= P[:, None, :]).all(axis=-1)  # (n, n): P_j ≤ P_i
    lt = (P[None, :, :] < P[:, None, :]).any(axis=-1)  # P_j < P_i somewhere
    return (le & lt).any(axis=1)


def first_copies(P: np.ndarray) -> np.ndarray:
    """(n,) bool: the first occurrence of every distinct row of ``P``."""
    _, first = np.unique(P, axis=0, return_index=True)
    out = np.zeros(len(P), dtype=bool)
    out[first] = True
    return out


def igd_loop(A: np.ndarray, R: np.ndarray) -> float:
    """IGD(A, R) = mean over r ∈ R of min over a ∈ A of ‖r − a‖₂, one point at a time."""
    total = 0.0
    for r in R:
        total += min(float(np.sqrt(((r - a) ** 2).sum())) for a in A)
    return total / len(R)


def _hv2(P: np.ndarray, ref: np.ndarray) -> float:
    """2-D hypervolume of any point set strictly dominating ``ref``."""
    order = np.argsort(P[:, 0], kind="stable")
    x = P[order, 0]
    y = np.minimum.accumulate(P[order, 1])
    widths = np.diff(np.append(x, ref[0]))
    return float((widths * (ref[1] - y)).sum())


def _hv_grid(P: np.ndarray, ref: np.ndarray) -> float:
    """Hypervolume (d ≥ 3) of any point set strictly dominating ``ref`` by grid slicing:
    a cell of the grid over objectives 3…d has a 2-D cross-section given by a sweep over
    the points whose rank in every objective j ≥ 3 is ≤ the cell's index."""
    n, d = P.shape
    Q = P[np.argsort(P[:, 0], kind="stable")]
    widths = np.diff(np.append(Q[:, 0], ref[0]))
    y = Q[:, 1]
    heights, ranks = [], []
    for j in range(2, d):
        order = np.argsort(Q[:, j], kind="stable")
        heights.append(np.diff(np.append(Q[order, j], ref[j])))
        rank = np.empty(n, dtype=np.intp)
        rank[order] = np.arange(n)
        ranks.append(rank)
    levels = np.arange(n)
    inner = np.ones((n,), dtype=bool)
    for rank in ranks[:-1]:
        inner = (rank <= levels.reshape((n,) + (1,) * inner.ndim)) & inner
    block = max(1, _GRID_CELLS // inner.size)
    total = 0.0
    for k0 in range(0, n, block):
        ks = levels[k0 : k0 + block]
        mask = (ranks[-1] <= ks.reshape((-1,) + (1,) * inner.ndim)) & inner
        yy = np.minimum.accumulate(np.where(mask, y, ref[1]), axis=-1)
        res = (ref[1] - yy) @ widths
        for h in heights[-2::-1]:
            res = np.tensordot(res, h, axes=([1], [0]))
        total += float(heights[-1][ks] @ res)
    return total


def _nondominated_unique(P: np.ndarray) -> np.ndarray:
    """Rows of ``P`` that are not dominated, one copy of each."""
    if len(P) < 2:
        return P
    return P[~dominated_mask(P) & first_copies(P)]


def _wfg(P: np.ndarray, ref: np.ndarray) -> float:
    """WFG on a non-dominated set ``P`` (n, d) strictly dominating ``ref`` (d,)."""
    n, d = P.shape
    if n == 0:
        return 0.0
    if n == 1:
        return float(np.prod(ref - P[0]))
    if d == 1:
        return float(ref[0] - P[:, 0].min())
    if d == 2:
        return _hv2(P, ref)
    if d <= 4 or n ** (d - 1) <= _GRID_CELLS:
        return _hv_grid(P, ref)
    # Worst-first in the last objective: each limit set shares the last coordinate.
    P = P[np.argsort(-P[:, -1], kind="stable")]
    head, last = P[:, :-1], P[:, -1]
    boxes = np.prod(ref[:-1] - head, axis=1)
    total = 0.0
    for k in range(n):
        exclusive = boxes[k]
        if k + 1 < n:
            limit = np.maximum(head[k + 1 :], head[k])
            if (limit == head[k]).all(axis=1).any():
                continue
            exclusive -= _wfg(_nondominated_unique(limit), ref[:-1])
        total += (ref[-1] - last[k]) * exclusive
    return total


def wfg_hypervolume(P: np.ndarray, ref: np.ndarray) -> float:
    """Exact hypervolume of the points of ``P`` (n, m) that strictly dominate ``ref`` (m,)
    (minimisation)."""
    P = np.asarray(P, dtype=float)
    ref = np.asarray(ref, dtype=float)
    P = P[(ref > P).all(axis=1)]
    return _wfg(_nondominated_unique(P), ref)
