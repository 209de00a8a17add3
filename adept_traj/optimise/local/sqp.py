r"""A dense SQP for a linear cost under smooth inequality rows and bounds: the solver of
each trust box of :mod:`adept_traj.optimise.local.trust_box`.

It solves

.. math::
    \min_y \; c^\top y \quad \text{s.t.} \quad h(y) \le 0, \quad l \le y \le u

with the method of Kraft's SLSQP (the solver scipy's ``SLSQP`` wraps): at each iterate
:math:`y_k` the quadratic subproblem

.. math::
    \min_d \; \tfrac12 d^\top B_k d + c^\top d \quad \text{s.t.} \quad
    h(y_k) + J(y_k)\, d \le 0, \quad l - y_k \le d \le u - y_k,

a line search on the :math:`\ell_1` merit function
:math:`\phi(y) = c^\top y + \rho^\top \max(h(y), 0)` (one penalty per row,
:math:`\rho_i \leftarrow \max(\tfrac12(\rho_i + \lambda_i), \lambda_i)`), and a
Powell-damped BFGS update of :math:`B` (the Hessian of the Lagrangian: the rows'
curvature, the cost having none). The subproblem is solved by DAQP (a dual active-set QP
solver for dense problems, ``daqp`` on PyPI): with the hundreds to thousands of rows of a
trajectory's samples and a few dozen variables its solve costs a small fraction of
SLSQP's least-squares subproblem (``docs/engine.md``). Each subproblem after the first
starts from the active set of the one before (DAQP's warm start: the rows and bounds
whose multipliers were not zero), which the iterates seldom change; a warm solve that
fails is solved again cold, so the warm start changes how fast a step is found, never
whether one is. The caller's ``rows`` function is
called once per trial point; it may record points (the trust box keeps the fastest point
met inside every row).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError, InputShapeError
from adept_traj.validation import as_finite_array, as_integer, as_scalar

__all__ = ["Rows", "SqpResult", "sqp"]

#: ``y ↦ (h (m,), J (m, n))``: the rows at a point and their Jacobian.
Rows = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]

#: Armijo factor of the line search, its most trials per iteration and the smallest
#: step fraction it takes (Kraft's values).
_ARMIJO, _LINE_TRIALS, _MIN_STEP = 0.1, 10, 0.1

#: Powell's damping threshold of the BFGS update.
_DAMPING = 0.2

#: DAQP's primal feasibility tolerance on the linearised rows (its default, 1e-6, leaves
#: answers outside the rows by more than the trust box's test of a point inside, 1e-8).
_PRIMAL_TOL = 1e-12

#: An infinite bound for DAQP.
_INF = 1e30


@dataclass(frozen=True)
class SqpResult:
    """The end of :func:`sqp`.

    Attributes
    ----------
    x:
        (n,) the last iterate (inside the bounds).
    nit:
        Iterations done.
    converged:
        True when the first-order test met ``tol``; False at the iteration limit, a failed
        line search or an infeasible subproblem.
    """

    x: np.ndarray
    nit: int
    converged: bool


def sqp(
    cost: np.ndarray,
    y0: np.ndarray,
    lower: np.ndarray,
    upper: np.ndarray,
    rows: Rows,
    *,
    max_iter: int,
    tol: float = 1e-10,
) -> SqpResult:
    """Minimise ``cost @ y`` subject to ``rows(y)[0] <= 0`` and the bounds (module
    docstring).

    Parameters
    ----------
    cost:
        (n,) the linear cost c.
    y0:
        (n,) the start (clipped into the bounds).
    lower, upper:
        (n,) the bounds (``±inf`` allowed).
    rows:
        ``y ↦ (h (m,), J (m, n))``: the rows and their Jacobian.
    max_iter:
        Most iterations (≥ 1).
    tol:
        Tolerance of the first-order test on the cost's change and the rows' violation
        (> 0).

    Raises
    ------
    InputShapeError
        ``cost`` not a vector (n,), or ``y0``, ``lower`` or ``upper`` of another shape.
    ConfigurationError
        ``max_iter`` < 1 or ``tol`` ≤ 0.

    Notes
    -----
    Runs with one BLAS thread (as :func:`~adept_traj.optimise.local.minimum_time.minimum_time`): a
    multi-threaded BLAS sums in an order that depends on its thread count, and the
    iterates amplify the last-bit differences — the same start would end elsewhere in a
    worker process than in the main one.
    """
    c = as_finite_array(cost, "cost")
    n = len(c) if c.ndim == 1 else -1
    shapes = {"y0": np.shape(y0), "lower": np.shape(lower), "upper": np.shape(upper)}
    if n < 1 or any(shape != (n,) for shape in shapes.values()):
        raise InputShapeError(
            f"cost, y0, lower and upper must have one shape (n,); got {c.shape} and {shapes}"
        )
    max_iter = as_integer(max_iter, "max_iter", minimum=1, error=ConfigurationError)
    tol = as_scalar(tol, "tol", minimum=0.0, strict=True, error=ConfigurationError)
    from threadpoolctl import threadpool_limits  # lazy, as the solver

    with threadpool_limits(limits=1, user_api="blas"):
        return _sqp(c, y0, (lower, upper), rows, max_iter, tol)


def _sqp(c: np.ndarray, y0: Any, bounds: tuple, rows: Rows, max_iter: int, tol: float) -> SqpResult:
    lo = np.where(np.isfinite(bounds[0]), bounds[0], -_INF)
    hi = np.where(np.isfinite(bounds[1]), bounds[1], _INF)
    y = np.clip(np.asarray(y0, dtype=float), lo, hi)
    h, J = rows(y)
    n, m = len(y), len(h)
    B = np.eye(n)
    rho = np.zeros(m)
    active = None  # the last subproblem's active set (DAQP's sense flags)
    for k in range(1, max_iter + 1):
        d, lam, active = _subproblem(B, c, J, h, lo - y, hi - y, active)
        if d is None:
            return SqpResult(y, k, False)
        violation = np.maximum(h, 0.0)
        if abs(c @ d) + lam @ np.abs(h) + violation.sum() < tol:
            return SqpResult(y, k, True)
        rho = np.maximum(0.5 * (rho + lam), lam)
        phi0 = c @ y + rho @ violation
        slope = c @ d - rho @ violation
        alpha = 1.0
        for _ in range(_LINE_TRIALS):
            yn = np.clip(y + alpha * d, lo, hi)
            hn, Jn = rows(yn)
            change = c @ yn + rho @ np.maximum(hn, 0.0) - phi0
            if change <= _ARMIJO * alpha * slope:
                break
            drop = slope * alpha - change  # < 0 along a descent direction
            alpha *= max(_MIN_STEP, 0.5 * slope * alpha / drop) if drop < 0.0 else _MIN_STEP
        else:
            return SqpResult(y, k, False)
        B = _bfgs(B, yn - y, (Jn - J).T @ lam)
        done = abs(c @ yn - c @ y) < tol and np.maximum(hn, 0.0).sum() < tol
        y, h, J = yn, hn, Jn
        if done:
            return SqpResult(y, k, True)
    return SqpResult(y, max_iter, False)


def _subproblem(
    B: np.ndarray,
    c: np.ndarray,
    J: np.ndarray,
    h: np.ndarray,
    dl: np.ndarray,
    du: np.ndarray,
    warm: np.ndarray | None = None,
) -> tuple[np.ndarray | None, np.ndarray, np.ndarray | None]:
    """The QP step d (``None``: infeasible or failed), the rows' multipliers λ ≥ 0 and
    the active set at the answer as DAQP's sense flags (n + m,) (``None`` on failure).

    ``warm``: the active set to start from (a previous answer's flags, same rows and
    bounds), else none; a warm solve that fails is solved again from no active set."""
    import daqp  # lazy: only the local solver needs it

    upper = np.concatenate([du, -h])
    lower = np.concatenate([dl, np.full(len(h), -_INF)])
    A = np.ascontiguousarray(J)
    for sense in (warm, None) if warm is not None and len(warm) == len(upper) else (None,):
        flags = np.zeros(len(upper), dtype=np.intc) if sense is None else sense
        d, _, flag, info = daqp.solve(B, c, A, upper, lower, flags, primal_tol=_PRIMAL_TOL)
        if flag >= 1:
            lam = np.asarray(info["lam"], dtype=float)
            return np.asarray(d, dtype=float), np.maximum(lam[len(c) :], 0.0), _active(lam)
    return None, np.zeros(len(h)), None


def _active(lam: np.ndarray) -> np.ndarray:
    """DAQP's sense flags of the constraints active at an answer with multipliers ``lam``
    (n + m,): ``ACTIVE`` (1) where λ ≠ 0, with ``LOWER`` (2) where λ < 0 (the lower
    bound)."""
    return np.where(lam > 0.0, 1, np.where(lam < 0.0, 3, 0)).astype(np.intc)


def _bfgs(B: np.ndarray, s: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Powell-damped BFGS update of ``B`` with step ``s`` and gradient change ``v``."""
    Bs = B @ s
    sBs = s @ Bs
    if sBs <= 0.0:
        return B
    sv = s @ v
    if sv < _DAMPING * sBs:
        theta = (1.0 - _DAMPING) * sBs / (sBs - sv)
        v = theta * v + (1.0 - theta) * Bs
        sv = s @ v
    return B + np.outer(v, v) / sv - np.outer(Bs, Bs) / sBs
