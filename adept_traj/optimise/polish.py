r"""Gradient-based polishing: the fastest move near a given one (SLSQP).

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
feasibility.

:func:`time_optimal` runs :func:`minimum_time` from several starts — the straight move and
the ``n_starts − 1`` kinematically fastest of 8 × (``n_starts`` − 1) ramps of
:class:`~adept_traj.optimise.RampSampling` drawn from a generator seeded by ``seed``, each
at its kinematic minimum T — and returns every outcome. When none of them ends feasible
(the straight move blocked, as on the detour scene), it adds the outcomes of detour
starts: the fastest evaluator-feasible of batches of seeded ramps, solved with extra
distance buffers until the move passes its certificate (``docs/engine.md``). Everything
is deterministic: the same problem and seed give the same vectors.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.refinement import Refinement, refine_minimum_time
from adept_traj.optimise.repair import kinematic_time
from adept_traj.optimise.sampling import RampSampling
from adept_traj.optimise.via_points import near_lower_bound, via_point_starts
from adept_traj.problem import CONSTRAINT_KINDS, local_constraints
from adept_traj.validation import as_integer, as_scalar, as_vector

__all__ = ["PolishOutcome", "minimum_time", "time_optimal"]

#: Relative slack on the kinematic minimum (as in :mod:`adept_traj.optimise.repair`).
_SLACK = 1e-9

#: Ramps drawn per ramp start of :func:`time_optimal` (the fastest ones are used).
_RAMPS_PER_START = 8

#: Index of the distance rows in :data:`~adept_traj.problem.CONSTRAINT_KINDS`.
_DISTANCE = CONSTRAINT_KINDS.index("distance")

#: Detour starts of :func:`time_optimal`: ramps drawn, and the multiples of each ramp's
#: kinematic minimum T at which they are evaluated (one batch of 2 000 moves, ≈ 1.5 s; on
#: the detour scene, of 400 ramps × (1, 1.25, 1.5, 2, 2.5) only ramps at 1 × were feasible).
_DETOUR_RAMPS = 2000
_DETOUR_SPEEDS = (1.0,)
#: Most batches of detour ramps drawn (a feasible ramp is rare: 0–3 in 2 000 there).
_DETOUR_BATCHES = 3


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


def time_optimal(
    problem: Any, seed: int = 1, n_starts: int = 4, *, rate_hz: float = 1000.0, **options: Any
) -> list[Refinement]:
    """:func:`~adept_traj.optimise.refine_minimum_time` from the straight move and the
    ``n_starts − 1`` kinematically fastest of ``8 (n_starts − 1)`` seeded ramps (each at
    its kinematic minimum T); one refinement per start, in start order. When no
    refinement ends **certified** within
    :data:`~adept_traj.optimise.GLOBAL_GAP` of the kinematic lower bound, followed by the
    refinements of the global stage's starts (:func:`~adept_traj.optimise.via_point_starts`)
    and of at most ``n_starts`` detour ramps (the fastest evaluator-feasible ones).

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    seed:
        Seed of the ramps' and the via points' generators (≥ 0).
    n_starts:
        Number of starts (≥ 1).
    rate_hz:
        Rate [Hz] of the certificates (> 0).
    options:
        ``max_boxes``, ``max_rounds`` of :func:`~adept_traj.optimise.refine_minimum_time`.
    """
    seed = as_integer(seed, "seed", minimum=0, error=ConfigurationError)
    n_starts = as_integer(n_starts, "n_starts", minimum=1, error=ConfigurationError)
    refine = functools.partial(refine_minimum_time, problem, rate_hz=rate_hz, **options)
    starts = _starts(problem, seed, n_starts)
    outcomes = [refine(x) for x in _feasible_first(problem, starts)]
    if near_lower_bound(problem, outcomes):
        return outcomes
    more = [via_point_starts(problem, seed, n_starts=n_starts)]
    more.append(_detour_starts(problem, seed, n_starts))
    return outcomes + [refine(x) for x in _feasible_first(problem, np.concatenate(more))]


def _feasible_first(problem: Any, starts: np.ndarray) -> np.ndarray:
    """``starts`` (k, n_var) with the evaluator-feasible ones first (each group in its
    order): a refinement from inside the constraints is cheap and seldom fails."""
    ok = np.all(problem.evaluate_batch(starts).constraints <= 0.0, axis=1) if len(starts) else []
    return np.concatenate([starts[ok], starts[~np.asarray(ok, dtype=bool)]])


def _detour_starts(problem: Any, seed: int, n_starts: int) -> np.ndarray:
    """(k, n_var), k ≤ ``n_starts``: the fastest feasible moves, one per ramp, among
    batches of :data:`_DETOUR_RAMPS` seeded ramps each at :data:`_DETOUR_SPEEDS` × its
    kinematic minimum T (one batched evaluation by the problem each), fastest first; up to
    :data:`_DETOUR_BATCHES` batches, until one holds a feasible move (k = 0: none did)."""
    speeds = np.asarray(_DETOUR_SPEEDS)
    for batch in range(_DETOUR_BATCHES):
        rng = np.random.default_rng([seed, 1 + batch])  # not the ramps of _starts
        ramps = RampSampling().ramps(problem, _DETOUR_RAMPS, rng)
        x = np.repeat(ramps, len(speeds), axis=0)
        t = np.repeat(kinematic_time(problem, ramps), len(speeds)) * np.tile(speeds, len(ramps))
        x[:, 0] = np.clip(t * (1.0 + _SLACK), problem.xl[0], problem.xu[0])
        ok = np.all(problem.evaluate_batch(x).constraints <= 0.0, axis=1).reshape(len(ramps), -1)
        rows = np.flatnonzero(ok.any(axis=1))
        if len(rows):
            rows = rows * len(speeds) + np.argmax(ok[rows], axis=1)  # each ramp's fastest
            return x[rows[np.argsort(x[rows, 0], kind="stable")][:n_starts]]
    return np.empty((0, problem.n_var))


def _starts(problem: Any, seed: int, n_starts: int) -> np.ndarray:
    """(n_starts, n_var): the straight move, then the ``n_starts − 1`` ramps of smallest
    kinematic minimum T among ``_RAMPS_PER_START`` × as many seeded ramps, each at its
    kinematic minimum T (SLSQP from a slow detour rarely converges in a few dozen
    iterations; measured on the paper scene: every ramp start with T_kin ≤ 1.4 s reached
    the optimum, none above 1.8 s)."""
    traj = problem.trajectory
    straight = traj.straight_line(problem.xl[0])[None]
    n_ramps = _RAMPS_PER_START * (n_starts - 1)
    ramps = RampSampling().ramps(problem, n_ramps, np.random.default_rng(seed))
    x = np.concatenate([straight, ramps])
    t_kin = kinematic_time(problem, x)
    order = np.concatenate([[0], 1 + np.argsort(t_kin[1:], kind="stable")])[:n_starts]
    x, t_kin = x[order], t_kin[order]
    x[:, 0] = np.clip(t_kin * (1.0 + _SLACK), problem.xl[0], problem.xu[0])
    return x


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


def _evaluated(problem: Any, x: np.ndarray) -> tuple[np.ndarray, Any]:
    """``x`` (n_var,) clipped to the bounds with T raised to its kinematic minimum, and its
    evaluation by the problem."""
    x = np.clip(x, problem.xl, problem.xu)
    t_kin = kinematic_time(problem, x[None])[0] * (1.0 + _SLACK)
    x[0] = min(max(x[0], t_kin), problem.xu[0])
    return x, problem.evaluate_batch(x)
