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

**Nothing is a finite difference.** The state derivatives of the two black boxes are
analytic too: :math:`\partial u/\partial(q, \dot q, \ddot q)` by Pinocchio's RNEA
derivatives (``computeRNEADerivatives``; rotor inertia included, the viscous friction
added, the Coulomb term's derivative 0 away from rest) and :math:`\partial d/\partial(q, t)`
from coal's nearest points and normal through the joint Jacobians and the obstacles'
motion laws (:func:`~adept_traj.collision.distance_gradients`, which also says what
happens at ties and in penetration); a sample and obstacle farther than ``influence`` has
a zero gradient, exact for the clipped distance. The spline bases of the constraint grids
are computed once and reused at every solver iteration.

Between the velocity samples the speed can exceed its sample maximum a little; the local
solver therefore finishes by raising T to the spline's exact kinematic minimum
(:func:`~adept_traj.optimise.kinematic_time`), and its result is certified like any other.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from adept_traj.collision import distance_gradients
from adept_traj.errors import ConfigurationError
from adept_traj.robot import coulomb_sign
from adept_traj.robot.limits import LIMITS
from adept_traj.validation import as_batch, as_integer

__all__ = ["CONSTRAINT_KINDS", "LocalConstraints", "local_constraints"]

#: Central-difference step in the state (joint positions [rad | m], speeds, accelerations) of
#: the dynamics' derivatives of a model with mimic joints.
_STATE_STEP = 1e-6

#: The kinds of per-sample constraints, in the order of :class:`LocalConstraints` rows.
CONSTRAINT_KINDS: tuple[str, ...] = ("velocity", "acceleration", "jerk", "torque", "distance")


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


def local_constraints(
    problem: Any, x: Any, *, points_per_segment: int = 4, extra_samples: Any = None
) -> LocalConstraints:
    r"""The smooth per-sample constraints of decision vectors ``x`` (pop, n_var) or
    (n_var,) and their Jacobians (see the module docstring).

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    x:
        Decision vectors ``[T [s], free control points [rad | m]]``.
    points_per_segment:
        Velocity samples per spline segment (≥ 1; plus the last knot).
    extra_samples:
        (k,) normalised times :math:`s \in [0, 1]` where the torque and distance rows are
        also imposed, after those at ``problem.s`` (``None``: none): the adaptive samples
        of the certified local solver (:mod:`adept_traj.optimise.local.refinement`), placed where
        a certificate found the distance dipping between the problem's samples.

    Returns
    -------
    LocalConstraints
        With a leading population axis of 1 for a single vector.
    """
    xa = np.atleast_2d(as_batch(x, "x", problem.n_var))
    n = as_integer(points_per_segment, "points_per_segment", minimum=1, error=ConfigurationError)
    if not np.all(xa[:, 0] > 0.0):
        raise ConfigurationError(f"travel times x[:, 0] must be > 0 [s]; got {xa[:, 0]}")
    s = problem.s
    if extra_samples is not None:
        extra = np.asarray(extra_samples, dtype=float).ravel()
        if not np.all((extra >= 0.0) & (extra <= 1.0)):
            raise ConfigurationError(
                f"extra_samples must be normalised times in [0, 1]; got {extra}"
            )
        s = np.concatenate([s, extra])
    return _local_constraints(problem, xa, n, s)


def _local_constraints(
    problem: Any, x: np.ndarray, n_per_segment: int, s_rows: np.ndarray
) -> LocalConstraints:
    traj = problem.trajectory
    S = traj.n_segments
    grids = (
        np.linspace(0.0, 1.0, n_per_segment * S + 1),  # velocity
        np.linspace(0.0, 1.0, S + 1),  # acceleration: the knots
        (np.arange(S) + 0.5) / S,  # jerk: the segment midpoints
    )
    T, P = traj.decode(x)
    blocks = [
        _kinematic(T, P, S, s, order, problem.robot.limits.bound(kind.name))
        for order, (s, kind) in enumerate(zip(grids, LIMITS[1:4]), start=1)
    ]
    blocks.append(_torque(problem, T, P, s_rows))
    blocks.append(_distance(problem, T, P, s_rows))
    kind = np.concatenate([np.full(b[0].shape[1], i) for i, b in enumerate(blocks)])
    return LocalConstraints(
        values=np.concatenate([b[0] for b in blocks], axis=1),
        jacobian=np.concatenate([b[1] for b in blocks], axis=1),
        kind=kind,
    )


def _basis(n_segments: int, s: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    """(n_s, n_control) basis of the uniform spline of ``n_segments`` at ``s`` (derivative
    ``order``) and its free columns (n_s, n_free), computed once per grid (the same at
    every solver iteration; read-only)."""
    return _cached_basis(n_segments, s.tobytes(), order)


@functools.lru_cache(maxsize=64)
def _cached_basis(n_segments: int, s_bytes: bytes, order: int) -> tuple[np.ndarray, np.ndarray]:
    from adept_traj.problem.bspline import BSplineTrajectory

    s = np.frombuffer(s_bytes)
    zeros = np.zeros(1)
    full = BSplineTrajectory(zeros, zeros, n_knots=n_segments + 1).basis_matrix(s, order)
    free = np.ascontiguousarray(full[:, 3:-3])
    full.flags.writeable = free.flags.writeable = False
    return full, free


def _samples(P: np.ndarray, T: np.ndarray, n_segments: int, s: np.ndarray, order: int):
    """(pop, n_s, nq) derivative ``order`` in time of the splines ``(T, P)`` at ``s``."""
    full, _ = _basis(n_segments, s, order)
    return np.einsum("kc,pcj->pkj", full, P) / T[:, None, None] ** order


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


def _kinematic(T, P, n_segments: int, s: np.ndarray, order: int, limit: np.ndarray):
    """Velocity (order 1), acceleration (2) or jerk (3) rows at ``s``."""
    y = _samples(P, T, n_segments, s, order)  # (pop, n_s, nq)
    nq = y.shape[-1]
    scale = T[:, None, None, None] ** order
    eye = np.broadcast_to(np.eye(nq), (len(T), len(s), nq, nq))
    d_free = _chain(eye / scale, _basis(n_segments, s, order)[1])
    d_T = -order * y / T[:, None, None]
    return _two_sided(y, d_free, d_T, limit)


def _inverse_dynamics_derivatives(robot: Any, q: np.ndarray, v: np.ndarray, a: np.ndarray):
    """(∂u/∂q, ∂u/∂v, ∂u/∂a), each (..., nq_out, nq_in), of
    :meth:`~adept_traj.robot.Robot.inverse_dynamics`: Pinocchio's analytic RNEA derivatives
    (rotor inertia included in :math:`\\partial u/\\partial a = M(q)`), the viscous friction's
    :math:`F_v` added to :math:`\\partial u / \\partial v`; the Coulomb term's derivative is
    0 away from rest. One Pinocchio call per sample (no batched variant exists; still
    faster than batched central differences, 116 samples). Pinocchio's derivatives
    do not support mimic joints (the Panda's fingers): such a model takes
    :func:`_central_dynamics_derivatives`."""
    model = robot.model
    if any(j.shortname() == "JointModelMimic" for j in model.joints):
        return _central_dynamics_derivatives(robot, q, v, a)
    data = model.createData()
    nq = q.shape[-1]
    flat = [np.ascontiguousarray(z.reshape(-1, nq)) for z in (q, v, a)]
    out = np.empty((3, flat[0].shape[0], nq, nq))
    for i, (qi, vi, ai) in enumerate(zip(*flat)):
        pin.computeRNEADerivatives(model, data, qi, vi, ai)
        out[0, i], out[1, i], out[2, i] = data.dtau_dq, data.dtau_dv, data.M
    upper = np.triu(out[2])  # Pinocchio fills the upper triangle of M
    out[2] = upper + np.swapaxes(np.triu(upper, 1), -1, -2)
    out[1] += np.diag(np.asarray(model.damping, dtype=float))
    return tuple(o.reshape(*q.shape, nq) for o in out)


def _central_dynamics_derivatives(robot: Any, q: np.ndarray, v: np.ndarray, a: np.ndarray):
    """(∂u/∂q, ∂u/∂v, ∂u/∂a) as :func:`_inverse_dynamics_derivatives`, by central differences
    in the state (step :data:`_STATE_STEP`), all perturbations in one batched call of
    :meth:`~adept_traj.robot.Robot.inverse_dynamics`; the Coulomb term (constant away from
    rest) is left out of ∂u/∂v exactly."""
    nq, h = q.shape[-1], _STATE_STEP
    delta = np.zeros((3, 2, nq, 3, nq))  # (state part, sign, joint, state part, joint)
    for part in range(3):
        delta[part, 0, :, part, :] = h * np.eye(nq)
        delta[part, 1, :, part, :] = -h * np.eye(nq)
    delta = delta.reshape(6 * nq, 3, nq)
    base = (q[..., None, :], v[..., None, :], a[..., None, :])
    u = robot.inverse_dynamics(*(base[i] + delta[:, i] for i in range(3)))  # (..., 6nq, nq)
    u = u.reshape(*q.shape[:-1], 3, 2, nq, nq)
    d = np.swapaxes((u[..., 0, :, :] - u[..., 1, :, :]) / (2.0 * h), -1, -2)
    friction = np.asarray(robot.model.friction, dtype=float)
    if np.any(friction):
        jump = (coulomb_sign(v + h) - coulomb_sign(v - h)) / (2.0 * h)  # (..., nq)
        idx = np.arange(nq)
        d[..., 1, idx, idx] -= friction * jump
    return d[..., 0, :, :], d[..., 1, :, :], d[..., 2, :, :]


def _torque(problem: Any, T: np.ndarray, P: np.ndarray, s: np.ndarray):
    """Torque rows at the samples ``s`` (n_s,)."""
    robot, S = problem.robot, problem.trajectory.n_segments
    q, qd, qdd = (_samples(P, T, S, s, order) for order in range(3))
    u = robot.inverse_dynamics(q, qd, qdd)  # (pop, n_s, nq)
    dq, dv, da = _inverse_dynamics_derivatives(robot, q, qd, qdd)
    T4 = T[:, None, None, None]
    d_free = (
        _chain(dq, _basis(S, s, 0)[1])
        + _chain(dv / T4, _basis(S, s, 1)[1])
        + _chain(da / T4**2, _basis(S, s, 2)[1])
    )
    d_T = -(np.einsum("pkij,pkj->pki", dv, qd) + 2.0 * np.einsum("pkij,pkj->pki", da, qdd))
    return _two_sided(u, d_free, d_T / T[:, None, None], robot.limits.bound(LIMITS[4].name))


def _distance(problem: Any, T: np.ndarray, P: np.ndarray, s: np.ndarray):
    """Distance rows at the samples ``s`` (n_s,), one per sample and obstacle, with coal's
    witness-point derivatives (:func:`~adept_traj.collision.distance_gradients`: zero
    where the clipped distance is at ``influence``)."""
    st, S = problem.settings, problem.trajectory.n_segments
    q = _samples(P, T, S, s, 0)
    grad = distance_gradients(problem.checker, q, T[:, None] * s)
    d0 = np.minimum(grad.distance, st.influence)  # (pop, n_s, n_obs)
    pop, n_s, n_obs = d0.shape
    d_free = _chain(grad.dq, _basis(S, s, 0)[1])  # (pop, n_s, n_obs, nq·n_free)
    d_T = grad.dt * s[None, :, None]
    jac = -np.concatenate([d_T[..., None], d_free], axis=-1) / st.influence
    vals = (st.margin + st.search_buffer - d0) / st.influence
    return vals.reshape(pop, n_s * n_obs), jac.reshape(pop, n_s * n_obs, jac.shape[-1])
