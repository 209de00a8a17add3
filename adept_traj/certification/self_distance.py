r"""The robot's distance to itself in the certificate: :class:`SelfDistance`.

When the problem checks self-collision (:attr:`~adept_traj.problem.TrajectoryProblem.self_check`,
``ProblemSettings.self_collision``), :func:`~adept_traj.analysis.certify` computes the
signed distance of every checked pair of robot solids (adjacent and disabled pairs left
out, :class:`~adept_traj.collision.SelfCollision`) at every dense sample, and bounds it
between the samples as for the obstacles
(:func:`~adept_traj.certification.continuous.continuous_self_distance`): both solids of a pair
move, but a joint moving both moves them rigidly together, so the rate of change of the
pair's distance :math:`d_{ab}` is bounded by the joints that move exactly one of them,

.. math::
    |\dot d_{ab}| \le \sum_{j \in J_a \setminus J_b} r_{aj} |\dot q_j|
                   + \sum_{j \in J_b \setminus J_a} r_{bj} |\dot q_j|,

with the lever arms :math:`r_{sj}` [m] of :func:`~adept_traj.collision.solid_lever_arms`.
The self-distance must reach the same safety margin as the obstacle distance: the margin
covers what the model leaves out (the convex hulls of the meshes, calibration,
tracking error), which is the same for a link near another link as near an obstacle.
It enters the verdict (:attr:`Certificate.feasible <adept_traj.analysis.Certificate.feasible>`,
:attr:`~adept_traj.analysis.Certificate.certified`), not the dense trajectory's
``min_distance`` series (robot–obstacle only).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from adept_traj.certification.continuous import (
    CONTINUOUS,
    SampledMove,
    continuous_self_distance,
    self_check_of,
)
from adept_traj.errors import InvalidInputError
from adept_traj.problem.trajectory_problem import TrajectoryProblem

__all__ = [
    "MIN_SEARCH",
    "SelfDistance",
    "normalise_distance_fields",
    "self_distance",
]

#: Most exact distances computed to make the smallest self-distance of a certificate exact.
MIN_SEARCH = 64


@dataclass(frozen=True)
class SelfDistance:
    """The smallest distance between two of the robot's own checked solids over a motion.

    Attributes
    ----------
    min_distance: smallest signed distance [m] over the samples and checked pairs
        (negative: penetration depth; ``inf``: no checked pair); exact when ``exact``,
        else a lower bound of the smallest distance (above the margin).
    exact: whether :attr:`min_distance` is the exact smallest distance.
    t_min_distance: its time [s] (of the smallest bound when not ``exact``; ``None``: no
        checked pair).
    pair: ``(solid a, solid b)`` names there (``None``: no checked pair).
    guarantee: ``"continuous"`` (the bound holds at every instant) or ``"sampled at N Hz"``.
    distance_bound: lower bound [m] of the self-distance at every instant of [0, T]
        (``None``: not computed; ``inf``: no checked pair).
    """

    min_distance: float
    exact: bool
    t_min_distance: float | None
    pair: tuple[str, str] | None
    guarantee: str
    distance_bound: float | None

    def __post_init__(self) -> None:
        normalise_distance_fields(self, "min_distance", "t_min_distance", "pair", "distance_bound")

    def ok(self, margin: float) -> bool:
        """The smallest self-distance is at least ``margin`` [m]."""
        return self.min_distance >= margin

    def violations(self, margin: float) -> tuple[str, ...]:
        """The certificate's message when the self-distance is below ``margin`` [m], e.g.
        ``"self-distance: -0.0123 m < margin 0.01 m at t = 0.512 s (forearm – base)"``."""
        if self.ok(margin) or self.pair is None:
            return ()
        return (
            f"self-distance: {self.min_distance:.4g} m < margin {margin:.4g} m at "
            f"t = {self.t_min_distance:.3f} s ({self.pair[0]} – {self.pair[1]})",
        )


def normalise_distance_fields(record: object, value: str, when: str, pair: str, bound: str) -> None:
    """Check and convert, in place, the distance fields of a frozen record (a
    :class:`SelfDistance` or a :class:`~adept_traj.analysis.Certificate`).

    Parameters
    ----------
    record:
        The frozen dataclass, changed in place by its ``__post_init__``.
    value, when, pair, bound:
        Field names: the distance [m] (a number or +inf), its time [s] (or ``None``), the
        pair of two names (or ``None``) and the lower bound [m] (a number or ``None``).

    Raises
    ------
    InvalidInputError
        NaN or -inf distance, a pair that is not two names, a NaN bound.
    """
    d = float(getattr(record, value))
    if math.isnan(d) or d == -math.inf:
        raise InvalidInputError(f"{value} must be a number or +inf; got {d!r}")
    object.__setattr__(record, value, d)
    if getattr(record, when) is not None:
        object.__setattr__(record, when, float(getattr(record, when)))
    if getattr(record, pair) is not None:
        names = tuple(str(n) for n in getattr(record, pair))
        if len(names) != 2:
            raise InvalidInputError(f"{pair} must be a pair of names; got {names!r}")
        object.__setattr__(record, pair, names)
    if getattr(record, bound) is not None:
        low = float(getattr(record, bound))
        if math.isnan(low):
            raise InvalidInputError(f"{bound} must be a number or ±inf; got nan")
        object.__setattr__(record, bound, low)


def self_distance(
    problem: TrajectoryProblem, move: SampledMove, continuous: bool, max_depth: int
) -> SelfDistance:
    """The :class:`SelfDistance` of a move
    (:func:`~adept_traj.certification.continuous.sampled_move`), for
    :func:`~adept_traj.analysis.certify` (its ``continuous`` and ``max_depth``; the
    problem's self-collision check must be on).

    The distances at the samples are exact where below the margin and lower bounds
    above it (:meth:`~adept_traj.collision.SelfCollision.distances` with ``exact_below``:
    the verdict and the continuous bound need no more, and a pair touching by design is
    not computed at every sample). The smallest is then made exact by branch and bound:
    the smallest bound is replaced by its exact distance, which lifts the pair's other
    bounds by the joint-space Lipschitz bound, until the smallest value is exact or above
    the check's influence distance, at most :data:`MIN_SEARCH` times (else it is reported
    as a bound, ``exact=False``), whatever ``certify``'s ``exact``.

    Raises
    ------
    InvalidInputError
        As :func:`~adept_traj.certification.continuous.continuous_self_distance`.
    """
    check = self_check_of(problem)
    t, q, grid_hz = move.t, move.q, move.rate_hz
    if not check.n_pairs:
        return SelfDistance(math.inf, True, None, None, CONTINUOUS, math.inf)
    margin = float(problem.settings.margin)
    d = check.distances(q, exact_below=margin)  # (n, n_pairs)
    known = d <= margin
    rho = check.lever_arms  # (n_pairs, nq) [m/rad | 1]
    for _ in range(MIN_SEARCH):
        k, p = np.unravel_index(int(np.argmin(d)), d.shape)
        if known[k, p] or d[k, p] > check.influence:
            break
        exact_kp = float(check.pair_distance(q[k], int(p)))
        np.maximum(d[:, p], exact_kp - np.abs(q - q[k]) @ rho[p], out=d[:, p])  # lift
        d[k, p], known[k, p] = exact_kp, True
    k, p = np.unravel_index(int(np.argmin(d)), d.shape)
    best, t_best, exact = float(d[k, p]), float(t[k]), bool(known[k, p])
    guarantee, bound = f"sampled at {grid_hz:g} Hz", None
    if continuous:
        between = continuous_self_distance(problem, move, d, max_depth)
        guarantee, bound = between.guarantee, between.lower_bound
        if between.min_distance < best:  # (exact: below the margin) between the samples
            best, t_best, p = between.min_distance, between.t_min_distance, between.pair[0]
            exact = best <= margin
    return SelfDistance(best, exact, t_best, check.pair_names[p], guarantee, bound)
