r"""The kinematic lower bound of the travel time: no rest-to-rest move can be faster.

:func:`kinematic_lower_bound` gives, per joint, the exact minimum time of a rest-to-rest
move under velocity, acceleration and jerk limits (the time-optimal jerk-limited "double S"
profile); the slowest joint sets :attr:`KinematicBound.T_min`, a bound no trajectory (and in
particular no :class:`~adept_traj.problem.BSplineTrajectory`) respecting the limits can beat.
:class:`~adept_traj.problem.TrajectoryProblem` uses it for the default range of the travel
time ``T`` (objective z1), and results report the gap of the optimised ``T`` to it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.validation import as_finite_array, as_vector, describe_bad_values

__all__ = ["KinematicBound", "kinematic_lower_bound"]


@dataclass(frozen=True, eq=False)
class KinematicBound:
    r"""Minimum rest-to-rest travel times under velocity, acceleration and jerk limits.

    Attributes
    ----------
    times: per-joint minimum time [s], shape ``(nq,)``.
    delta: per-joint distance :math:`|q_\text{goal} - q_\text{start}|` [rad] or [m],
        shape ``(nq,)``.
    cases: per-joint profile type, one of ``"rest"`` (Δ = 0), ``"instant"`` (all limits
        infinite), ``"jerk"`` (neither a nor v reached), ``"acc"`` (a reached, v not),
        ``"vel"`` (v reached, a not), ``"acc+vel"`` (both reached).
    T_min: :math:`\max_i` ``times[i]`` [s]: no trajectory respecting the limits can be
        faster.
    limiting_joint: index of the joint that attains ``T_min`` (0 if all times are 0).
    """

    times: np.ndarray
    delta: np.ndarray
    cases: tuple[str, ...]
    T_min: float
    limiting_joint: int


def kinematic_lower_bound(
    start: Any, goal: Any, v_max: Any, a_max: Any, j_max: Any
) -> KinematicBound:
    r"""Exact minimum time of a rest-to-rest move under per-joint v, a, j limits.

    For each joint, :math:`h = |q_\text{goal} - q_\text{start}|` and limits
    :math:`|\dot q| \le v`, :math:`|\ddot q| \le a`, :math:`|\dddot q| \le j`, the
    time-optimal profile is the jerk-limited "double S" (bang-bang jerk; Biagiotti &
    Melchiorri 2008, Sec. 3.4). With :math:`T_a` the time to accelerate from 0 to v,

    .. math::

        T_a = \begin{cases} a/j + v/a & v j \ge a^2 \\ 2\sqrt{v/j} & v j < a^2
              \end{cases}, \qquad
        T = \begin{cases}
            h/v + T_a & h \ge v T_a \quad\text{(v reached)} \\
            a/j + \sqrt{(a/j)^2 + 4h/a} & h < v T_a,\ h \ge 2a^3/j^2
                \quad\text{(a reached)} \\
            4\,(h/(2j))^{1/3} & \text{otherwise.}
        \end{cases}

    Infinite limits are allowed (``j = inf`` gives the trapezoidal-velocity times;
    all three infinite give 0). ``h = 0`` gives 0.

    Parameters
    ----------
    start: start configuration [rad] or [m], shape ``(nq,)``.
    goal: goal configuration [rad] or [m], shape ``(nq,)``.
    v_max: velocity limits [rad/s] or [m/s], scalar or ``(nq,)``, > 0 (inf allowed).
    a_max: acceleration limits [rad/s²] or [m/s²], scalar or ``(nq,)``, > 0.
    j_max: jerk limits [rad/s³] or [m/s³], scalar or ``(nq,)``, > 0.

    Returns
    -------
    :class:`KinematicBound` (per-joint times [s], ``T_min`` [s], ``limiting_joint``).

    Examples
    --------
    >>> kinematic_lower_bound([0.0], [0.929], np.inf, 9.5, 50.0).T_min  # doctest: +ELLIPSIS
    0.843...
    """
    q0 = as_finite_array(start, "start")
    if q0.ndim != 1 or q0.shape[0] == 0:
        raise InputShapeError(f"start must have shape (nq,) with nq >= 1; got {q0.shape}")
    nq = q0.shape[0]
    q1 = as_vector(goal, "goal", nq)
    v = _as_limit(v_max, "v_max", nq)
    a = _as_limit(a_max, "a_max", nq)
    j = _as_limit(j_max, "j_max", nq)
    delta = np.abs(q1 - q0)
    results = [
        _double_s_time(float(delta[i]), float(v[i]), float(a[i]), float(j[i])) for i in range(nq)
    ]
    times = np.array([r[0] for r in results])
    limiting = int(np.argmax(times))
    return KinematicBound(
        times=times,
        delta=delta,
        cases=tuple(r[1] for r in results),
        T_min=float(times[limiting]),
        limiting_joint=limiting,
    )


def _double_s_time(h: float, v: float, a: float, j: float) -> tuple[float, str]:
    """Minimum rest-to-rest time [s] for distance ``h`` ≥ 0 under limits v, a, j (> 0, may be inf).

    Biagiotti & Melchiorri, *Trajectory Planning for Automatic Machines and Robots* (2008),
    Sec. 3.4, with zero boundary velocities and accelerations and symmetric limits.
    """
    if h == 0.0:
        return 0.0, "rest"
    if math.isinf(j):
        # Jerk unlimited: trapezoidal (or triangular) velocity profile.
        if math.isinf(a):
            return (0.0, "instant") if math.isinf(v) else (h / v, "vel")
        if math.isinf(v) or v * v / a >= h:
            return 2.0 * math.sqrt(h / a), "acc"
        return h / v + v / a, "acc+vel"
    # Jerk limited. 1) Is v reached? Time Ta to accelerate from 0 to v:
    if not math.isinf(v):
        a_reached = (not math.isinf(a)) and v * j >= a * a
        t_acc = a / j + v / a if a_reached else 2.0 * math.sqrt(v / j)
        if h >= v * t_acc:  # distance covered by accelerating to v and back to 0
            return h / v + t_acc, ("acc+vel" if a_reached else "vel")
    # 2) v not reached: is a reached?
    if not math.isinf(a) and h >= 2.0 * a**3 / j**2:
        return a / j + math.sqrt((a / j) ** 2 + 4.0 * h / a), "acc"
    return 4.0 * (h / (2.0 * j)) ** (1.0 / 3.0), "jerk"


def _as_limit(value: Any, name: str, nq: int) -> np.ndarray:
    """Return a positive limit (inf allowed) broadcast to shape ``(nq,)``."""
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be numeric; got {value!r} ({exc})") from None
    if arr.ndim > 1 or (arr.ndim == 1 and arr.shape[0] != nq):
        raise InputShapeError(f"{name} must be a scalar or have shape ({nq},); got {arr.shape}")
    arr = np.broadcast_to(arr, (nq,)).copy()
    bad = ~(arr > 0.0)  # NaN, zero and negative values
    if bad.any():
        raise InvalidInputError(
            f"{name} must be > 0 (inf allowed); bad entries: {describe_bad_values(arr, bad)}"
        )
    return arr
