"""adept_traj.optimise.local.sqp, the trust boxes' SQP: a closed-form optimum (a linear cost on
a ball), scipy's SLSQP (an independent implementation of the same method) on a random
smooth problem, bounds honoured, infeasible subproblems and iteration limits reported,
determinism, and the subproblems' warm start (each step that of a cold solve; a failing
warm solve solved again cold)."""

from __future__ import annotations

import daqp
import numpy as np
import pytest
from scipy.optimize import minimize

from adept_traj.errors import ConfigurationError, InputShapeError
from adept_traj.optimise.local.sqp import sqp


def _ball(center: np.ndarray, radius: float):
    """The row ‖y − center‖² − radius² ≤ 0 and its gradient."""

    def rows(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        r = y - center
        return np.array([r @ r - radius**2]), 2.0 * r[None]

    return rows


def test_a_linear_cost_on_a_ball_ends_at_the_closed_form_optimum() -> None:
    """min c·y on ‖y − a‖ ≤ r: y* = a − r c / ‖c‖."""
    c = np.array([1.0, -2.0, 0.5])
    a = np.array([0.3, 0.1, -0.2])
    res = sqp(c, a, np.full(3, -np.inf), np.full(3, np.inf), _ball(a, 0.7), max_iter=50)
    assert res.converged
    np.testing.assert_allclose(res.x, a - 0.7 * c / np.linalg.norm(c), atol=1e-6)


def test_bounds_are_honoured_at_every_trial_point() -> None:
    """The optimum on the ball is cut by a bound: every trial point lies in the bounds,
    and the end is the optimum of the cut problem (y0 at its bound)."""
    seen: list[np.ndarray] = []
    inner = _ball(np.zeros(2), 1.0)

    def rows(y):
        seen.append(y.copy())
        return inner(y)

    lower, upper = np.array([-0.5, -2.0]), np.array([2.0, 2.0])
    res = sqp(np.array([1.0, 0.0]), np.zeros(2), lower, upper, rows, max_iter=50)
    assert res.converged
    assert all(np.all(y >= lower) and np.all(y <= upper) for y in seen)
    assert res.x[0] == pytest.approx(-0.5, abs=1e-8)


def test_agrees_with_scipy_slsqp_on_random_smooth_rows() -> None:
    """Quadratic rows g_i(y) = ½ yᵀQ_i y + b_iᵀy − 1 ≤ 0 (Q_i positive definite: a convex
    problem, one optimum), linear cost: the same optimum as scipy's SLSQP."""
    rng = np.random.default_rng(3)
    n, m = 6, 12
    Q = [(lambda M: M @ M.T + np.eye(n))(rng.normal(size=(n, n))) for _ in range(m)]
    b = rng.normal(size=(m, n))
    c = rng.normal(size=n)

    def rows(y):
        g = np.array([0.5 * y @ Qi @ y for Qi in Q]) + b @ y - 1.0
        return g, np.array([Qi @ y for Qi in Q]) + b

    lo, hi = np.full(n, -5.0), np.full(n, 5.0)
    ours = sqp(c, np.zeros(n), lo, hi, rows, max_iter=100)
    ref = minimize(
        lambda y: c @ y, np.zeros(n), jac=lambda y: c, method="SLSQP", bounds=list(zip(lo, hi)),
        constraints=[{"type": "ineq", "fun": lambda y: -rows(y)[0], "jac": lambda y: -rows(y)[1]}],
        options={"maxiter": 200, "ftol": 1e-12},
    )  # fmt: skip
    assert ours.converged
    assert ref.success
    assert np.max(rows(ours.x)[0]) <= 1e-8
    np.testing.assert_allclose(ours.x, ref.x, atol=1e-5)
    again = sqp(c, np.zeros(n), lo, hi, rows, max_iter=100)
    np.testing.assert_array_equal(ours.x, again.x)  # deterministic


def test_an_infeasible_subproblem_and_the_iteration_limit_are_reported() -> None:
    """Rows that no point inside the bounds meets: not converged, the start kept; one
    iteration from far away: not converged."""
    far = _ball(np.array([10.0, 0.0]), 1.0)
    res = sqp(np.ones(2), np.zeros(2), -np.ones(2), np.ones(2), far, max_iter=20)
    assert not res.converged
    np.testing.assert_array_equal(res.x, np.zeros(2))
    one = sqp(np.ones(2), np.zeros(2), np.full(2, -np.inf), np.full(2, np.inf),
              _ball(np.array([3.0, 3.0]), 1.0), max_iter=1)  # fmt: skip
    assert not one.converged
    assert one.nit == 1


def test_bad_input_is_refused_before_any_row_is_evaluated() -> None:
    """Shapes that disagree, max_iter < 1 and tol ≤ 0: the library's errors, naming the
    value, before ``rows`` is called."""
    calls: list[int] = []

    def rows(y):
        calls.append(1)
        return np.zeros(1), np.zeros((1, len(y)))

    free = np.full(2, np.inf)
    with pytest.raises(InputShapeError, match="one shape"):
        sqp(np.ones(2), np.zeros(3), -free, free, rows, max_iter=5)
    with pytest.raises(ConfigurationError, match="max_iter"):
        sqp(np.ones(2), np.zeros(2), -free, free, rows, max_iter=0)
    with pytest.raises(ConfigurationError, match="tol"):
        sqp(np.ones(2), np.zeros(2), -free, free, rows, max_iter=5, tol=0.0)
    assert calls == []


def _random_rows(seed: int, n: int = 6, m: int = 40):
    """Convex quadratic rows ½ yᵀQ_i y + b_iᵀy − 1 ≤ 0 and a linear cost (as above, more
    rows: several active at the optimum)."""
    rng = np.random.default_rng(seed)
    Q = [(lambda M: M @ M.T + np.eye(n))(rng.normal(size=(n, n))) for _ in range(m)]
    b = rng.normal(size=(m, n))

    def rows(y):
        g = np.array([0.5 * y @ Qi @ y for Qi in Q]) + b @ y - 1.0
        return g, np.array([Qi @ y for Qi in Q]) + b

    return rng.normal(size=n), rows


def test_each_warm_started_subproblem_has_the_step_of_a_cold_solve(monkeypatch) -> None:
    """Every DAQP call after the first of a run starts from an active set (sense flags);
    the step it returns is the one DAQP gives the same QP from no active set (the QP is
    strictly convex: one answer), and the run ends where scipy's SLSQP does."""
    c, rows = _random_rows(5)
    calls: list[tuple] = []
    solve = daqp.solve

    def recording(H, f, A, bupper, blower, sense, **kw):
        out = solve(H, f, A, bupper, blower, sense, **kw)
        calls.append((H.copy(), f.copy(), A.copy(), bupper.copy(), blower.copy(),
                      sense.copy(), kw, out[0].copy(), out[2]))  # fmt: skip
        return out

    monkeypatch.setattr(daqp, "solve", recording)
    lo, hi = np.full(6, -5.0), np.full(6, 5.0)
    res = sqp(c, np.zeros(6), lo, hi, rows, max_iter=100)
    monkeypatch.undo()
    assert res.converged
    assert len(calls) >= 3
    assert not calls[0][5].any()  # the first from no active set
    assert all(call[5].any() for call in calls[1:])  # the others warm
    for H, f, A, bu, bl, sense, kw, d, flag in calls:
        assert flag >= 1
        cold = solve(H, f, A, bu, bl, np.zeros_like(sense), **kw)
        assert cold[2] >= 1
        np.testing.assert_allclose(d, cold[0], rtol=1e-7, atol=1e-10)
    ref = minimize(
        lambda y: c @ y, np.zeros(6), jac=lambda y: c, method="SLSQP", bounds=list(zip(lo, hi)),
        constraints=[{"type": "ineq", "fun": lambda y: -rows(y)[0], "jac": lambda y: -rows(y)[1]}],
        options={"maxiter": 200, "ftol": 1e-12},
    )  # fmt: skip
    assert ref.success
    np.testing.assert_allclose(res.x, ref.x, atol=1e-5)


def test_a_failing_warm_solve_is_solved_again_cold(monkeypatch) -> None:
    """DAQP made to fail every warm-started call: each subproblem is solved again from no
    active set, and the run ends at the same point as one that never warm-starts."""
    c, rows = _random_rows(7)
    solve = daqp.solve
    lo, hi = np.full(6, -5.0), np.full(6, 5.0)
    warm_calls = []

    def cold_only(H, f, A, bupper, blower, sense, **kw):
        return solve(H, f, A, bupper, blower, np.zeros_like(sense), **kw)

    monkeypatch.setattr(daqp, "solve", cold_only)
    never_warm = sqp(c, np.zeros(6), lo, hi, rows, max_iter=100)

    def failing_warm(H, f, A, bupper, blower, sense, **kw):
        if sense.any():
            warm_calls.append(1)
            return np.zeros(len(f)), 0.0, -1, {"lam": np.zeros(len(bupper))}
        return solve(H, f, A, bupper, blower, sense, **kw)

    monkeypatch.setattr(daqp, "solve", failing_warm)
    res = sqp(c, np.zeros(6), lo, hi, rows, max_iter=100)
    assert warm_calls  # the warm start was tried
    assert res.converged
    assert never_warm.converged
    np.testing.assert_array_equal(res.x, never_warm.x)
