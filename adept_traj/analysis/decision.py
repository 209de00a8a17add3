r"""Choosing one trajectory from a Pareto front (paper Section 4, Step 4.3; Tables 3 and 4).

The paper selects its "best optimal solution trade-off" with two scalar scores used "in a
combined manner": the *average fitness factor* :math:`F_{avg}` (Table 3) and the
*combined objective function* :math:`f_c` of the "normalized weighting objective functions"
method (Table 4), with the weights :data:`PAPER_WEIGHTS`. Neither formula is printed. This
module implements

* :func:`normalise` — per-objective scores in [0, 1], 1 best (reproduces Table 3);
* :func:`average_fitness` — :math:`F_{avg}`, the mean score (reproduces Table 3: 0.683650
  and 0.852519 to within one unit of the 6th decimal);
* :func:`combined_objective` — :math:`f_c = \sum_i w_i (1 - n_i)`, lower is better
  (**does not reproduce Table 4**; no natural definition does, see the function and
  ``docs/decision-and-metrics.md``);
* :func:`best_tradeoff` — a documented, deterministic rule combining both scores.

Objective arrays ``F`` have shape ``(n, m)`` (paper: m = 6, ``[z1..z6]`` with z4 = :math:`|\det J|`
positive and maximised); the sense is given by ``maximised`` (default :data:`MAXIMISED`).
Inputs are never modified. Feasibility and non-dominance are the caller's business: pass
the feasible Pareto front.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from adept_traj.analysis.objective_arrays import as_objectives, as_sense, fraction_towards
from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.problem.objectives import MAXIMISED
from adept_traj.validation import as_finite_array, as_vector, readonly_copy

__all__ = [
    "PAPER_WEIGHTS",
    "BestTradeoff",
    "average_fitness",
    "best_tradeoff",
    "combined_objective",
    "normalise",
    "objective_weights",
]

PAPER_WEIGHTS: tuple[float, ...] = (0.25, 0.25, 0.1, 0.1, 0.15, 0.15)
"""The paper's sample weights w1..w6 for z1..z6 (Section 5; they sum to 1)."""


def _bounds(
    F: np.ndarray, z_min: ArrayLike | None, z_max: ArrayLike | None
) -> tuple[np.ndarray, np.ndarray]:
    """Return (Z_min, Z_max), each (m,): given values or the column extremes of F."""
    m = F.shape[1]
    lo = F.min(axis=0) if z_min is None else as_vector(z_min, "z_min", m)
    hi = F.max(axis=0) if z_max is None else as_vector(z_max, "z_max", m)
    if (lo > hi).any():
        j = int(np.argmax(lo > hi))
        raise InvalidInputError(
            f"z_min must not exceed z_max; objective {j}: z_min={lo[j]!r} > z_max={hi[j]!r}"
        )
    return lo, hi


def normalise(
    F: ArrayLike,
    z_min: ArrayLike | None = None,
    z_max: ArrayLike | None = None,
    maximised: bool | Sequence[bool] = MAXIMISED,
) -> np.ndarray:
    r"""Per-objective scores :math:`n_{ki}` with 1 for the best and 0 for the worst value.

    .. math::

        n_{ki} = \frac{Z_i^{\max} - z_{ki}}{Z_i^{\max} - Z_i^{\min}} \;(\text{minimised}),
        \qquad
        n_{ki} = \frac{z_{ki} - Z_i^{\min}}{Z_i^{\max} - Z_i^{\min}} \;(\text{maximised})

    Parameters
    ----------
    F: (n, m) objective values z (raw units: s, J, …, m² for z4).
    z_min, z_max: (m,) bounds :math:`Z^{\min}, Z^{\max}` (``z_min <= z_max``). Default: the
        column minimum / maximum of ``F``. To compare several fronts on one scale, as the
        paper's Table 3 does (its Z_max/Z_min rows are the extremes over the fronts being
        compared), pass the extremes of their union
        (:func:`~adept_traj.analysis.indicators.objective_bounds`).
    maximised: sense of each objective (bool or (m,) bools); default :data:`MAXIMISED`
        (only z4 maximised).

    Returns
    -------
    (n, m) new array of scores. With the default bounds every score lies in [0, 1]; with
    given bounds a value outside them scores outside [0, 1] (nothing is clipped).
    A **degenerate column** (:math:`Z_i^{\max} = Z_i^{\min}`, e.g. z3 = 0 for every
    collision-free solution) scores 1 for every solution: nobody is worse than anybody
    else in that objective.
    """
    arr = as_objectives(F, "F")
    m = arr.shape[1]
    sense = as_sense(maximised, m)
    lo, hi = _bounds(arr, z_min, z_max)
    return fraction_towards(arr, lo, hi, sense, flat=1.0)


def average_fitness(
    F: ArrayLike,
    z_min: ArrayLike | None = None,
    z_max: ArrayLike | None = None,
    maximised: bool | Sequence[bool] = MAXIMISED,
) -> np.ndarray:
    r"""Average fitness factor :math:`F_{avg}` of every solution (higher is better).

    .. math::

        F_{avg,k} = \frac{1}{m} \sum_{i=1}^{m} n_{ki} \in [0, 1]

    with :math:`n_{ki}` from :func:`normalise`. With the Z_max/Z_min rows of the paper's
    Table 3 this gives 0.6836490 for the NSGA-II row (Table 3: 0.683650; the difference,
    1.0e-6, is within the rounding of z1 = 0.898, printed to 3 decimals) and 0.8525191 for
    the MODE row (Table 3: 0.852519).

    Parameters
    ----------
    F, z_min, z_max, maximised: as :func:`normalise`.

    Returns
    -------
    (n,) array.
    """
    return normalise(F, z_min, z_max, maximised).mean(axis=1)


def objective_weights(weights: ArrayLike, m: int) -> np.ndarray:
    r"""Validate weights and rescale them to sum 1: :math:`w_i \leftarrow w_i / \sum_j w_j`.

    Parameters
    ----------
    weights: (m,) finite, non-negative, with a positive sum.
    m: number of objectives.

    Returns
    -------
    (m,) new array summing to 1.
    """
    w = as_finite_array(weights, "weights")
    if w.shape != (m,):
        raise InputShapeError(
            f"weights must have one entry per objective ({m},); got shape {w.shape}"
        )
    if (w < 0).any():
        raise InvalidInputError(f"weights must be non-negative; got {w.tolist()}")
    with np.errstate(over="ignore"):  # huge weights: handled below
        total = float(w.sum())
    if total <= 0.0:
        raise InvalidInputError(f"weights must have a positive sum; got {w.tolist()}")
    if not np.isfinite(total):  # huge weights: their sum overflows; scale them down first
        w = w / w.max()
        total = float(w.sum())
    return w / total


def combined_objective(
    F: ArrayLike,
    weights: ArrayLike = PAPER_WEIGHTS,
    z_min: ArrayLike | None = None,
    z_max: ArrayLike | None = None,
    maximised: bool | Sequence[bool] = MAXIMISED,
) -> np.ndarray:
    r"""Combined objective :math:`f_c` of every solution (lower is better).

    The normalised weighted sum of the normalised objectives ("normalized weighting
    objective functions"): with :math:`n_{ki}` from :func:`normalise` (1 best) and the
    weights rescaled to sum 1,

    .. math::

        f_{c,k} = \sum_{i=1}^{m} \hat w_i \,(1 - n_{ki}), \qquad
        \hat w_i = \frac{w_i}{\sum_j w_j}, \qquad f_{c,k} \in [0, 1]

    i.e. the weighted distance of each objective from its best value, as a fraction of the
    range; 0 for a solution that is best in every objective. With equal weights
    :math:`f_c = 1 - F_{avg}`.

    **Table 4 cannot be reproduced.** For the rows of Table 3 (bounds Z_max/Z_min, weights
    :data:`PAPER_WEIGHTS`) this definition gives f_c = 0.267611 (NSGA-II) and 0.221221
    (MODE); the paper prints 0.497040 and 0.467136. Other natural definitions (Σ w n,
    Σ w z/Z_max with or without a reversed z4, unweighted variants, …) do not give them
    either (see ``tests/analysis/test_decision.py`` and ``docs/decision-and-metrics.md``); the paper
    probably normalised by per-front values it does not print. Our definition keeps the
    paper's ordering (MODE < NSGA-II).

    Parameters
    ----------
    F: (n, m) objective values.
    weights: (m,) finite, non-negative, positive sum (rescaled to sum 1); default
        :data:`PAPER_WEIGHTS` (m = 6).
    z_min, z_max, maximised: as :func:`normalise`.

    Returns
    -------
    (n,) array.
    """
    scores = normalise(F, z_min, z_max, maximised)
    w = objective_weights(weights, scores.shape[1])
    return (1.0 - scores) @ w


@dataclass(frozen=True)
class BestTradeoff:
    r"""The chosen solution of :func:`best_tradeoff` and the scores behind the choice.

    Attributes
    ----------
    index: row of ``F`` chosen (``order[0]``).
    order: (n,) every row, best first by the same rule (for fall-backs).
    objectives: (m,) objective values of the chosen row (raw units).
    f_c: (n,) combined objective of every row (lower is better).
    F_avg: (n,) average fitness factor of every row (higher is better).
    rank_f_c: (n,) int rank of f_c, 1 = lowest (ties share the lowest rank).
    rank_F_avg: (n,) int rank of F_avg, 1 = highest (ties share the lowest rank).
    rank_sum: (n,) ``rank_f_c + rank_F_avg``; the chosen row minimises it.
    weights: (m,) weights used, rescaled to sum 1.
    z_min, z_max: (m,) normalisation bounds used.
    """

    index: int
    order: np.ndarray
    objectives: np.ndarray
    f_c: np.ndarray
    F_avg: np.ndarray
    rank_f_c: np.ndarray
    rank_F_avg: np.ndarray
    rank_sum: np.ndarray
    weights: np.ndarray
    z_min: np.ndarray
    z_max: np.ndarray

    def __post_init__(self) -> None:
        for field in ("objectives", "f_c", "F_avg", "weights", "z_min", "z_max"):
            object.__setattr__(self, field, readonly_copy(getattr(self, field)))
        for field in ("order", "rank_f_c", "rank_F_avg", "rank_sum"):
            arr = np.array(getattr(self, field), dtype=np.int64)
            arr.setflags(write=False)
            object.__setattr__(self, field, arr)


def _min_rank(values: np.ndarray) -> np.ndarray:
    """Competition ranks ("1224"): 1 + the number of strictly smaller values."""
    s = np.sort(values)
    return np.searchsorted(s, values, side="left") + 1


def best_tradeoff(
    F: ArrayLike,
    weights: ArrayLike = PAPER_WEIGHTS,
    z_min: ArrayLike | None = None,
    z_max: ArrayLike | None = None,
    maximised: bool | Sequence[bool] = MAXIMISED,
) -> BestTradeoff:
    r"""Pick the best trade-off with :math:`f_c` and :math:`F_{avg}` "in a combined manner".

    The paper does not say how the two scores are combined. Rule used here (deterministic):

    1. rank every solution by :math:`f_c` ascending and by :math:`F_{avg}` descending
       (competition ranks: 1 = best, equal values share the lower rank);
    2. choose the minimal rank sum :math:`r^{f_c}_k + r^{F_{avg}}_k`;
    3. ties: lower :math:`f_c`, then lower row index. (Equal rank sums and equal
       :math:`f_c` imply equal :math:`F_{avg}` ranks, hence equal :math:`F_{avg}`: no
       further key is needed.)

    .. math::

        k^\star = \operatorname*{arg\,min}_k \big( r^{f_c}_k + r^{F_{avg}}_k,\;
        f_{c,k},\; k \big) \quad \text{(lexicographic)}

    Ranks make the two scores commensurable without a further weight; a solution that is
    best in both is always chosen. :math:`f_c` carries the user's preferences (weights),
    :math:`F_{avg}` the unweighted balance. With equal weights the two rankings coincide.

    Parameters
    ----------
    F: (n, m) objective values of the (feasible, non-dominated) front, n ≥ 1.
    weights, z_min, z_max, maximised: as :func:`combined_objective`. By default the bounds
        are the extremes of ``F``; pass common bounds to choose on the scale of several
        fronts.

    Returns
    -------
    :class:`BestTradeoff`.
    """
    arr = as_objectives(F, "F")
    lo, hi = _bounds(arr, z_min, z_max)
    w = objective_weights(weights, arr.shape[1])
    f_c = combined_objective(arr, w, lo, hi, maximised)
    f_avg = average_fitness(arr, lo, hi, maximised)
    rank_fc = _min_rank(f_c)
    rank_avg = _min_rank(-f_avg)
    rank_sum = rank_fc + rank_avg
    order = np.lexsort((np.arange(arr.shape[0]), f_c, rank_sum))
    index = int(order[0])
    return BestTradeoff(
        index=index,
        order=order,
        objectives=arr[index],
        f_c=f_c,
        F_avg=f_avg,
        rank_f_c=rank_fc,
        rank_F_avg=rank_avg,
        rank_sum=rank_sum,
        weights=w,
        z_min=lo,
        z_max=hi,
    )
