r"""Standard indicators of Pareto fronts, and the objective conventions of the package.

* :func:`non_dominated` — Pareto dominance (``moocore.is_nondominated``);
* :func:`hypervolume`, :func:`normalised_hypervolume` — the exact hypervolume
  (``moocore.hypervolume``), raw or in the unit box of :func:`to_unit_minimisation` on
  common :func:`objective_bounds`;
* :func:`igd` — the inverted generational distance (``pymoo.indicators.igd.IGD``).

The paper's own measures (SSM, RNI, OO, AE) are in :mod:`adept_traj.analysis.paper_measures`;
``docs/decision-and-metrics.md`` gives every formula with its reference.

Conventions
-----------
* Objective arrays ``F`` have shape ``(n, m)``, one row per solution. The *sense* of each
  objective is given by ``maximised`` (a bool, or one bool per column); the default
  :data:`MAXIMISED` is the paper's six objectives ``[z1..z6]`` with **z4 = |det J| positive
  and maximised** and all others minimised.
* Every function first maps ``F`` to "minimisation form" (maximised columns negated) where
  the sense matters. Inputs are never modified.
* Feasibility is the caller's business: pass only feasible solutions where that matters.

Why moocore
-----------
moocore (C; pymoo depends on it, so it is always installed) replaced the package's own
numpy WFG hypervolume and pairwise dominance test, which are now the independent oracles
of the tests (``tests/indicator_oracles.py``). ``benchmarks/bench_indicators.py`` times
both (6 objectives, mutually non-dominated points on the unit sphere); its figures are in
``docs/performance.md``.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

from adept_traj.analysis.objective_arrays import (
    as_objectives,
    as_sense,
    fraction_towards,
    minimisation_form,
)
from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.problem.objectives import MAXIMISED  # the objective table's sense
from adept_traj.validation import as_finite_array, as_vector

__all__ = [
    "DEFAULT_HV_REFERENCE",
    "hypervolume",
    "igd",
    "non_dominated",
    "normalised_hypervolume",
    "objective_bounds",
    "to_unit_minimisation",
]


#: Default reference point of :func:`normalised_hypervolume`, in the unit space where 0 is
#: the best bound and 1 the worst bound of every objective.
DEFAULT_HV_REFERENCE = 1.1


# --------------------------------------------------------------------------------------
# Dominance
# --------------------------------------------------------------------------------------
def non_dominated(
    F: ArrayLike,
    maximised: bool | Sequence[bool] = MAXIMISED,
    *,
    keep_duplicates: bool = True,
) -> np.ndarray:
    r"""Mask of the non-dominated rows of ``F`` (Pareto dominance).

    Row :math:`a` dominates row :math:`b` when, in minimisation form,

    .. math::

        a \preceq b \iff a_j \le b_j \;\forall j \;\wedge\; \exists j:\; a_j < b_j .

    Parameters
    ----------
    F: (n, m) objective values.
    maximised: sense of each objective (bool or (m,) bools); default :data:`MAXIMISED`.
    keep_duplicates: identical rows do not dominate each other, so by default every copy of
        a non-dominated point is marked ``True``; with ``False`` only the first copy is kept
        (``moocore.is_nondominated``'s ``keep_weakly``).

    Returns
    -------
    (n,) bool array. Feasibility is not considered: filter infeasible rows first.
    """
    arr = as_objectives(F, "F")
    P = minimisation_form(arr, as_sense(maximised, arr.shape[1]))
    import moocore  # on first use (its import costs more than a short run's search)

    return moocore.is_nondominated(P, keep_weakly=bool(keep_duplicates))


# --------------------------------------------------------------------------------------
# IGD
# --------------------------------------------------------------------------------------
def igd(F: ArrayLike, reference_front: ArrayLike) -> float:
    r"""Inverted generational distance (Coello & Reyes Sierra 2004), lower is better.

    .. math::

        \mathrm{IGD}(F, R) = \frac{1}{|R|} \sum_{r \in R} \min_{a \in F} \lVert r - a \rVert_2

    Parameters
    ----------
    F: (n, m) approximation front.
    reference_front: (k, m) reference front R (true front, or the non-dominated union of
        all compared fronts).

    Distances are taken in the units of the inputs: normalise both first (e.g. with
    :func:`to_unit_minimisation`) when the objectives have different units. The objective
    sense does not matter (Euclidean distance).
    """
    A = as_objectives(F, "F")
    R = as_objectives(reference_front, "reference_front")
    if R.shape[1] != A.shape[1]:
        raise InputShapeError(
            f"reference_front must have {A.shape[1]} columns like F; got shape {R.shape}"
        )
    from pymoo.indicators.igd import IGD  # with moocore, on first use

    return float(IGD(R).do(A))


# --------------------------------------------------------------------------------------
# Hypervolume
# --------------------------------------------------------------------------------------
def hypervolume(
    F: ArrayLike,
    reference_point: ArrayLike,
    maximised: bool | Sequence[bool] = MAXIMISED,
    method: Literal["auto", "moocore", "wfg"] = "auto",
) -> float:
    r"""Exact hypervolume of the region dominated by ``F`` and bounded by a reference point.

    In minimisation form (maximised columns and the reference point negated),

    .. math::

        \mathrm{HV}(F, r) = \lambda_m\Big(\bigcup_{a \in F,\; a \prec\prec r}
        [a_1, r_1] \times \dots \times [a_m, r_m]\Big)

    with :math:`\lambda_m` the Lebesgue measure. Points that do not strictly dominate ``r``
    in every objective contribute nothing; dominated and duplicate points are harmless.
    Computed by ``moocore.hypervolume`` (exact; see the module docstring for its cost).

    Parameters
    ----------
    F: (n, m) objective values, n ≥ 1.
    reference_point: (m,) reference point r, in the same units and sense as ``F`` (for a
        maximised column it lies *below* the points).
    maximised: sense of each objective; default :data:`MAXIMISED`.
    method: ``"auto"`` or ``"moocore"`` (the same). ``"wfg"``, the package's former numpy
        implementation, is deprecated: it warns and gives moocore's value (the same to
        within 1e-12 relative; moocore is much faster, ``docs/performance.md``).

    Returns
    -------
    HV ≥ 0, in the product of the objectives' units.
    """
    arr = as_objectives(F, "F")
    m = arr.shape[1]
    ref = as_vector(reference_point, "reference_point", m)
    sense = as_sense(maximised, m)
    if method not in ("auto", "moocore", "wfg"):
        raise InvalidInputError(f"method must be 'auto' or 'moocore'; got {method!r}")
    if method == "wfg":
        warnings.warn(
            "hypervolume(method='wfg') is deprecated: the value now always comes from moocore "
            "(the same to 1e-12); use method='auto'",
            DeprecationWarning,
            stacklevel=2,
        )
    P = minimisation_form(arr, sense)
    r = np.where(sense, -ref, ref)
    P = P[(r > P).all(axis=1)]
    if len(P) == 0:
        return 0.0
    import moocore

    return float(moocore.hypervolume(P, ref=r))


# --------------------------------------------------------------------------------------
# Normalisation for the hypervolume
# --------------------------------------------------------------------------------------
def objective_bounds(*fronts: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """Column-wise minimum and maximum over the union of one or more fronts.

    Parameters
    ----------
    *fronts: arrays of shape (n_k, m), same m.

    Returns
    -------
    ``(lower, upper)``, each (m,), in the raw units and sense of the objectives.
    """
    if not fronts:
        raise InvalidInputError("objective_bounds needs at least one front")
    arrays = [as_objectives(f, f"fronts[{i}]") for i, f in enumerate(fronts)]
    m = arrays[0].shape[1]
    for i, a in enumerate(arrays):
        if a.shape[1] != m:
            raise InputShapeError(f"fronts[{i}] has {a.shape[1]} columns; fronts[0] has {m}")
    stacked = np.concatenate(arrays, axis=0)
    return stacked.min(axis=0), stacked.max(axis=0)


def to_unit_minimisation(
    F: ArrayLike,
    lower: ArrayLike,
    upper: ArrayLike,
    maximised: bool | Sequence[bool] = MAXIMISED,
) -> np.ndarray:
    r"""Map objectives to a unit box where every objective is minimised: 0 best, 1 worst.

    .. math::

        u_j = \frac{z_j - L_j}{U_j - L_j} \;(\text{minimised}), \qquad
        u_j = \frac{U_j - z_j}{U_j - L_j} \;(\text{maximised})

    A degenerate column (:math:`U_j = L_j`) maps to 0 (every solution at the best bound,
    consistent with :func:`~adept_traj.analysis.decision.normalise`, where it scores 1).
    Values outside [L, U] map outside [0, 1]; nothing is clipped.

    Parameters
    ----------
    F: (n, m) objective values.
    lower, upper: (m,) bounds in raw units (e.g. :func:`objective_bounds` over all fronts
        being compared), ``lower <= upper``.
    maximised: sense of each objective; default :data:`MAXIMISED`.

    Returns
    -------
    (n, m) new array.
    """
    arr = as_objectives(F, "F")
    m = arr.shape[1]
    lo = as_vector(lower, "lower", m)
    hi = as_vector(upper, "upper", m)
    if (lo > hi).any():
        j = int(np.argmax(lo > hi))
        raise InvalidInputError(
            f"lower must not exceed upper; objective {j}: lower={lo[j]!r} > upper={hi[j]!r}"
        )
    return fraction_towards(arr, lo, hi, ~as_sense(maximised, m), flat=0.0)


def normalised_hypervolume(
    F: ArrayLike,
    lower: ArrayLike,
    upper: ArrayLike,
    maximised: bool | Sequence[bool] = MAXIMISED,
    reference: float | Sequence[float] = DEFAULT_HV_REFERENCE,
) -> float:
    r"""Hypervolume in the unit minimisation space of :func:`to_unit_minimisation`.

    .. math::

        \mathrm{HV}_{\mathrm{norm}} = \mathrm{HV}(u(F), (\rho, \dots, \rho)),
        \qquad 0 \le \mathrm{HV}_{\mathrm{norm}} \le \rho^m

    The default :math:`\rho = 1.1` puts the reference point 10 % beyond the worst bound of
    every objective, so that the boundary solutions of the front (which lie *on* the worst
    bound of some objective) still contribute volume — the usual choice in the literature.
    Use the *same* ``lower``/``upper`` (e.g. :func:`objective_bounds` over all compared
    fronts) for every front, or the values are not comparable.

    Parameters
    ----------
    F: (n, m) objective values in raw units.
    lower, upper: (m,) bounds in raw units.
    maximised: sense of each objective; default :data:`MAXIMISED`.
    reference: ρ, a scalar or (m,) values in unit space (each > 0).
    """
    u = to_unit_minimisation(F, lower, upper, maximised)
    m = u.shape[1]
    rho = as_finite_array(reference, "reference")
    if rho.ndim == 0:
        rho = np.full(m, float(rho))
    rho = as_vector(rho, "reference", m)
    if (rho <= 0).any():
        raise InvalidInputError(f"reference must be > 0 in unit space; got {rho!r}")
    return hypervolume(u, rho, maximised=False)
