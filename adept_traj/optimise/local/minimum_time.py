r"""One SLSQP solve: the fastest move near a given one (:func:`minimum_time`).

:func:`minimum_time` solves, from a start vector :math:`x_0`,

.. math::
    \min_{x = [T, P]} T \quad \text{s.t.} \quad g_k(x) \le 0 \ \ \forall k, \qquad
    x_l \le x \le x_u,

with the smooth per-sample constraints :math:`g_k` of
:func:`~adept_traj.problem.local_constraints` (velocity, acceleration, jerk, torque and
distance per sample; exact Jacobians up to the state derivatives of the dynamics and the
distances, see :mod:`adept_traj.problem.gradients`) by scipy's SLSQP (sequential quadratic
programming; ``scipy.optimize`` is imported when first used). IPOPT (cyipopt) has no wheel
for this platform and is not offered. The solver's answer is then made kinematically exact:
T is raised to the spline's exact kinematic minimum :math:`T_{kin}(P)`
(:func:`~adept_traj.optimise.kinematic_time`) if the velocity samples missed a peak, and
the move is evaluated by the problem itself; the caller certifies it
(:func:`~adept_traj.analysis.certify`): the certificate, not the solver, decides
feasibility. The certified local solver of the polish and the time-optimal mode is
:func:`~adept_traj.optimise.refine_minimum_time`; :class:`PolishOutcome` is the record of
a local solve shared by the ε-constraint and weighted-sum solvers.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.operators.repair import KINEMATIC_SLACK, kinematic_time
from adept_traj.problem import CONSTRAINT_KINDS, local_constraints
from adept_traj.validation import as_integer, as_scalar, as_vector

__all__ = ["PolishOutcome", "at_kinematic_minimum", "minimum_time"]


#: Index of the distance rows in :data:`~adept_traj.problem.CONSTRAINT_KINDS`.
_DISTANCE = CONSTRAINT_KINDS.index("distance")


@dataclass(frozen=True)
class PolishOutcome:
    """One local solve.

    Attributes
    ----------
    x:
        (n_var,) the polished decision vector (T raised to its kinematic minimum if needed).
    objectives, constraints:
        (6,) z1…z6 and (n_constr,) constraints of ``x`` by the problem's evaluator.
    feasible:
        True when every evaluator constraint of ``x`` is ≤ 0 (not yet a certificate).
    start:
        (n_var,) the start vector.
    n_iterations:
        SLSQP iterations.
    n_evaluations:
        Constraint-and-Jacobian evaluations of the solver plus the final evaluation.
    seconds:
        Wall time [s] of the solve.
    evaluation_s:
        The part of ``seconds`` spent evaluating constraints, Jacobians and the result [s].
    message:
        SLSQP's exit message.
    """

    x: np.ndarray
    objectives: np.ndarray
    constraints: np.ndarray
    feasible: bool
    start: np.ndarray
    n_iterations: int
    n_evaluations: int
    seconds: float
    evaluation_s: float
    message: str


def minimum_time(
    problem: Any, x0: Any, *, max_iter: int = 100, tol: float = 1e-10, buffer: float = 0.0
) -> PolishOutcome:
    """The fastest move near ``x0`` (n_var,) subject to every constraint (see the module
    docstring).

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    x0:
        (n_var,) start ``[T [s], free control points [rad | m]]``, inside the bounds.
    max_iter:
        Most SLSQP iterations (≥ 1).
    tol:
        SLSQP's ``ftol`` on the travel time [s] (> 0).
    buffer:
        Distance [m] (≥ 0) the solve adds to the problem's margin and search buffer in its
        distance rows (the final evaluation uses the problem's own): room for the corners
        a fast move cuts between the samples.

    When SLSQP ends outside the constraints (from a detour its iterates may cross an
    obstacle and stop there), the fastest point it visited inside every per-sample
    constraint is returned instead, evaluated (the start when it was inside).
    """
    x0 = as_vector(x0, "x0", problem.n_var)
    max_iter = as_integer(max_iter, "max_iter", minimum=1, error=ConfigurationError)
    tol = as_scalar(tol, "tol", minimum=0.0, error=ConfigurationError)
    buffer = as_scalar(buffer, "buffer", "m", minimum=0.0, error=ConfigurationError)
    if tol <= 0.0:
        raise ConfigurationError(f"tol must be > 0 [s]; got {tol}")
    if np.any(x0 < problem.xl) or np.any(x0 > problem.xu):
        raise ConfigurationError("x0 must lie inside the decision bounds (problem.xl, problem.xu)")
    import scipy.optimize  # noqa: F401  (lazy; loaded first: its BLAS is limited too)
    from threadpoolctl import threadpool_limits  # lazy, as scipy.optimize

    # One BLAS thread: a multi-threaded BLAS sums in an order that depends on its thread
    # count, and SLSQP amplifies the last-bit differences (a move polished in a Dask worker,
    # single-threaded, differed from the same move polished here at 1e-13 s).
    with threadpool_limits(limits=1, user_api="blas"):
        return _minimum_time(problem, x0, max_iter, tol, buffer)


def _minimum_time(
    problem: Any, x0: np.ndarray, max_iter: int, tol: float, buffer: float
) -> PolishOutcome:
    from scipy.optimize import minimize  # lazy: scipy.optimize is heavy

    started = time.perf_counter()
    cache: dict[bytes, Any] = {}

    def constraints(x: np.ndarray) -> Any:
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            tic = time.perf_counter()
            xc = np.clip(x, problem.xl, problem.xu)
            lc = local_constraints(problem, xc)
            cache[key] = (lc.values[0] + extra * (lc.kind == _DISTANCE), lc.jacobian[0])
            counter[0] += 1
            spent[0] += time.perf_counter() - tic
            if np.all(lc.values[0] <= 0.0) and (safe[0] is None or xc[0] < safe[0][0]):
                safe[0] = xc  # the fastest point found within the problem's constraints
        return cache[key]

    counter, spent, safe = [0], [0.0], [None]
    extra = buffer / problem.settings.influence  # distance rows are scaled by influence
    grad = np.zeros(problem.n_var)
    grad[0] = 1.0
    res = minimize(
        lambda x: x[0],
        x0,
        jac=lambda x: grad,
        method="SLSQP",
        bounds=list(zip(problem.xl, problem.xu)),
        constraints=[
            {
                "type": "ineq",  # scipy: fun(x) ≥ 0
                "fun": lambda x: -constraints(x)[0],
                "jac": lambda x: -constraints(x)[1],
            }
        ],
        options={"maxiter": max_iter, "ftol": tol},
    )
    x, ev = _evaluated(problem, res.x)
    spent[0] += ev.seconds
    if np.any(ev.constraints > 0.0) and safe[0] is not None:
        # SLSQP ended outside (from a detour its iterates cross an obstacle and stop there):
        # the fastest point it visited inside every per-sample constraint instead.
        x, ev = _evaluated(problem, safe[0])
        counter[0] += 1
        spent[0] += ev.seconds
    return PolishOutcome(
        x=x,
        objectives=ev.objectives,
        constraints=ev.constraints,
        feasible=bool(np.all(ev.constraints <= 0.0)),
        start=x0.copy(),
        n_iterations=int(res.nit),
        n_evaluations=counter[0] + 1,
        seconds=time.perf_counter() - started,
        evaluation_s=spent[0],
        message=str(res.message),
    )


def at_kinematic_minimum(problem: Any, x: np.ndarray) -> np.ndarray:
    """(n_var,) a new copy of ``x`` (n_var,) clipped to the bounds, its T [s] raised to the
    spline's exact kinematic minimum (:func:`~adept_traj.optimise.kinematic_time`, with a
    relative slack of 1e-9) where a solver's samples missed a peak, and kept ≤ the upper
    bound."""
    x = np.clip(x, problem.xl, problem.xu)
    t_kin = kinematic_time(problem, x[None])[0] * (1.0 + KINEMATIC_SLACK)
    x[0] = min(max(x[0], t_kin), problem.xu[0])
    return x


def _evaluated(problem: Any, x: np.ndarray) -> tuple[np.ndarray, Any]:
    """:func:`at_kinematic_minimum` of ``x`` and its evaluation by the problem."""
    x = at_kinematic_minimum(problem, x)
    return x, problem.evaluate_batch(x)
