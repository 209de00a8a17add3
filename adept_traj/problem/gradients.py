r"""Smooth per-sample constraints of the trajectory problem and their exact Jacobians.

The evaluator's constraints (:mod:`adept_traj.problem.trajectory_problem`) are maxima and
minima over the whole motion: right for ranking a population, but not differentiable.
A gradient-based solver needs each extremum replaced by **one smooth constraint per
sample** (as Drake's ``KinematicTrajectoryOptimization`` does): the maximum of the samples
is below the limit exactly when every sample is, so the feasible sets agree on the samples
and a local optimum of the per-sample problem is one of the max/min problem
("exact at the optimum"). With :math:`x = [T, P_{free}]`, the samples at normalised times
:math:`s_k` are linear in the control points
(:meth:`~adept_traj.problem.BSplineTrajectory.basis_matrix`):

.. math::
    q_k = B^{(0)}_k P, \qquad \dot q_k = \frac{B^{(1)}_k P}{T}, \qquad
    \ddot q_k = \frac{B^{(2)}_k P}{T^2}, \qquad \dddot q_k = \frac{B^{(3)}_k P}{T^3},

so a kinematic constraint :math:`g = \pm q^{(r)}_{k,i} / L_i - 1` has the exact gradient
:math:`\pm B^{(r)}_{kc} / (T^r L_i)` in the control point :math:`P_{c,i}` and
:math:`-r\,(g + 1) / T` in :math:`T`. The constraints, all :math:`\le 0` and normalised as
in the evaluator:

- **velocity**: :math:`\pm \dot q_{k,i} / VC_i - 1` at ``points_per_segment`` + 1 evenly
  spaced points of every segment (a quadratic there; the exact maximum may lie a little
  above the samples, see below);
- **acceleration**: :math:`\pm \ddot q_{k,i} / WC_i - 1` at the knots (linear per segment:
  exact);
- **jerk**: :math:`\pm \dddot q_{k,i} / JC_i - 1` at the segment midpoints (constant per
  segment: exact);
- **torque**: :math:`\pm u_{k,i} / UC_i - 1` at the problem's samples ``problem.s``, with
  :math:`u = \mathrm{ID}(q, \dot q, \ddot q)` (:meth:`~adept_traj.robot.Robot.inverse_dynamics`)
  and the chain rule

  .. math::
      \frac{\partial u_k}{\partial P_c} = \frac{\partial u}{\partial q} B^{(0)}_{kc}
        + \frac{\partial u}{\partial \dot q} \frac{B^{(1)}_{kc}}{T}
        + \frac{\partial u}{\partial \ddot q} \frac{B^{(2)}_{kc}}{T^2}, \qquad
      \frac{\partial u_k}{\partial T} = -\frac{1}{T}\left(\frac{\partial u}{\partial \dot q}
        \dot q_k + 2 \frac{\partial u}{\partial \ddot q} \ddot q_k\right);

- **distance**: :math:`(m + b - \min(d_{k,o}, \delta)) / \delta` per sample ``problem.s`` and
  obstacle o, :math:`d_{k,o}` the smallest signed distance between the robot's solids and
  obstacle o at :math:`(q_k, t_k = T s_k)` (moving obstacles at their pose at
  :math:`t_k`), with

  .. math::
      \frac{\partial d_{k,o}}{\partial P_c} = \frac{\partial d}{\partial q} B^{(0)}_{kc},
      \qquad \frac{\partial d_{k,o}}{\partial T} = \frac{\partial d}{\partial t}\, s_k .

The joint position limits need no constraint: the control points' box bounds
(``problem.xl``, ``problem.xu``) keep the whole spline inside them (convex hull).

**What is a finite difference.** Everything above is exact except the state derivatives
of two black boxes, taken by *central differences in the state* (a few batched calls over
all samples at once, never through the decision vector): :math:`\partial u/\partial(q,
\dot q, \ddot q)` of the inverse dynamics (step ``1e-6``; the Coulomb term's derivative is
0 away from rest and is left out exactly) and :math:`\partial d/\partial(q, t)` of the
distances (step ``1e-6``; coal's GJK tolerance is 1e-9 m; only at samples within
``influence`` + 1 mm of an obstacle, the others have a zero gradient). The analytic
distance gradient (coal's nearest points and normal through the frame Jacobians, the
pendulum through its motion law) is not implemented yet.

Between the velocity samples the speed can exceed its sample maximum a little; the local
solver therefore finishes by raising T to the spline's exact kinematic minimum
(:func:`~adept_traj.optimise.kinematic_time`), and its result is certified like any other.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.robot.limits import LIMITS
from adept_traj.validation import as_batch, as_integer

__all__ = ["CONSTRAINT_KINDS", "LocalConstraints", "local_constraints"]

#: The kinds of per-sample constraints, in the order of :class:`LocalConstraints` rows.
CONSTRAINT_KINDS: tuple[str, ...] = ("velocity", "acceleration", "jerk", "torque", "distance")

#: Central-difference steps in the state: joint positions [rad | m], speeds, accelerations,
#: time [s].
_H = 1e-6

#: Samples farther than ``influence + _NEAR`` [m] from every obstacle get no distance
#: derivative (their clipped distance stays at ``influence`` under a step of ``_H``).
_NEAR = 1e-3


@dataclass(frozen=True)
class LocalConstraints:
    """Per-sample constraints :math:`g \\le 0` of a population and their Jacobians.

    Attributes
    ----------
    values:
        (pop, m) constraint values (normalised, dimensionless; feasible where ≤ 0).
    jacobian:
        (pop, m, n_var) :math:`\\partial g / \\partial x` (per [s] in the T column, per
        [rad | m] in the control-point columns).
    kind:
        (m,) int, index into :data:`CONSTRAINT_KINDS` of each row.
    """

    values: np.ndarray
    jacobian: np.ndarray
    kind: np.ndarray


def local_constraints(problem: Any, x: Any, *, points_per_segment: int = 4) -> LocalConstraints:
    """The smooth per-sample constraints of decision vectors ``x`` (pop, n_var) or
    (n_var,) and their Jacobians (see the module docstring).

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    x:
        Decision vectors ``[T [s], free control points [rad | m]]``.
    points_per_segment:
        Velocity samples per spline segment (≥ 1; plus the last knot).

    Returns
    -------
    LocalConstraints
        With a leading population axis of 1 for a single vector.
    """
    xa = np.atleast_2d(as_batch(x, "x", problem.n_var))
    n = as_integer(points_per_segment, "points_per_segment", minimum=1, error=ConfigurationError)
    if not np.all(xa[:, 0] > 0.0):
        raise ConfigurationError(f"travel times x[:, 0] must be > 0 [s]; got {xa[:, 0]}")
    return _local_constraints(problem, xa, n)


def _local_constraints(problem: Any, x: np.ndarray, n_per_segment: int) -> LocalConstraints:
    traj = problem.trajectory
    S = traj.n_segments
    grids = (
        np.linspace(0.0, 1.0, n_per_segment * S + 1),  # velocity
        np.linspace(0.0, 1.0, S + 1),  # acceleration: the knots
        (np.arange(S) + 0.5) / S,  # jerk: the segment midpoints
    )
    blocks = [
        _kinematic(problem, x, s, order, problem.robot.limits.bound(kind.name))
        for order, (s, kind) in enumerate(zip(grids, LIMITS[1:4]), start=1)
    ]
    blocks.append(_torque(problem, x))
    blocks.append(_distance(problem, x))
    kind = np.concatenate([np.full(b[0].shape[1], i) for i, b in enumerate(blocks)])
    return LocalConstraints(
        values=np.concatenate([b[0] for b in blocks], axis=1),
        jacobian=np.concatenate([b[1] for b in blocks], axis=1),
        kind=kind,
    )


def _free_basis(traj: Any, s: np.ndarray, order: int) -> np.ndarray:
    """(n_s, n_free) basis of the free control points at ``s`` (derivative ``order``)."""
    return traj.basis_matrix(s, order)[:, 3:-3]


def _chain(d_state: np.ndarray, basis: np.ndarray) -> np.ndarray:
    """(pop, n_s, r, nq·n_free) from per-sample state derivatives ``d_state`` (pop, n_s, r,
    nq) and the free basis (n_s, n_free): joint-major, as the decision vector."""
    out = np.einsum("pkrj,kc->pkrjc", d_state, basis)
    return out.reshape(*out.shape[:3], out.shape[3] * out.shape[4])  # r may be 0


def _two_sided(value: np.ndarray, d_free: np.ndarray, d_T: np.ndarray, scale: np.ndarray):
    """Rows :math:`\\pm y / L - 1` of samples ``value`` (pop, n_s, nq) with derivatives
    ``d_free`` (pop, n_s, nq, n_free·nq) and ``d_T`` (pop, n_s, nq): (pop, m), (pop, m, n_var)."""
    pop = value.shape[0]
    g = value / scale
    jac = np.concatenate([d_T[..., None], d_free], axis=-1) / scale[:, None]
    vals = np.concatenate([g.reshape(pop, -1) - 1.0, -g.reshape(pop, -1) - 1.0], axis=1)
    jac = jac.reshape(pop, -1, jac.shape[-1])
    return vals, np.concatenate([jac, -jac], axis=1)


def _kinematic(problem: Any, x: np.ndarray, s: np.ndarray, order: int, limit: np.ndarray):
    """Velocity (order 1), acceleration (2) or jerk (3) rows at ``s``."""
    traj = problem.trajectory
    T, P = traj.decode(x)
    B = traj.basis_matrix(s, order)
    y = np.einsum("kc,pcj->pkj", B, P) / T[:, None, None] ** order  # (pop, n_s, nq)
    Bf = _free_basis(traj, s, order)
    scale = T[:, None, None, None] ** order
    eye = np.broadcast_to(np.eye(traj.nq), (len(x), len(s), traj.nq, traj.nq))
    d_free = _chain(eye / scale, Bf)
    d_T = -order * y / T[:, None, None]
    return _two_sided(y, d_free, d_T, limit)


def _inverse_dynamics_derivatives(robot: Any, q: np.ndarray, v: np.ndarray, a: np.ndarray):
    """(∂u/∂q, ∂u/∂v, ∂u/∂a), each (..., nq_out, nq_in), by central differences in the state,
    all perturbations in one batched call; the Coulomb term (constant away from rest) is
    removed from ∂u/∂v exactly."""
    nq = q.shape[-1]
    # Perturbations (3 state parts, 2 signs, nq joints) of (q, v, a): (6 nq, 3, nq)
    delta = np.zeros((3, 2, nq, 3, nq))
    for part in range(3):
        delta[part, 0, :, part, :] = _H * np.eye(nq)
        delta[part, 1, :, part, :] = -_H * np.eye(nq)
    delta = delta.reshape(6 * nq, 3, nq)
    base = (q[..., None, :], v[..., None, :], a[..., None, :])
    u = robot.inverse_dynamics(*(base[i] + delta[:, i] for i in range(3)))  # (..., 6nq, nq)
    u = u.reshape(*q.shape[:-1], 3, 2, nq, nq)
    d = (u[..., 0, :, :] - u[..., 1, :, :]) / (2.0 * _H)  # (..., 3, nq_in, nq_out)
    d = np.swapaxes(d, -1, -2)  # (..., 3, nq_out, nq_in)
    friction = np.asarray(robot.model.friction, dtype=float)
    if np.any(friction):
        from adept_traj.robot import coulomb_sign

        jump = (coulomb_sign(v + _H) - coulomb_sign(v - _H)) / (2.0 * _H)  # (..., nq)
        idx = np.arange(nq)
        d[..., 1, idx, idx] -= friction * jump
    return d[..., 0, :, :], d[..., 1, :, :], d[..., 2, :, :]


def _torque(problem: Any, x: np.ndarray):
    """Torque rows at the problem's samples."""
    traj, robot = problem.trajectory, problem.robot
    s = problem.s
    smp = traj.sample(x, s, orders=(0, 1, 2))
    u = robot.inverse_dynamics(smp.q, smp.qd, smp.qdd)  # (pop, n_s, nq)
    dq, dv, da = _inverse_dynamics_derivatives(robot, smp.q, smp.qd, smp.qdd)
    T = x[:, 0][:, None, None, None]
    d_free = (
        _chain(dq, _free_basis(traj, s, 0))
        + _chain(dv / T, _free_basis(traj, s, 1))
        + _chain(da / T**2, _free_basis(traj, s, 2))
    )
    d_T = (
        -(np.einsum("pkij,pkj->pki", dv, smp.qd) + 2.0 * np.einsum("pkij,pkj->pki", da, smp.qdd))
        / x[:, 0][:, None, None]
    )
    return _two_sided(u, d_free, d_T, robot.limits.bound(LIMITS[4].name))


def _distance(problem: Any, x: np.ndarray):
    """Distance rows at the problem's samples, one per sample and obstacle. The state
    derivatives are taken only at the samples closer than ``influence + _NEAR`` to some
    obstacle (elsewhere the clipped distance is constant: zero gradient)."""
    traj, st, checker = problem.trajectory, problem.settings, problem.checker
    s = problem.s
    smp = traj.sample(x, s, orders=(0,))
    q, t = smp.q, smp.t  # (pop, n_s, nq), (pop, n_s)
    nq = traj.nq
    d0 = np.minimum(checker.distances(q, t).distance.min(axis=-2), st.influence)
    pop, n_s, n_obs = d0.shape
    grad_q = np.zeros((pop, n_s, n_obs, nq))
    grad_t = np.zeros((pop, n_s, n_obs))
    near = np.flatnonzero((d0 < st.influence + _NEAR).any(axis=-1).ravel())
    if len(near):
        # ± each joint, then ± time: (n_near, 2 nq + 2, ·)
        dq = np.concatenate([_H * np.eye(nq), -_H * np.eye(nq), np.zeros((2, nq))])
        dt = np.concatenate([np.zeros(2 * nq), [_H, -_H]])
        qs = q.reshape(-1, nq)[near][:, None, :] + dq
        ts = t.reshape(-1)[near][:, None] + dt
        d = np.minimum(checker.distances(qs, ts).distance.min(axis=-2), st.influence)
        g_q = np.moveaxis((d[:, :nq] - d[:, nq : 2 * nq]) / (2 * _H), 1, -1)
        grad_q.reshape(-1, n_obs, nq)[near] = g_q
        grad_t.reshape(-1, n_obs)[near] = (d[:, -2] - d[:, -1]) / (2 * _H)
    d_free = _chain(grad_q, _free_basis(traj, s, 0))  # (pop, n_s, n_obs, nq·n_free)
    d_T = grad_t * s[None, :, None]
    jac = -np.concatenate([d_T[..., None], d_free], axis=-1) / st.influence
    vals = (st.margin + st.search_buffer - d0) / st.influence
    return vals.reshape(pop, n_s * n_obs), jac.reshape(pop, n_s * n_obs, jac.shape[-1])
