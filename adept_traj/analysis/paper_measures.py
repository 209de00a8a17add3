r"""The four performance measures the paper names (Section 4, Step 4; Table 5).

The paper gives no formulas for the *solution spread measure* (SSM), the *ratio of
non-dominated individuals* (RNI), the *optimiser overhead* (OO) and the *algorithm effort*
(AE); this module implements them from their usual sources (``docs/decision-and-metrics.md``
gives the formulas with references and explains every choice):

* :func:`spread` — SSM, Deb's Δ (2 objectives) or its generalisation by Zhou et al.;
* :func:`ratio_non_dominated` — RNI (Tan, Lee & Khor 2002);
* :func:`optimizer_overhead` — OO, the share of the run time outside evaluations;
* :func:`algorithm_effort` — AE, run time per evaluation [s].

Objective arrays ``F`` have shape ``(n, m)`` and the sense of each objective is given by
``maximised`` (default :data:`~adept_traj.problem.MAXIMISED`), as in
:mod:`adept_traj.analysis.indicators`, which holds the standard indicators (hypervolume,
IGD) and the dominance test. Inputs are never modified.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from adept_traj.analysis.indicators import non_dominated
from adept_traj.analysis.objective_arrays import as_objectives, as_sense, minimisation_form
from adept_traj.errors import ConfigurationError, InputShapeError, InvalidInputError
from adept_traj.problem.objectives import MAXIMISED
from adept_traj.validation import as_integer, as_scalar

__all__ = [
    "algorithm_effort",
    "optimizer_overhead",
    "ratio_non_dominated",
    "spread",
]

# Rows per block of the O(n² m) nearest-neighbour distances (peak memory ~block·n·m).
_BLOCK = 256


# --------------------------------------------------------------------------------------
# Ratio of non-dominated individuals (RNI)
# --------------------------------------------------------------------------------------
def ratio_non_dominated(F: ArrayLike, maximised: bool | Sequence[bool] = MAXIMISED) -> float:
    r"""Ratio of non-dominated individuals, RNI (Tan, Lee & Khor 2002).

    .. math::

        \mathrm{RNI} = \frac{|\{x \in P : x \text{ non-dominated in } P\}|}{|P|}
        \in (0, 1]

    Parameters
    ----------
    F: (n, m) objective values of the whole population P (n = population size), not only
        its front. Duplicates of a non-dominated point all count as non-dominated.
    maximised: sense of each objective; default :data:`MAXIMISED`.
    """
    mask = non_dominated(F, maximised)
    return float(mask.sum()) / mask.size


# --------------------------------------------------------------------------------------
# Spread (SSM)
# --------------------------------------------------------------------------------------
def _extremes(R: np.ndarray) -> np.ndarray:
    """(m, m): for each objective j, the row of R (minimisation form) with the largest
    value of objective j — the end of the front along axis j (Zhou et al. 2006; jMetal).
    Ties are broken by the smallest sum of the other objectives, then the lowest index."""
    m = R.shape[1]
    out = np.empty((m, m))
    total = R.sum(axis=1)
    for j in range(m):
        candidates = np.flatnonzero(R[:, j] == R[:, j].max())
        others = total[candidates] - R[candidates, j]
        out[j] = R[candidates[np.argmin(others)]]
    return out


def _nearest_neighbour_distances(P: np.ndarray) -> np.ndarray:
    """(n,) Euclidean distance from each row of P to its nearest *other* row."""
    n = P.shape[0]
    out = np.empty(n)
    for start in range(0, n, _BLOCK):
        block = P[start : start + _BLOCK]
        d = np.sqrt(((block[:, None, :] - P[None, :, :]) ** 2).sum(axis=-1))
        idx = np.arange(block.shape[0])
        d[idx, start + idx] = np.inf
        out[start : start + _BLOCK] = d.min(axis=1)
    return out


def spread(
    F: ArrayLike,
    reference: ArrayLike | None = None,
    *,
    maximised: bool | Sequence[bool] = MAXIMISED,
    method: Literal["auto", "deb", "generalized"] = "auto",
    normalise: bool = True,
) -> float:
    r"""Spread Δ of a front — the paper's *solution spread measure* (SSM). Lower is better.

    **Deb's spread** (Deb, Pratap, Agarwal & Meyarivan 2002, eq. (1); two objectives only).
    Sort the N points by the first objective; :math:`d_i` are the N − 1 distances between
    consecutive points, :math:`\bar d` their mean, :math:`d_f` and :math:`d_l` the distances
    from the two extreme points of the reference set to the first and last point:

    .. math::

        \Delta = \frac{d_f + d_l + \sum_{i=1}^{N-1} |d_i - \bar d|}{d_f + d_l + (N-1)\,\bar d}

    **Generalised spread** (Zhou, Jin, Zhang, Sendhoff & Tsang 2006; jMetal's
    ``GeneralizedSpread``), for any number m of objectives. :math:`d(X, S)` is the distance
    from X to its nearest *other* point of the front S, :math:`\bar d` the mean of
    :math:`d(X, S)` over S, and :math:`e_1 … e_m` the extreme points of the reference set:

    .. math::

        \Delta = \frac{\sum_{j=1}^{m} d(e_j, S) + \sum_{X \in S} |d(X, S) - \bar d|}
                      {\sum_{j=1}^{m} d(e_j, S) + |S|\,\bar d}

    Δ = 0 for a perfectly uniform front that reaches the extremes; Δ grows with clustering
    and with missing ends. ``e_j`` is the reference point with the *largest* value of
    objective j in minimisation form (the end of the front along axis j; ties: the smallest
    sum of the other objectives, then the lowest index). In two dimensions these are the two
    ends of the front, the same points as Deb's.

    Parameters
    ----------
    F: (n, m) objective values of the front S, n ≥ 2 (non-dominated, feasible: the caller
        filters). Duplicate points are kept (a duplicate has nearest-neighbour distance 0).
    reference: (k, m) reference set giving the extreme points (the true front if known, or
        the union of the fronts being compared). Default: ``F`` itself; the extreme points
        then belong to S, their distance terms vanish and Δ measures only the uniformity.
    maximised: sense of each objective (bool or (m,) bools); default :data:`MAXIMISED`.
    method: ``"deb"`` (m = 2 only), ``"generalized"``, or ``"auto"`` (Deb's formula for two
        objectives, the generalisation otherwise).
    normalise: if true (default) every objective is first scaled to [0, 1] by the
        minimum and maximum of the *reference set* (a constant column is left unscaled), so
        that objectives in different units (s, J, m², …) weigh alike. With ``False`` the raw
        values are used.

    Returns
    -------
    Δ ≥ 0 (dimensionless). If every distance in the formula is 0 (all points and extremes
    coincide: a collapsed front) Δ = 1 is returned, as jMetal does — the limit of Deb's
    formula for a front collapsed to one point when the extremes lie elsewhere.

    Notes
    -----
    Differences from jMetal's ``GeneralizedSpread``: duplicates count with distance 0 here
    (clustering, as in Deb's consecutive gaps), whereas jMetal skips zero distances; ties
    between extreme candidates are broken as described above rather than by sort order.

    Raises
    ------
    InputShapeError: bad shapes, fewer than 2 points, ``method="deb"`` with m ≠ 2.
    InvalidInputError: non-finite values, unknown ``method``.
    """
    arr = as_objectives(F, "F", min_rows=2)
    m = arr.shape[1]
    sense = as_sense(maximised, m)
    if reference is None:
        ref = arr
    else:
        ref = as_objectives(reference, "reference")
        if ref.shape[1] != m:
            raise InputShapeError(f"reference must have {m} columns like F; got shape {ref.shape}")
    if method not in ("auto", "deb", "generalized"):
        raise InvalidInputError(f"method must be 'auto', 'deb' or 'generalized'; got {method!r}")
    if method == "auto":
        method = "deb" if m == 2 else "generalized"
    if method == "deb" and m != 2:
        raise InputShapeError(f"Deb's spread needs exactly 2 objectives; F has {m}")

    S = minimisation_form(arr, sense)
    R = minimisation_form(ref, sense)
    if normalise:
        lo, hi = R.min(axis=0), R.max(axis=0)
        span = np.where(hi > lo, hi - lo, 1.0)
        S = (S - lo) / span
        R = (R - lo) / span
    E = _extremes(R)

    if method == "deb":
        S = S[np.lexsort((S[:, 1], S[:, 0]))]
        gaps = np.linalg.norm(np.diff(S, axis=0), axis=1)
        # first point (smallest f1) is the end towards the largest f2: extreme of objective 2
        d_f = float(np.linalg.norm(E[1] - S[0]))
        d_l = float(np.linalg.norm(E[0] - S[-1]))
        d_mean = float(gaps.mean())
        num = d_f + d_l + float(np.abs(gaps - d_mean).sum())
        den = d_f + d_l + gaps.size * d_mean
    else:
        d = _nearest_neighbour_distances(S)
        d_mean = float(d.mean())
        d_ext = np.sqrt(((E[:, None, :] - S[None, :, :]) ** 2).sum(axis=-1)).min(axis=1)
        num = float(d_ext.sum()) + float(np.abs(d - d_mean).sum())
        den = float(d_ext.sum()) + S.shape[0] * d_mean
    return 1.0 if den == 0.0 else num / den


# --------------------------------------------------------------------------------------
# Computational effort
# --------------------------------------------------------------------------------------
def optimizer_overhead(total_s: float, evaluation_s: float) -> float:
    r"""Optimiser overhead, OO: the share of the run time not spent evaluating solutions.

    .. math::

        \mathrm{OO} = \frac{T_{\mathrm{total}} - T_{\mathrm{eval}}}{T_{\mathrm{total}}}
        \in [0, 1]

    Parameters
    ----------
    total_s: wall-clock time of the whole run T_total [s], > 0.
    evaluation_s: time spent in objective/constraint evaluations T_eval [s],
        0 ≤ T_eval ≤ T_total.
    """
    total = as_scalar(total_s, "total_s", "[s]", minimum=0.0, strict=True)
    evaluation = as_scalar(evaluation_s, "evaluation_s", "[s]", minimum=0.0)
    if evaluation > total:
        raise ConfigurationError(
            f"evaluation_s ({evaluation!r} s) cannot exceed total_s ({total!r} s)"
        )
    return (total - evaluation) / total


def algorithm_effort(total_s: float, n_evaluations: int) -> float:
    r"""Algorithm effort, AE: run time per function evaluation [s].

    .. math::

        \mathrm{AE} = \frac{T_{\mathrm{run}}}{N_{\mathrm{eval}}}

    (Paper Table 4: 2 s / 87 = 0.02299.)

    Parameters
    ----------
    total_s: wall-clock run time T_run [s], ≥ 0.
    n_evaluations: number of objective-function evaluations N_eval, a positive integer.
    """
    total = as_scalar(total_s, "total_s", "[s]", minimum=0.0)
    return total / as_integer(n_evaluations, "n_evaluations", minimum=1)
