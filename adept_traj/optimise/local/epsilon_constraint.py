r"""The ε-constraint polish of a front member: improve one objective, worsen none (SLSQP).

:func:`epsilon_step` solves, from a front member :math:`x_0` with objectives :math:`z^0`,
a smooth problem over :math:`y = [x, s, m_1 … m_{n_{obs}}]`:

.. math::
    \min_y \; \frac{\sigma_j \hat z_j(y)}{r_j} \quad \text{s.t.} \quad g_k(x) \le 0 \ \forall k,
    \quad w(q_k) \ge s \ \forall k, \quad d_{k,o} \ge m_o \ \forall k, o, \quad
    \sigma_i \hat z_i(y) \le \sigma_i z^0_i \ \ (i \ne j),

    |x - x_0| \le \beta\,(x_u - x_l), \quad x_l \le x \le x_u, \quad m_o \le \delta,

where :math:`g_k` are the smooth per-sample constraints of
:func:`~adept_traj.problem.local_constraints`, :math:`\hat z = (T, z_2, \sum_o
\varphi(m_o), s, z_5, z_6)` the objectives with z3 and z4 in **epigraph** form
(:mod:`adept_traj.problem.objective_gradients`: :math:`w` the manipulability at the samples,
:math:`d_{k,o}` the distances clipped at δ, :math:`\varphi(d) = \max(0, 1 - d/\delta)^2`,
decreasing; at any feasible y, :math:`z_4(x) \ge s` and :math:`z_3(x) \le \sum_o
\varphi(m_o)`, with equality at the optimum), :math:`\sigma_i = -1` for the maximised z4
and +1 otherwise, :math:`r_j` a typical range of objective j and β = 3 % a local box. A
move that improves :math:`z_j` with these constraints dominates its start.

Details, each measured on paper fronts:

- the control points that shape a joint where it is at rest are frozen: z2's Coulomb term
  jumps when a resting joint starts to move;
- only the rows that can bind inside the box (by their linear bound) are handed to SLSQP,
  whose subproblem costs grow with the rows (2 900 on a paper member);
- the rows :math:`\hat z_i \le z^0_i` are tightened by ``1e-7`` of the range, except z4
  (its minimum is often at the fixed start or goal, where no move can raise it) and a z3
  at its floor 0 (exact through the bound :math:`m_o \le \delta`);
- **the solver does not decide**: after every SLSQP iteration the moves from the best so
  far towards the iterate (fractions 1, ½, …, 1/32; T raised to the spline's exact
  kinematic minimum, :func:`~adept_traj.optimise.kinematic_time`) are evaluated by the
  problem, and the best one that is feasible, worsens no other objective and improves
  :math:`z_j` is kept (SLSQP's iterates meet the nonlinear rows only to first order); the
  solve stops after :data:`MAX_EVALUATIONS` constraint-and-Jacobian evaluations. The
  caller certifies the result.

SLSQP runs with one BLAS thread (as
:func:`~adept_traj.optimise.local.minimum_time.minimum_time`): the same start gives the same
move.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.local.minimum_time import PolishOutcome
from adept_traj.optimise.operators.repair import KINEMATIC_SLACK, kinematic_time
from adept_traj.problem import MAXIMISED, local_constraints, objective_gradients
from adept_traj.robot import VELOCITY_AT_REST
from adept_traj.validation import as_integer, as_vector

__all__ = [
    "MAX_EVALUATIONS",
    "checked_start",
    "epsilon_solve",
    "epsilon_step",
]

#: σ_i of the sign convention: −1 where maximised (z4).
_SIGN = np.where(MAXIMISED, -1.0, 1.0)

#: Relative tightening of the "not worse" constraints (fraction of the objective's range).
_TIGHTEN = 1e-7

#: Objectives whose "not worse" constraint is tightened: z1, z2, z5, z6, and z3 when it is
#: not at its floor 0. Not z4: its minimum is often at the fixed start or goal, where no
#: move can raise it, and a tightened row would make SLSQP's subproblem infeasible.
_TIGHTENED = np.array([True, True, True, False, True, True])


#: Half-width of the box around the start that the solve stays in, as a fraction of each
#: decision variable's range (xu − xl): a local step (SLSQP's first iterates otherwise
#: leave the region where its linearisations hold, measured on paper fronts).
_BOX = 0.03

#: The solve stops at the first iteration that ends with at least this many evaluations
#: (measured on a paper front: the steps that succeed take 9–19 evaluations; a start whose
#: first iterates leave the feasible region took > 100 in 10 iterations without coming
#: back).
MAX_EVALUATIONS = 20

#: Fractions of the way from the best move so far to each SLSQP iterate that are evaluated
#: (SLSQP's iterates meet the objectives' constraints only to first order: a shorter step
#: often keeps every objective not worse where the full one does not).
_FRACTIONS = 0.5 ** np.arange(6)

#: Slack of the rows kept for the solve (normalised units, see ``_rows_in_reach``).
_ROW_SLACK = 0.05


def epsilon_step(
    problem: Any, x0: Any, objective: int, scale: Any, *, max_iter: int = 30
) -> PolishOutcome:
    """Improve objective ``objective`` (0…5 for z1…z6) from ``x0`` (n_var,) with no other
    objective worse and every constraint kept (see the module docstring).

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem` (``z3="clearance"``).
    x0:
        (n_var,) start ``[T [s], free control points [rad | m]]``, inside the bounds.
    objective:
        Index of the objective to improve (0 = z1 … 5 = z6).
    scale:
        (6,) a typical range of each objective (units of z; > 0 where used): the
        objective is divided by it, the tightening of the others is relative to it.
    max_iter:
        Most SLSQP iterations (≥ 1).

    Returns
    -------
    PolishOutcome
        ``x`` the best kept move (a copy of ``x0`` when none was found);
        ``n_evaluations`` counts constraint-and-Jacobian evaluations and batches of
        evaluated moves.
    """
    x0 = checked_start(problem, x0)
    j = as_integer(objective, "objective", minimum=0, maximum=5, error=ConfigurationError)
    span = as_vector(scale, "scale", 6)
    if span[j] <= 0.0:
        raise ConfigurationError(f"scale[{j}] must be > 0; got {span[j]}")
    cost = np.zeros(6)
    cost[j] = _SIGN[j] / span[j]
    keep = np.ones(6, dtype=bool)
    keep[j] = False
    max_iter = as_integer(max_iter, "max_iter", minimum=1, error=ConfigurationError)
    return epsilon_solve(problem, x0, cost, keep, span, max_iter)


def checked_start(problem: Any, x0: Any) -> np.ndarray:
    """The start of a member polish, checked.

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    x0:
        (n_var,) the start ``[T [s], control points [rad | m]]``.

    Returns
    -------
    numpy.ndarray
        (n_var,) float64.

    Raises
    ------
    ConfigurationError
        ``x0`` outside the decision bounds, or the problem's ``z3`` is not ``"clearance"``.
    """
    x0 = as_vector(x0, "x0", problem.n_var)
    if np.any(x0 < problem.xl) or np.any(x0 > problem.xu):
        raise ConfigurationError("x0 must lie inside the decision bounds (problem.xl, problem.xu)")
    if problem.settings.z3 != "clearance":
        raise ConfigurationError(
            f"the member polish needs z3='clearance'; got {problem.settings.z3!r}"
        )
    return x0


def epsilon_solve(problem: Any, x0: np.ndarray, *args: Any, **options: Any) -> PolishOutcome:
    """The ε-constraint SLSQP solve of :func:`epsilon_step`, BLAS limited to one thread.

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    x0:
        (n_var,) the checked start (:func:`checked_start`).
    *args:
        ``cost`` (6,) weights of the objectives (z / scale), ``no_worse`` (6,) bool (the
        objectives kept no worse), ``span`` (6,) the objectives' scales, ``max_iter``.
    **options:
        ``box`` (the trust box, a fraction of each variable's range) and
        ``max_evaluations``.

    Returns
    -------
    PolishOutcome
        As :func:`epsilon_step`.
    """
    import scipy.optimize  # noqa: F401  (lazy; loaded first: its BLAS is limited too)
    from threadpoolctl import threadpool_limits  # lazy, as in minimum_time

    with threadpool_limits(limits=1, user_api="blas"):
        return _solve(problem, x0, *args, **options)


class _Pieces:
    """Everything of one point x: constraint rows, ẑ and its Jacobian, epigraph rows."""

    def __init__(self, problem: Any, x: np.ndarray) -> None:
        lc = local_constraints(problem, x)
        og = objective_gradients(problem, x, local=lc)
        self.g, self.dg = lc.values[0], lc.jacobian[0]
        self.z, self.dz = og.values[0], og.jacobian[0]
        self.w, self.dw = og.manipulability[0], og.manipulability_jacobian[0]
        self.d, self.dd = og.distance[0].ravel(), og.distance_jacobian[0].reshape(-1, len(x))
        self.n_obs = og.distance.shape[-1]


def _solve(
    problem: Any,
    x0: np.ndarray,
    cost: np.ndarray,
    no_worse: np.ndarray,
    span: np.ndarray,
    max_iter: int,
    *,
    box: float = _BOX,
    max_evaluations: int = MAX_EVALUATIONS,
) -> PolishOutcome:
    from scipy.optimize import minimize  # lazy: scipy.optimize is heavy

    started = time.perf_counter()
    st, n = problem.settings, problem.n_var
    counter, moves, spent = [0], [0], [0.0]  # gradient evaluations, moves evaluated, [s]
    cache: dict[bytes, _Pieces] = {}

    def pieces(y: np.ndarray) -> _Pieces:
        x = np.clip(y[:n], problem.xl, problem.xu)
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            tic = time.perf_counter()
            cache[key] = _Pieces(problem, x)
            counter[0] += 1
            spent[0] += time.perf_counter() - tic
        return cache[key]

    p0 = pieces(x0)
    z0, n_obs = p0.z, p0.n_obs
    obstacle = np.tile(np.arange(n_obs), len(p0.w))  # obstacle of each distance row
    n_y = n + 1 + n_obs
    m0 = p0.d.reshape(-1, n_obs).min(axis=0)
    y0 = np.concatenate([x0, [p0.w.min()], m0])
    scale = np.where(span > 0.0, span, np.maximum(np.abs(z0), 1e-12))
    limit = _SIGN * z0 - np.where(_TIGHTENED & (z0 > 0.0), _TIGHTEN * scale, 0.0)
    rows = np.flatnonzero(no_worse)
    w_scale = max(float(z0[3]), 1e-12)
    half = box * (problem.xu - problem.xl)
    half[_at_rest(problem, x0)] = 0.0
    lower, upper = np.maximum(problem.xl, x0 - half), np.minimum(problem.xu, x0 + half)
    on_g, on_w, on_d = _rows_in_reach(p0, half, st.influence)

    def surrogate(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """ẑ (6,) with z3, z4 in epigraph form, and its Jacobian (6, n_y)."""
        p = pieces(y)
        slack = np.maximum(0.0, 1.0 - y[n + 1 :] / st.influence)
        z = p.z.copy()
        z[2], z[3] = np.sum(slack**2), y[n]
        jac = np.zeros((6, n_y))
        jac[:, :n] = p.dz
        jac[2:4] = 0.0
        jac[2, n + 1 :] = -2.0 * slack / st.influence
        jac[3, n] = 1.0
        return z, jac

    def values(y: np.ndarray) -> np.ndarray:  # scipy: feasible where ≥ 0
        p = pieces(y)
        z = surrogate(y)[0]
        return np.concatenate(
            [
                -p.g[on_g],
                (p.w[on_w] - y[n]) / w_scale,
                (p.d[on_d] - y[n + 1 + obstacle[on_d]]) / st.influence,
                (limit[rows] - _SIGN[rows] * z[rows]) / scale[rows],
            ]
        )

    def jacobian(y: np.ndarray) -> np.ndarray:
        p = pieces(y)
        jz = surrogate(y)[1]
        j_g = np.zeros((len(on_g), n_y))
        j_g[:, :n] = -p.dg[on_g]
        j_w = np.zeros((len(on_w), n_y))
        j_w[:, :n], j_w[:, n] = p.dw[on_w] / w_scale, -1.0 / w_scale
        j_d = np.zeros((len(on_d), n_y))
        j_d[:, :n] = p.dd[on_d] / st.influence
        j_d[np.arange(len(on_d)), n + 1 + obstacle[on_d]] = -1.0 / st.influence
        j_e = -(_SIGN[rows] / scale[rows])[:, None] * jz[rows]
        return np.concatenate([j_g, j_w, j_d, j_e])

    best: list[Any] = [x0, z0, None]  # the best acceptable iterate, its z, its evaluation

    def keep_if_better(y: np.ndarray) -> None:
        """Evaluate moves from the best so far towards the iterate (fractions
        :data:`_FRACTIONS`, T raised to the kinematic minimum), in one batch, and keep the
        best that is feasible, has no objective of ``no_worse`` worse than at the start, and
        lowers the cost."""
        step = np.clip(y[:n], problem.xl, problem.xu) - best[0]
        x = best[0] + _FRACTIONS[:, None] * step
        t_kin = kinematic_time(problem, x) * (1.0 + KINEMATIC_SLACK)
        x[:, 0] = np.minimum(np.maximum(x[:, 0], t_kin), problem.xu[0])
        ev = problem.evaluate_batch(x)
        moves[0] += 1  # one batch
        spent[0] += ev.seconds
        z = ev.objectives
        ok = (
            np.all(ev.constraints <= 0.0, axis=1)
            & np.all(_SIGN[rows] * z[:, rows] <= _SIGN[rows] * z0[rows], axis=1)
            & (z @ cost < cost @ best[1])
        )
        if ok.any():
            k = np.flatnonzero(ok)[np.argmin(z[ok] @ cost)]
            best[:] = [x[k], z[k], (ev.objectives[k], ev.constraints[k])]
        if counter[0] >= max_evaluations:
            raise StopIteration  # scipy ends the solve (its callback protocol)

    res = minimize(
        lambda y: float(cost @ surrogate(y)[0]),
        y0,
        jac=lambda y: cost @ surrogate(y)[1],
        method="SLSQP",
        bounds=[*zip(lower, upper), (0.0, None), *([(None, st.influence)] * n_obs)],
        constraints=[{"type": "ineq", "fun": values, "jac": jacobian}],
        options={"maxiter": max_iter, "ftol": 1e-10},
        callback=keep_if_better,
    )
    x, _, found = best
    if found is None:  # nothing better than the start: the start, evaluated
        ev = problem.evaluate_batch(x)
        moves[0] += 1
        spent[0] += ev.seconds
        found = (ev.objectives, ev.constraints)
    return PolishOutcome(
        x=x.copy(),
        objectives=found[0],
        constraints=found[1],
        feasible=bool(np.all(found[1] <= 0.0)),
        start=x0.copy(),
        n_iterations=int(res.nit),
        n_evaluations=counter[0] + moves[0],
        seconds=time.perf_counter() - started,
        evaluation_s=spent[0],
        message=str(res.message),
    )


def _rows_in_reach(p0: _Pieces, half: np.ndarray, influence: float) -> tuple[np.ndarray, ...]:
    r"""Indices of the rows that may bind inside the box ``x0 ± half`` (n_var,), by their
    linear bound :math:`|\Delta r| \le |\nabla r|\,h`: constraint rows that can reach
    −_ROW_SLACK, manipulability rows whose lowest value may be the minimum, distance rows
    likewise per obstacle (a clipped row with a zero gradient never binds below the bound
    :math:`m_o \le \delta`). SLSQP's subproblem costs grow with the rows (2 900 on a paper
    member); the evaluator's check of every
    iterate catches a dropped row that binds after all."""
    reach_g = np.abs(p0.dg) @ half
    on_g = np.flatnonzero(p0.g + reach_g > -_ROW_SLACK)
    reach_w = np.abs(p0.dw) @ half
    on_w = np.flatnonzero(p0.w - reach_w <= np.min(p0.w + reach_w) + _ROW_SLACK * p0.w.min())
    d = p0.d.reshape(-1, p0.n_obs)
    reach_d = (np.abs(p0.dd) @ half).reshape(d.shape)
    low = d - reach_d
    near = (low <= np.min(d + reach_d, axis=0) + _ROW_SLACK * influence) & (
        (d < influence) | (reach_d > 0.0)
    )
    return on_g, on_w, np.flatnonzero(near.ravel())


def _at_rest(problem: Any, x: np.ndarray) -> np.ndarray:
    """(n_var,) bool: the free control points that shape a joint where it is at rest
    (speed ≤ :data:`~adept_traj.robot.VELOCITY_AT_REST` at a sample of ``problem.s``)."""
    traj = problem.trajectory
    qd = traj.sample(x, problem.s, orders=(1,)).qd  # (n_s, nq)
    basis = traj.basis_matrix(problem.s, 0)[:, 3:-3] != 0.0  # (n_s, n_free)
    rest = np.abs(qd) <= VELOCITY_AT_REST
    frozen = np.einsum("kj,kc->jc", rest, basis) > 0  # (nq, n_free), joint-major as x
    return np.concatenate([[False], frozen.ravel()])
