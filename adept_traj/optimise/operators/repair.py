r"""Kinematic time repair: no candidate is faster than its own control polygon allows.

For fixed control points P, velocities scale as :math:`1/T`, accelerations as
:math:`1/T^2` and jerks as :math:`1/T^3`. With the exact per-segment extrema at T = 1
(:math:`V_j, A_j, J_j`), the smallest travel time meeting every velocity, acceleration and
jerk limit is

.. math::
    T_{kin}(P) = \max_j \max\left(\frac{V_j}{VC_j},\ \sqrt{\frac{A_j}{WC_j}},\
                 \sqrt[3]{\frac{J_j}{JC_j}}\right).

:class:`KinematicTimeRepair` (a pymoo ``Repair``) raises T to
:math:`\min(\max(T, T_{kin}(P)), T_{max})`; the decision vector keeps its meaning
(``[T, control points]``), constraints (8)–(10) hold by construction whenever
:math:`T_{kin}(P) \le T_{max}`, and the search concentrates on shapes and timing. A
fraction ``snap`` of the candidates is set exactly to :math:`T_{kin}(P)` (also lowered),
pushing the search towards the fastest move of each shape. It is
applied to the initial population and to every offspring (pymoo calls it after mating).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pymoo.core.repair import Repair

from adept_traj.errors import ConfigurationError
from adept_traj.problem import derivative_abs_max
from adept_traj.validation import as_scalar

__all__ = ["KINEMATIC_SLACK", "KinematicTimeRepair", "kinematic_time"]

#: Relative slack on the kinematic minimum: a travel time set to ``kinematic_time(...) *
#: (1 + KINEMATIC_SLACK)`` meets every velocity, acceleration and jerk limit despite
#: rounding. The repair, the fast-end search and the local solvers all raise T by it.
KINEMATIC_SLACK = 1e-9

#: Candidates whose exact extrema are computed at once: the per-segment arrays of
#: :meth:`~adept_traj.problem.BSplineTrajectory.bounds` stay a few MB whatever the
#: population size.
_BLOCK_ROWS = 1024


def kinematic_time(problem: Any, x: np.ndarray) -> np.ndarray:
    """(pop,) smallest T [s] meeting the velocity, acceleration and jerk limits for the
    control points of ``x`` (pop, n_var) (their current T is ignored).

    Computed in blocks of :data:`_BLOCK_ROWS` candidates (each row alone: the same numbers
    as at once), so the peak memory does not grow with the population."""
    x = np.asarray(x, dtype=float)
    if len(x) <= _BLOCK_ROWS:
        return _kinematic_time(problem, x)
    return np.concatenate(
        [_kinematic_time(problem, x[i : i + _BLOCK_ROWS]) for i in range(0, len(x), _BLOCK_ROWS)]
    )


def _kinematic_time(problem: Any, x: np.ndarray) -> np.ndarray:
    """:func:`kinematic_time` of one block ``x`` (k, n_var)."""
    unit = np.array(x, dtype=float)
    unit[..., 0] = 1.0
    qd, qdd, qddd = derivative_abs_max(problem.trajectory, unit)  # the extrema at T = 1
    lim = problem.robot.limits
    with np.errstate(divide="ignore", invalid="ignore"):
        v, a, j = qd / lim.velocity, np.sqrt(qdd / lim.acceleration), np.cbrt(qddd / lim.jerk)
    # The largest time over the three kinds and the joints, a NaN (0/0: a zero limit, no
    # motion) counting as 0 and ±inf as the largest float (``nan_to_num``): that map keeps
    # the order of the times, so it is applied to the largest non-NaN time (``fmax``
    # skips NaN; NaN only if all are) — the same number.
    return np.nan_to_num(np.fmax.reduce(np.fmax(np.fmax(v, a), j), axis=-1), nan=0.0)


class KinematicTimeRepair(Repair):
    """Raise each candidate's T to its kinematic minimum (see module doc).

    Parameters
    ----------
    snap:
        Probability that a candidate's T is instead set exactly to its kinematic minimum
        (also lowered), which pushes the search towards the fastest moves of each shape
        (default 0.2; drawn from the algorithm's seeded generator; 0 disables it).
    """

    def __init__(self, snap: float = 0.2) -> None:
        super().__init__()
        snap = as_scalar(snap, "snap", minimum=0.0, error=ConfigurationError)
        if snap > 1.0:
            raise ConfigurationError(f"snap must be a probability in [0, 1]; got {snap}")
        self.snap = snap

    def _do(self, problem: Any, X: np.ndarray, **kwargs: Any) -> np.ndarray:
        X = np.array(X, dtype=float)
        if X.size == 0:
            return X
        return self.repaired(problem, X, self.snaps(len(X), kwargs.get("random_state")))

    def snaps(self, n: int, rng: np.random.Generator | None) -> np.ndarray:
        """(n,) bool: which of n candidates get T exactly at their kinematic minimum — the
        draws the repair makes (one uniform each from ``rng``; none, all false, at
        ``snap`` 0 or without a generator)."""
        if self.snap > 0.0 and rng is not None:
            return rng.uniform(size=n) < self.snap
        return np.zeros(n, dtype=bool)

    def repaired(
        self,
        problem: Any,
        X: np.ndarray,
        snapped: np.ndarray,
        t_kin: np.ndarray | None = None,
    ) -> np.ndarray:
        """The candidates ``X`` (n, n_var) repaired (a copy): T raised to its kinematic
        minimum, or set to it where ``snapped`` (n,) (from :meth:`snaps`), clipped to
        T's bounds. ``t_kin`` (n,) [s]: the candidates' :func:`kinematic_time` if already
        computed (e.g. with other rows)."""
        X = np.array(X, dtype=float)
        if X.size == 0:
            return X
        t_kin = (kinematic_time(problem, X) if t_kin is None else t_kin) * (1.0 + KINEMATIC_SLACK)
        T = np.where(snapped, t_kin, np.maximum(X[:, 0], t_kin))
        X[:, 0] = np.clip(T, problem.xl[0], problem.xu[0])
        return X
