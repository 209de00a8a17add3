r"""The weighted sum of the six objectives with a fixed normalisation (one move, one number).

The single-objective mode of :func:`~adept_traj.plan` (``algorithm="time-optimal"`` with
``weights``) minimises

.. math::
    f_w(x) = \sum_{i=1}^{6} \hat w_i \, \sigma_i \, \frac{z_i(x)}{r_i}, \qquad
    \hat w_i = \frac{w_i}{\sum_j w_j}, \qquad
    \sigma_i = \begin{cases} -1 & \text{z4 (maximised)} \\ +1 & \text{otherwise,}
    \end{cases}

lower is better; only differences of :math:`f_w` matter (the maximised z4 enters with a
minus sign, so :math:`f_w` may be negative). The normalisation :math:`r` (6,) is **fixed by
the problem alone**, not by a front (:func:`~adept_traj.analysis.combined_objective`
normalises by the front's ranges, which a single move does not have): :math:`r_i =
|z_i(x_s)|` of the *straight move* :math:`x_s`, the joint-space minimum-jerk ramp from start
to goal (:meth:`~adept_traj.problem.BSplineTrajectory.straight_line`) at the kinematic
lower bound :math:`T_{lb}` (so :math:`r_1 = T_{lb}` [s], :math:`r_2` [J], :math:`r_4`
[m² for the SCARA], :math:`r_5`, :math:`r_6` in the units of
:data:`~adept_traj.problem.OBJECTIVES`), except :math:`r_3 = 1`: the clearance penalty is
already dimensionless, :math:`\varphi \in [0, 1]` per obstacle. A scale that is not > 0 (a
degenerate straight move, e.g. z4 = 0 from a singular start) is 1 in the objective's unit.

Why this reference: it exists for every problem, costs one evaluation and no search, and
depends neither on the seed, the weights nor the solver, so the same weights mean the same
trade-off on every run of a problem and ``adept-traj verify`` recomputes it from the
stored problem. The paper's Table 3 bounds exist only for its own scene and robot; the
minimum-T move's values would depend on which local optimum the solver found (three
distinct ones on the paper scene, with z2 from 3 408 to 3 791 J). With these scales a unit
of :math:`f_w` is "the straight move's value of every objective": on the paper scene the
minimum-T moves have :math:`z_1/r_1 = 1.0036` and :math:`z_2/r_2` from 1.14 to 1.27.

:meth:`WeightedSum.to_dict` gives the weights and scales as stored in a result
(``result.algorithm_settings["weighted_sum"]``), :meth:`WeightedSum.from_settings` reads
them back.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from adept_traj.analysis.decision import objective_weights
from adept_traj.errors import InvalidInputError
from adept_traj.problem import MAXIMISED, check_differentiable, objective_gradients
from adept_traj.validation import as_batch, as_vector, readonly_copy

__all__ = ["WEIGHTED_SUM_REFERENCE", "WeightedSum", "weighted_sum"]

#: What the scales of :func:`weighted_sum` are taken from (stored with them).
WEIGHTED_SUM_REFERENCE = "straight move at T_lb (z3: 1)"

#: σ_i of the sign convention: −1 where maximised (z4).
_SIGN = np.where(MAXIMISED, -1.0, 1.0)


@dataclass(frozen=True)
class WeightedSum:
    r"""The weighted sum :math:`f_w` of the module docstring.

    Attributes
    ----------
    weights:
        (6,) :math:`\hat w`, non-negative, summing to 1.
    scale:
        (6,) :math:`r` > 0, in the units of z1…z6 ([s], [J], 1, [m²], …).
    reference:
        What the scales were taken from (:data:`WEIGHTED_SUM_REFERENCE`).
    """

    weights: np.ndarray
    scale: np.ndarray
    reference: str = WEIGHTED_SUM_REFERENCE

    def __post_init__(self) -> None:
        w = objective_weights(self.weights, len(_SIGN))
        r = as_vector(self.scale, "scale", len(_SIGN))
        if np.any(r <= 0.0):
            raise InvalidInputError(f"scale must be > 0 in every objective; got {r.tolist()}")
        object.__setattr__(self, "weights", readonly_copy(w))
        object.__setattr__(self, "scale", readonly_copy(r))

    @property
    def cost(self) -> np.ndarray:
        r"""(6,) :math:`c_i = \hat w_i \sigma_i / r_i`, so that :math:`f_w = c \cdot z`."""
        return self.weights * _SIGN / self.scale

    def values(self, objectives: ArrayLike) -> np.ndarray:
        """(n,) :math:`f_w` of objectives (n, 6) as reported (z4 positive), or a float for
        one (6,) row."""
        z = np.asarray(objectives, dtype=float)
        if z.ndim == 1:
            return float(as_vector(z, "objectives", len(_SIGN)) @ self.cost)
        return as_batch(z, "objectives", len(_SIGN)) @ self.cost

    def order(self, objectives: ArrayLike) -> np.ndarray:
        """(n,) rows of ``objectives`` (n, 6) by increasing :math:`f_w`, ties by row."""
        return np.argsort(self.values(np.atleast_2d(objectives)), kind="stable")

    def gradient(self, problem: Any, x: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        r"""(n,) :math:`f_w` of ``x`` (n, n_var) and (n, n_var) its gradient
        :math:`\sum_i c_i\, \partial z_i / \partial x` by
        :func:`~adept_traj.problem.objective_gradients` (``z3="clearance"``, finite torque
        limits; z3, z4 differentiated at their minimising sample)."""
        og = objective_gradients(problem, x)
        return og.values @ self.cost, np.einsum("i,piv->pv", self.cost, og.jacobian)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form stored in a result's algorithm settings."""
        return {
            "weights": self.weights.tolist(),
            "scale": self.scale.tolist(),
            "reference": self.reference,
        }

    @classmethod
    def from_settings(cls, settings: Mapping[str, Any]) -> WeightedSum | None:
        """The weighted sum stored under ``settings["weighted_sum"]`` (a result's algorithm
        settings), ``None`` when the run had none (every run but the weighted mode)."""
        stored = settings.get("weighted_sum")
        if stored is None:
            return None
        if not isinstance(stored, Mapping) or not {"weights", "scale"} <= set(stored):
            raise InvalidInputError(
                f"algorithm settings 'weighted_sum' must hold 'weights' and 'scale'; got {stored!r}"
            )
        reference = stored.get("reference", WEIGHTED_SUM_REFERENCE)
        return cls(stored["weights"], stored["scale"], str(reference))


def weighted_sum(problem: Any, weights: ArrayLike) -> WeightedSum:
    """:class:`WeightedSum` of ``weights`` (6,) (finite, ≥ 0, positive sum; rescaled to sum
    1) on ``problem`` (a :class:`~adept_traj.problem.TrajectoryProblem`), with the scales of
    its straight move at T_lb (module docstring). Bad weights raise
    :class:`~adept_traj.errors.InvalidInputError` or
    :class:`~adept_traj.errors.InputShapeError` naming them; a problem whose objectives
    have no gradients (``z3`` other than ``"clearance"``, an infinite torque limit)
    :class:`~adept_traj.errors.ConfigurationError`."""
    w = objective_weights(weights, len(_SIGN))
    check_differentiable(problem)
    straight = problem.trajectory.straight_line(problem.lower_bound.T_min)
    z = problem.evaluate_batch(straight[None]).objectives[0]
    r = np.abs(z)
    r[2] = 1.0
    r[~(r > 0.0) | ~np.isfinite(r)] = 1.0
    return WeightedSum(w, r)
