"""Analysis of fronts: decision making (:mod:`~adept_traj.analysis.decision`), indicators
(:mod:`~adept_traj.analysis.indicators`), the paper's measures
(:mod:`~adept_traj.analysis.paper_measures`), the weighted sum of a move and the
plausibility warnings of a scene.

The certificate moved to :mod:`adept_traj.certification` (issue #27); its public names are
still found here (``from adept_traj.analysis import certify``), imported from there on first
use, for code written before."""

from __future__ import annotations

from adept_traj.analysis.decision import (
    PAPER_WEIGHTS,
    BestTradeoff,
    average_fitness,
    best_tradeoff,
    combined_objective,
    normalise,
    objective_weights,
)
from adept_traj.analysis.indicators import (
    DEFAULT_HV_REFERENCE,
    hypervolume,
    igd,
    non_dominated,
    normalised_hypervolume,
    objective_bounds,
    to_unit_minimisation,
)
from adept_traj.analysis.paper_measures import (
    algorithm_effort,
    optimizer_overhead,
    ratio_non_dominated,
    spread,
)
from adept_traj.analysis.plausibility import REACH_FACTOR, robot_reach, unit_warnings
from adept_traj.analysis.weighted_sum import WEIGHTED_SUM_REFERENCE, WeightedSum, weighted_sum
from adept_traj.lazy_names import lazy_names
from adept_traj.robot.limits import LIMIT_KINDS  # the one vocabulary, re-exported

__all__ = [
    "DEFAULT_HV_REFERENCE",
    "LIMIT_KINDS",
    "PAPER_WEIGHTS",
    "REACH_FACTOR",
    "WEIGHTED_SUM_REFERENCE",
    "BestTradeoff",
    "WeightedSum",
    "algorithm_effort",
    "average_fitness",
    "best_tradeoff",
    "combined_objective",
    "hypervolume",
    "igd",
    "non_dominated",
    "normalise",
    "normalised_hypervolume",
    "objective_bounds",
    "objective_weights",
    "optimizer_overhead",
    "ratio_non_dominated",
    "robot_reach",
    "spread",
    "to_unit_minimisation",
    "unit_warnings",
    "weighted_sum",
]


#: A public name of :mod:`adept_traj.certification` (moved from here), on first use.
__getattr__ = lazy_names(__name__, "adept_traj.certification")
