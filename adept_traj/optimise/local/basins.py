r"""Basins of moves: which moves a local solver would take to the same local optimum.

Two moves lie in one basin, for :func:`basin_labels`, when their joint paths stay close
**at the same instants**: with :math:`q_a(t), q_b(t)` the joint positions and
:math:`r_j` the range of joint j,

.. math::
    \delta(a, b) = \max_{k, j} \frac{|q_{a,j}(t_k) - q_{b,j}(t_k)|}{r_j}
    \le \text{threshold},

over :data:`N_INSTANTS` instants :math:`t_k`. In a scene with a moving obstacle the
instants are **scene times** spread over :math:`[0, \max T]` (a move that has arrived
stays at the goal): two moves along the same path that pass a swinging pendulum at
different phases — one before it, one after — are different basins, and a local solver
from one does not reach the other. Without moving obstacles the instants are normalised
times :math:`t_k = s_k T` of each move (the shape of the path decides the basin; the same
path at another speed is the same basin, which the minimum-time solve descends anyway).

The grouping is greedy in the given order (pass the moves fastest first): a move joins the
first basin whose first move (its representative) is within the threshold, else it starts
a new basin. Chosen over a topological signature (which side of each obstacle a move
passes, at which phase of each swing) because it needs nothing of the obstacles' shapes
and works the same for any robot and scene; the threshold (:data:`BASIN_THRESHOLD`, 10 % of each
joint's range) is documented in ``docs/detour-scene.md``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.validation import as_batch, as_scalar

__all__ = ["BASIN_THRESHOLD", "N_INSTANTS", "basin_labels", "basin_starts"]

#: Instants at which two moves are compared.
N_INSTANTS = 48

#: Largest joint distance of one basin, as a fraction of each joint's range.
BASIN_THRESHOLD = 0.10


def basin_labels(problem: Any, x: Any, *, threshold: float = BASIN_THRESHOLD) -> np.ndarray:
    """(n,) int basin of each move ``x`` (n, n_var), numbered 0, 1, … in order of first
    appearance (module docstring).

    Parameters
    ----------
    problem: the :class:`~adept_traj.problem.TrajectoryProblem` (its scene says whether
        the instants are scene times or normalised times).
    x: (n, n_var) decision vectors ``[T [s], free control points]``.
    threshold: largest distance within one basin (fraction of each joint's range, > 0).
    """
    xs = np.atleast_2d(as_batch(x, "x", problem.n_var))
    limit = as_scalar(threshold, "threshold", minimum=0.0, strict=True, error=ConfigurationError)
    if len(xs) == 0:
        return np.empty(0, dtype=int)
    span = problem.robot.limits.upper - problem.robot.limits.lower
    span = np.where(span > 0.0, span, 1.0)
    paths = _paths(problem, xs) / span  # (n, N_INSTANTS, nq)
    labels = np.full(len(xs), -1)
    representatives: list[int] = []
    for i in range(len(xs)):  # one loop step per move (a population), not per sample
        if representatives:
            gap = np.max(np.abs(paths[representatives] - paths[i]), axis=(1, 2))
            near = np.flatnonzero(gap <= limit)
            if len(near):
                labels[i] = near[0]
                continue
        labels[i] = len(representatives)
        representatives.append(i)
    return labels


def basin_starts(problem: Any, x: Any, max_basins: int) -> np.ndarray:
    """(k,) int rows of ``x`` (n, n_var): the fastest move of each of the ``max_basins``
    fastest basins (:func:`basin_labels` of the moves fastest first), fastest first
    (k ≤ ``max_basins``)."""
    xs = np.atleast_2d(as_batch(x, "x", problem.n_var))
    order = np.argsort(xs[:, 0], kind="stable")
    _, first = np.unique(basin_labels(problem, xs[order]), return_index=True)
    return order[np.sort(first)[:max_basins]]


def _paths(problem: Any, xs: np.ndarray) -> np.ndarray:
    """(n, N_INSTANTS, nq) joint positions of the moves at the comparison instants."""
    traj = problem.trajectory
    moving = any(not ob.motion.is_fixed for ob in problem.scene.obstacles)
    if not moving:
        s = np.linspace(0.0, 1.0, N_INSTANTS)
        return traj.sample(xs, s, orders=(0,)).q
    t = np.linspace(0.0, float(xs[:, 0].max()), N_INSTANTS)
    s = np.clip(t[None, :] / xs[:, :1], 0.0, 1.0)  # (n, N_INSTANTS): arrived moves stay
    basis = traj.basis_matrix(s.ravel(), 0).reshape(*s.shape, -1)  # (n, N, n_control)
    _, control = traj.decode(xs)  # (n, n_control, nq)
    return np.einsum("nkc,ncj->nkj", basis, control)
