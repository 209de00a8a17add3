r"""Gradients of the six objectives z1…z6 with respect to the decision vector, batched.

With :math:`x = [T, P_{free}]` and the spline samples of
:mod:`adept_traj.problem.gradients` (:math:`q^{(r)}_k = B^{(r)}_k P / T^r`),
:func:`objective_gradients` returns the objectives exactly as the evaluator computes them
(:meth:`~adept_traj.problem.TrajectoryProblem.evaluate_batch`) and their gradients:

- **z1** :math:`= T`: :math:`\partial z_1/\partial x = e_0` (exact).
- **z5, z6**: quadratic in the control points with a power of T (exact; the Gram matrices
  :math:`M_r = \int_0^1 B^{(r)\top} B^{(r)} ds` by Gauss–Legendre quadrature, exact for the
  piecewise-polynomial integrands):

  .. math::
      z_6 = T^{-3} \sum_j P_j^\top M_2 P_j, \quad z_5 = T^{-5} \sum_j P_j^\top M_3 P_j,
      \quad \frac{\partial z}{\partial P_{c,j}} = \frac{2 (M_r P_j)_c}{T^{2r-1}}, \quad
      \frac{\partial z}{\partial T} = -\frac{(2r-1)\, z}{T}.

- **z2** :math:`= T \sum_k w_k \sum_i u_{k,i}^2` (the problem's quadrature at ``problem.s``):

  .. math::
      \frac{\partial z_2}{\partial x} = e_0 \sum_k w_k \lVert u_k\rVert^2
        + 2 T \sum_k w_k\, u_k^\top \frac{\partial u_k}{\partial x},

  with the torques and their derivatives :math:`\partial u_k/\partial x` of the torque rows
  of :func:`~adept_traj.problem.local_constraints` (the inverse dynamics' state derivative
  through the chain rule; finite torque limits needed).
- **z3** :math:`= \sum_o \varphi(\min_k d_{k,o})`, :math:`\varphi(d) = \max(0, 1 -
  d/\delta)^2` (``z3="clearance"`` only): the gradient of the minimum at its sample
  :math:`k^\star_o` (the derivative wherever that sample is unique),
  :math:`\sum_o \varphi'(d_{k^\star_o, o})\, \partial d_{k^\star_o,o}/\partial x`, with the
  per-sample distances and their derivatives of the distance rows of
  :func:`~adept_traj.problem.local_constraints` (clipped at :math:`\delta`).
- **z4** :math:`= \min_k w(q_k)`, :math:`w = |\det J_t|`
  (:meth:`~adept_traj.robot.Robot.manipulability`): likewise the gradient at the minimising
  sample, :math:`\partial w/\partial q` by central differences in the state (step 1e-6
  [rad | m], one batched call over all samples) times :math:`B^{(0)}_k`.

**Smooth per-sample forms.** z3 and z4 are minima over the samples, not differentiable
where two samples tie. A gradient-based solver uses instead the per-sample values returned
here (:attr:`ObjectiveGradients.manipulability`, :attr:`ObjectiveGradients.distance` and
their Jacobians): as a **constraint**, :math:`z_4 \ge z_4^0` is exactly
:math:`w(q_k) \ge z_4^0` for every sample k, and :math:`z_3 \le z_3^0` holds when
:math:`d_{k,o} \ge \min_{k'} d^0_{k',o}` for every sample and obstacle (sufficient: no
obstacle comes closer than before); as an **objective**, the epigraph: maximise a level
:math:`s` with :math:`w(q_k) \ge s` for all k, and minimise :math:`\sum_o \varphi(m_o)` with
:math:`d_{k,o} \ge m_o` (φ decreasing: at the optimum :math:`s` and :math:`m_o` are the
minima). See :mod:`adept_traj.optimise.local.epsilon_constraint`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.problem.gradients import CONSTRAINT_KINDS, LocalConstraints, local_constraints
from adept_traj.robot.limits import LIMITS
from adept_traj.validation import as_batch, check_type

__all__ = ["ObjectiveGradients", "check_differentiable", "objective_gradients"]

#: Central-difference step in the joint positions [rad | m] for ∂|det J|/∂q.
_H = 1e-6


@dataclass(frozen=True)
class ObjectiveGradients:
    """The objectives of a population, their gradients and the smooth per-sample pieces.

    Attributes
    ----------
    values:
        (pop, 6) z1…z6 as reported (z4 positive; units of
        :data:`~adept_traj.problem.OBJECTIVES`).
    jacobian:
        (pop, 6, n_var) :math:`\\partial z_i / \\partial x` (z4 of the reported, positive,
        value).
    manipulability:
        (pop, n_s) :math:`|\\det J_t(q_k)|` at the samples ``problem.s`` [m² for the SCARA].
    manipulability_jacobian:
        (pop, n_s, n_var) its derivative.
    distance:
        (pop, n_s, n_obs) smallest distance [m] between the robot and each obstacle at the
        samples, clipped at the influence distance δ.
    distance_jacobian:
        (pop, n_s, n_obs, n_var) its derivative (0 where clipped).
    """

    values: np.ndarray
    jacobian: np.ndarray
    manipulability: np.ndarray
    manipulability_jacobian: np.ndarray
    distance: np.ndarray
    distance_jacobian: np.ndarray


def objective_gradients(
    problem: Any, x: Any, *, local: LocalConstraints | None = None
) -> ObjectiveGradients:
    """The objectives of ``x`` (pop, n_var) or (n_var,) and their gradients (see the module
    docstring).

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem` (``z3="clearance"``, finite
        torque limits).
    x:
        Decision vectors ``[T [s], free control points [rad | m]]``.
    local:
        :func:`~adept_traj.problem.local_constraints` of the same ``x`` if already computed
        (its torque and distance rows are reused).

    Returns
    -------
    ObjectiveGradients
        With a leading population axis of 1 for a single vector.
    """
    xa = np.atleast_2d(as_batch(x, "x", problem.n_var))
    check_differentiable(problem)
    if local is None:
        local = local_constraints(problem, xa)
    else:
        check_type(local, LocalConstraints, "local")
        if local.values.shape[0] != len(xa):
            raise ConfigurationError(
                f"local has {local.values.shape[0]} vectors but x has {len(xa)}"
            )
    return _objective_gradients(problem, xa, local)


def check_differentiable(problem: Any) -> None:
    """Refuse (:class:`~adept_traj.errors.ConfigurationError`) a problem whose objectives
    have no gradients here: ``z3`` other than ``"clearance"`` (the paper's penalties are not
    differentiated) or an infinite torque limit (z2's gradient uses the torque rows)."""
    if problem.settings.z3 != "clearance":
        raise ConfigurationError(
            f"objective gradients need z3='clearance'; this problem has z3="
            f"{problem.settings.z3!r} (the paper's penalties are not differentiated)"
        )
    torque_limit = problem.robot.limits.bound(LIMITS[4].name)
    if not np.all(np.isfinite(torque_limit)):
        raise ConfigurationError(
            f"the z2 gradient needs finite torque limits [N·m | N]; got {torque_limit}"
        )


def _objective_gradients(
    problem: Any, x: np.ndarray, local: LocalConstraints
) -> ObjectiveGradients:
    pop, n_var = x.shape
    traj, st = problem.trajectory, problem.settings
    T = x[:, 0]
    n_s, nq = len(problem.s), traj.nq
    jac = np.zeros((pop, 6, n_var))
    values = np.zeros((pop, 6))
    values[:, 0], jac[:, 0, 0] = T, 1.0
    # z2 from the torque rows (+u/UC − 1 first, then −u/UC − 1), joint-minor per sample.
    rows = np.flatnonzero(local.kind == CONSTRAINT_KINDS.index("torque"))[: n_s * nq]
    limit = problem.robot.limits.bound(LIMITS[4].name)
    u = ((local.values[:, rows] + 1.0).reshape(pop, n_s, nq)) * limit
    du = local.jacobian[:, rows].reshape(pop, n_s, nq, n_var) * limit[:, None]
    w = problem.weights
    energy = np.einsum("k,pki->p", w, u**2)
    values[:, 1] = T * energy
    jac[:, 1] = 2.0 * T[:, None] * np.einsum("k,pki,pkiv->pv", w, u, du)
    jac[:, 1, 0] += energy
    # z3 at each obstacle's closest sample.
    rows = np.flatnonzero(local.kind == CONSTRAINT_KINDS.index("distance"))
    n_obs = len(rows) // n_s
    g = local.values[:, rows].reshape(pop, n_s, n_obs)
    dist = st.margin + st.search_buffer - st.influence * g
    d_dist = -st.influence * local.jacobian[:, rows].reshape(pop, n_s, n_obs, n_var)
    k_star = np.argmin(dist, axis=1)  # (pop, n_obs)
    d_min = np.take_along_axis(dist, k_star[:, None], axis=1)[:, 0]  # (pop, n_obs)
    grad_min = np.take_along_axis(d_dist, k_star[:, None, :, None], axis=1)[:, 0]
    slack = np.maximum(0.0, 1.0 - d_min / st.influence)
    values[:, 2] = np.sum(slack**2, axis=1)
    jac[:, 2] = np.einsum("po,pov->pv", -2.0 * slack / st.influence, grad_min)
    # z4 at the least manipulable sample.
    manip, d_manip = _manipulability(problem, x)
    k4 = np.argmin(manip, axis=1)
    values[:, 3] = manip[np.arange(pop), k4]
    jac[:, 3] = d_manip[np.arange(pop), k4]
    # z5, z6: exact quadratic forms.
    for col, order in ((4, 3), (5, 2)):
        values[:, col], jac[:, col] = _quadratic(traj, x, order)
    return ObjectiveGradients(
        values=values,
        jacobian=jac,
        manipulability=manip,
        manipulability_jacobian=d_manip,
        distance=dist,
        distance_jacobian=d_dist,
    )


def _manipulability(problem: Any, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(pop, n_s) manipulability at the samples and (pop, n_s, n_var) its derivative."""
    traj, robot = problem.trajectory, problem.robot
    q = traj.sample(x, problem.s, orders=(0,)).q  # (pop, n_s, nq)
    nq = traj.nq
    steps = np.concatenate([_H * np.eye(nq), -_H * np.eye(nq)])  # (2 nq, nq)
    w = robot.manipulability(np.concatenate([q[..., None, :], q[..., None, :] + steps], axis=-2))
    dq = (w[..., 1 : nq + 1] - w[..., nq + 1 :]) / (2.0 * _H)  # (pop, n_s, nq)
    basis = traj.basis_matrix(problem.s, 0)[:, 3:-3]  # (n_s, n_free)
    d_free = np.einsum("pkj,kc->pkjc", dq, basis).reshape(*dq.shape[:2], -1)
    d = np.concatenate([np.zeros((*dq.shape[:2], 1)), d_free], axis=-1)
    return w[..., 0], d


def _quadratic(traj: Any, x: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    """:math:`z = T^{1-2r} \\sum_j P_j^\\top M_r P_j` (pop,) and its gradient (pop, n_var)."""
    T, P = traj.decode(x)
    s, w = traj.quadrature(2)  # B^(r) has degree ≤ 1 per segment: 2 nodes are exact
    B = traj.basis_matrix(s, order)
    gram = B.T @ (w[:, None] * B)  # (n_control, n_control)
    MP = np.einsum("cd,pdj->pcj", gram, P)
    power = 2 * order - 1
    z = np.einsum("pcj,pcj->p", P, MP) / T**power
    d_free = 2.0 * np.swapaxes(MP[:, 3:-3, :], 1, 2).reshape(len(x), -1) / T[:, None] ** power
    return z, np.concatenate([(-power * z / T)[:, None], d_free], axis=1)
