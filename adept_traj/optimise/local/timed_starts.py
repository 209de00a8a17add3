r"""Starts for the certified local solver from the timed trees of
:mod:`~adept_traj.optimise.local.timed_roadmap`: their earliest joined paths fitted into the
problem's B-spline decision vector.

:func:`timed_roadmap_starts` fits each of the earliest arrivals' paths
(:func:`~adept_traj.optimise.timed_paths`, shortcut: at most
:data:`~adept_traj.optimise.local.timed_roadmap.JOINED_PATHS`), held at the goal up to
:data:`HOLDS` × its arrival time (the phase of the way is kept: the rest is a wait at the
goal), by least squares on the free control points with a weight on the accelerations
(:func:`fit_timed_path`, at each of :data:`SMOOTHINGS`: a path of straight edges has
corners that no move within the limits follows), evaluates every fit with the problem's
evaluator (one batched call) and returns the feasible ones first (fastest first), then
the others by their distance violation × :data:`DISTANCE_WEIGHT` + their other violations:
a limit is met by a slower move, a moving obstacle's phase is not. These are starts for
:func:`~adept_traj.optimise.refine_minimum_time`, whose elastic solve reaches the feasible
set from them.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.local.timed_roadmap import timed_paths
from adept_traj.validation import as_integer

__all__ = [
    "DISTANCE_WEIGHT",
    "FIT_SAMPLES",
    "HOLDS",
    "SMOOTHINGS",
    "fit_timed_path",
    "timed_roadmap_starts",
]

#: Factors of the arrival time at which a path is fitted (the rest held at the goal).
HOLDS: tuple[float, ...] = (1.0, 1.1, 1.2)

#: Weights µ [rad²] of the accelerations in the fits (:func:`fit_timed_path`).
SMOOTHINGS: tuple[float, ...] = (1e-3, 1e-2, 1e-1)

#: Weight of the distance violation against the limits' in the ranking of the fits.
DISTANCE_WEIGHT = 10.0

#: Instants of the least-squares fit.
FIT_SAMPLES = 80


def fit_timed_path(problem: Any, q: Any, t: Any, T: float, smoothing: float = 0.0) -> np.ndarray:
    r"""(n_var,) the decision vector of travel time ``T`` [s] whose free control points
    :math:`P` minimise, over :data:`FIT_SAMPLES` instants :math:`t_k` evenly over [0, T],

    .. math::
        \sum_k \lVert q(t_k) - p(t_k) \rVert^2
        + \mu \sum_k \sum_i \big(\ddot q_i(t_k) / a_{\max,i}\big)^2,

    :math:`p` the timed path through the states ``q`` at the times ``t`` (linear between
    them, held at the last after ``t[-1]``) and :math:`\mu` = ``smoothing`` [rad²]
    (≥ 0; it trades the fit for smaller accelerations); clipped to the bounds.

    Parameters
    ----------
    problem: the :class:`~adept_traj.problem.TrajectoryProblem`.
    q: (m, nq) states [rad | m], m ≥ 2.
    t: (m,) their times [s], non-decreasing from 0.
    T: travel time [s], at least ``t[-1]``.
    smoothing: the weight :math:`\mu` [rad²] of the accelerations.
    """
    traj = problem.trajectory
    q, t = np.asarray(q, dtype=float), np.asarray(t, dtype=float)
    if q.ndim != 2 or q.shape[1] != traj.nq or t.shape != (len(q),) or len(q) < 2:
        raise ConfigurationError(
            f"q must have shape (m, {traj.nq}) with m ≥ 2 and t shape (m,); "
            f"got {q.shape} and {t.shape}"
        )
    if not (np.all(np.isfinite(t)) and t[0] == 0.0 and np.all(np.diff(t) >= 0.0)):
        raise ConfigurationError(f"t must be finite and non-decreasing from 0 [s]; got {t}")
    if not (np.isfinite(T) and t[-1] <= T and T > 0.0):
        raise ConfigurationError(f"T must be finite, > 0 and ≥ t[-1] = {t[-1]} [s]; got {T}")
    if not (np.isfinite(smoothing) and smoothing >= 0.0):
        raise ConfigurationError(f"smoothing must be finite and ≥ 0 [rad²]; got {smoothing}")
    s = np.linspace(0.0, 1.0, FIT_SAMPLES)
    target = np.stack([np.interp(s * T, t, q[:, j]) for j in range(traj.nq)], axis=1)
    free = np.empty((traj.n_free, traj.nq))
    acc = problem.robot.limits.acceleration
    for j in range(traj.nq):  # per joint: its own acceleration scale
        rows, rhs = [], []
        for order, weight, goal in ((0, 1.0, target[:, j]), (2, smoothing, 0.0)):
            B = traj.basis_matrix(s, order) * (np.sqrt(weight) / (T**order * acc[j] ** (order / 2)))
            ends = B[:, :3].sum(axis=1) * traj.start[j] + B[:, -3:].sum(axis=1) * traj.goal[j]
            rows.append(B[:, 3:-3])
            rhs.append(np.sqrt(weight) * goal * (order == 0) - ends)
        free[:, j] = np.linalg.lstsq(np.concatenate(rows), np.concatenate(rhs), rcond=None)[0]
    return np.clip(traj.encode(float(T), free), problem.xl, problem.xu)


def timed_roadmap_starts(
    problem: Any, seed: int, *, guides: Any = None, n_starts: int = 3
) -> np.ndarray:
    """(k ≤ n_starts, n_var) starts from the timed trees (:func:`timed_paths`): the fits
    (:func:`fit_timed_path`) of their earliest arrivals, held to
    :data:`HOLDS` × their arrival time (at most the largest T), at each of
    :data:`SMOOTHINGS`; the evaluator-feasible ones first (fastest first), then the others
    by their distance violation × :data:`DISTANCE_WEIGHT` + their other violations (a
    limit is met by a slower move, a moving obstacle's phase is not); empty (0, n_var)
    when no pair of trees was joined.

    Parameters
    ----------
    problem: the :class:`~adept_traj.problem.TrajectoryProblem`.
    seed: seed of the trees' generators (≥ 0).
    guides: (k, n_var) guide moves of :func:`timed_paths` (default: the straight move).
    n_starts: most starts (≥ 1).
    """
    n_starts = as_integer(n_starts, "n_starts", minimum=1, error=ConfigurationError)
    found = timed_paths(problem, seed, guides=guides)
    t_max = float(problem.xu[0])
    fits = [
        fit_timed_path(problem, q, t, min(h * t[-1], t_max), mu)
        for q, t in zip(found.paths, found.times)
        for h in HOLDS
        for mu in SMOOTHINGS
    ]
    if not fits:
        return np.empty((0, problem.n_var))
    x = np.array(fits)
    g = np.maximum(problem.evaluate_batch(x).constraints, 0.0)
    key = DISTANCE_WEIGHT * g[:, -1] + g[:, :-1].sum(axis=1)
    key = np.where(key == 0.0, -1.0 / x[:, 0], key)  # the feasible first, fastest first
    return x[np.argsort(key, kind="stable")[:n_starts]]
