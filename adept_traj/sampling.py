r"""Initial populations for trajectory problems.

pymoo's default :class:`~pymoo.operators.sampling.rnd.FloatRandomSampling` draws every
control point uniformly inside the joint limits: such trajectories shake between the limits
and violate the velocity, acceleration and jerk limits by orders of magnitude, so a run
spends most of its budget finding the feasible region. :class:`RampSampling` (the default)
draws **rest-to-rest ramps with random timing and a random detour per joint**:

.. math::
    P_{c,j} = q_{s,j} + \Delta_j\,\sigma\!\left(\frac{\xi_c - a_j}{b_j - a_j}\right)
              + \beta_j \sin(\pi \xi_c)\,(\bar q_j - \underline q_j),

with :math:`\xi_c` the control points' positions in [0, 1], σ the smoothstep
:math:`10u^3 - 15u^4 + 6u^5` clipped to [0, 1], a random window
:math:`0 \le a_j < b_j \le 1` (when joint j moves) and a random detour amplitude
:math:`\beta_j \sim \mathcal N(0, \text{detour}^2)`; T is uniform in its bounds. The straight
joint-space move is always included. Control points are clipped to the decision bounds.
Nothing about a particular scene is assumed.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pymoo.core.sampling import Sampling

from .errors import ConfigurationError

__all__ = ["RampSampling"]


def _smoothstep(u: np.ndarray) -> np.ndarray:
    u = np.clip(u, 0.0, 1.0)
    return u * u * u * (10.0 + u * (-15.0 + 6.0 * u))


class RampSampling(Sampling):
    """Random rest-to-rest ramps with random per-joint timing and detours (see module doc).

    Parameters
    ----------
    detour:
        Standard deviation of the detour amplitude, as a fraction of each joint's range
        (default 0.05).
    min_window:
        Smallest fraction of the control polygon over which a joint moves (default 0.3).
    """

    def __init__(self, detour: float = 0.05, min_window: float = 0.3) -> None:
        super().__init__()
        if not (np.isfinite(detour) and detour >= 0):
            raise ConfigurationError(f"detour must be ≥ 0; got {detour}")
        if not 0 < min_window <= 1:
            raise ConfigurationError(f"min_window must be in (0, 1]; got {min_window}")
        self.detour, self.min_window = float(detour), float(min_window)

    def _do(self, problem: Any, n_samples: int, random_state: Any = None, **kwargs: Any):
        rng = random_state if random_state is not None else np.random.default_rng()
        traj = problem.trajectory
        nq = traj.nq
        xi = np.linspace(0.0, 1.0, traj.n_control)[3:-3]  # (n_free,)
        span = problem.robot.limits.upper - problem.robot.limits.lower
        T = rng.uniform(problem.xl[0], problem.xu[0], size=n_samples)
        a = rng.uniform(0.0, 1.0 - self.min_window, size=(n_samples, nq))
        b = a + rng.uniform(self.min_window, 1.0, size=(n_samples, nq)) * (1.0 - a)
        b = np.maximum(b, a + self.min_window)
        ramp = _smoothstep((xi[None, :, None] - a[:, None, :]) / (b - a)[:, None, :])
        detour = rng.normal(0.0, self.detour, size=(n_samples, 1, nq)) * span
        free = (
            traj.start
            + (traj.goal - traj.start) * ramp
            + detour * np.sin(np.pi * xi)[None, :, None]
        )  # (n_samples, n_free, nq)
        x = traj.encode(T, free)
        if n_samples > 0:
            x[0] = traj.straight_line(0.5 * (problem.xl[0] + problem.xu[0]))
        return np.clip(x, problem.xl, problem.xu)
