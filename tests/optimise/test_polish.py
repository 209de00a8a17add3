"""Smooth per-sample constraints, their Jacobians, and the SLSQP minimum-time polish."""

from __future__ import annotations

import numpy as np
import pytest

from adept_traj import Scene, TrajectoryProblem, plan
from adept_traj.certification import certify
from adept_traj.errors import ConfigurationError, InputShapeError
from adept_traj.optimise import (
    RampSampling,
    minimum_time,
    near_lower_bound,
    screen_starts,
    time_optimal,
)
from adept_traj.problem import CONSTRAINT_KINDS, local_constraints
from adept_traj.testing.paper_moves import lift_then_lower

#: Drake's KinematicTrajectoryOptimization (SNOPT) on the paper scene (issue #12) [s].
DRAKE_T = 1.0766


@pytest.fixture(scope="module")
def ramps(problem: TrajectoryProblem) -> np.ndarray:
    """Two seeded ramps (random shapes and times)."""
    return RampSampling().ramps(problem, 2, np.random.default_rng(3))


def test_jacobian_matches_central_differences(problem, ramps) -> None:
    """Every row's gradient against central differences of the values through x, on T and
    a fixed random choice of control-point columns (a collision-free move that comes
    within the influence distance of an obstacle, so distance rows have gradients)."""
    x = lift_then_lower(problem)
    lc = local_constraints(problem, x)
    rng = np.random.default_rng(7)
    columns = np.concatenate([[0], rng.choice(np.arange(1, problem.n_var), 8, replace=False)])
    h = 1e-6
    smp = problem.trajectory.sample(x, problem.s, orders=(1,))
    # A joint at rest switches its Coulomb friction: no derivative there (torque rows only).
    torque_ok = np.tile((np.abs(smp.qd) > 1e-3).ravel(), 2)  # rows: (±, sample, joint)
    keep = lc.kind != CONSTRAINT_KINDS.index("torque")
    keep[lc.kind == CONSTRAINT_KINDS.index("torque")] = torque_ok
    assert torque_ok.mean() > 0.5
    distance = lc.kind == CONSTRAINT_KINDS.index("distance")
    assert np.any(lc.jacobian[0, distance] != 0.0)
    for c in columns:
        e = np.zeros(problem.n_var)
        e[c] = h
        fd = (
            local_constraints(problem, x + e).values[0]
            - local_constraints(problem, x - e).values[0]
        ) / (2 * h)
        error = np.abs(fd - lc.jacobian[0, :, c]) / (1.0 + np.abs(fd))
        np.testing.assert_array_less(error[keep & ~distance], 1e-6)
        # The distance rows' reference is noisier: the checker's distances have GJK's
        # 1e-9 m tolerance, ~1e-9 / h after the difference (the gradient's own witness
        # points use 1e-14, tests/collision/test_distance_gradient.py checks it more closely).
        np.testing.assert_array_less(error[distance], 1e-4)


def test_row_maxima_are_the_evaluators_constraints(problem, ramps) -> None:
    """Acceleration (at the knots), jerk (per segment), torque and distance (at the
    problem's samples): the largest row of a kind and joint is the evaluator's constraint;
    velocity rows never exceed it (samples of a quadratic)."""
    lc = local_constraints(problem, ramps)
    ev = problem.evaluate_batch(ramps)
    nq = problem.robot.nq
    for kind, first in (("acceleration", 2), ("jerk", 3), ("torque", 4)):
        rows = lc.values[:, lc.kind == CONSTRAINT_KINDS.index(kind)]
        per_joint = rows.reshape(len(ramps), 2, -1, nq).max(axis=(1, 2))
        np.testing.assert_allclose(
            per_joint, ev.constraints[:, first * nq : (first + 1) * nq], rtol=1e-12, atol=1e-12
        )
    velocity = lc.values[:, lc.kind == 0].reshape(len(ramps), 2, -1, nq).max(axis=(1, 2))
    exact = ev.constraints[:, nq : 2 * nq]
    assert np.all(velocity <= exact + 1e-12)
    assert np.all(velocity >= exact - 0.01)
    distance = lc.values[:, lc.kind == CONSTRAINT_KINDS.index("distance")].max(axis=1)
    np.testing.assert_allclose(distance, ev.constraints[:, -1], rtol=0, atol=1e-12)


def test_bad_input_is_refused(problem) -> None:
    with pytest.raises(InputShapeError):
        local_constraints(problem, np.zeros(3))
    with pytest.raises(ConfigurationError, match="points_per_segment"):
        local_constraints(problem, problem.xl, points_per_segment=0)
    with pytest.raises(ConfigurationError, match="inside the decision bounds"):
        minimum_time(problem, problem.xu + 1.0)
    with pytest.raises(ConfigurationError, match="n_starts and max_iter"):
        plan(problem, "time-optimal", pop_size_typo=3)
    with pytest.raises(ConfigurationError, match="n_starts"):
        plan(problem, "time-optimal", n_starts=0)


def test_minimum_time_from_the_straight_move_reaches_drakes_optimum(problem) -> None:
    """From the straight move, SLSQP reaches Drake's T (within 0.1 %), at ≥ the kinematic
    lower bound, and the move passes the 1 kHz certificate with the continuous guarantee;
    the same start gives the same vector, and the T the central-difference derivatives
    gave before the analytic ones (1.0765924346 s) to 1e-7 s (the elastic first solve from
    outside the rows, issue #24, ends 4e-8 s above it)."""
    first = time_optimal(problem, seed=1, n_starts=1)[0]
    again = time_optimal(problem, seed=1, n_starts=1)[0]
    np.testing.assert_array_equal(first.x, again.x)
    assert first.feasible
    assert problem.lower_bound.T_min <= first.x[0] <= 1.001 * DRAKE_T
    assert first.x[0] == pytest.approx(1.0765924346, abs=1e-7)
    assert certify(problem, first.x, rate_hz=1000.0).certified


@pytest.fixture(scope="module")
def small_runs(problem: TrajectoryProblem):
    """The same small NSGA-II run without and with the polish of the fastest member."""
    options = {"seed": 1, "pop_size": 16, "n_gen": 4}
    return plan(problem, "nsga2", polish=False, **options), plan(
        problem, "nsga2", polish="fastest", **options
    )


def test_plan_polishes_the_fastest_feasible_member(problem, small_runs) -> None:
    """The polished run's front holds the certified refinement of the unpolished run's
    fastest feasible member (same seed: same population; its basin is the fastest, and its
    screening — one round of the certified solver — reaches the kinematic bound to 1 %, so
    no other basin is screened and nothing is refined further), faster than every
    unpolished member; its evaluations are the run's plus the screening's."""
    raw, polished = small_runs
    ok = np.flatnonzero(np.all(raw.front.constraints <= 0.0, axis=1))
    start = raw.front.x[ok[np.argmin(raw.front.x[ok, 0])]]
    expected = screen_starts(problem, start[None])[0]
    assert near_lower_bound(problem, [expected])  # the only basin refined (paper scene)
    rows = np.flatnonzero(np.all(polished.front.x == expected.x, axis=1))
    assert len(rows) == 1
    assert polished.front.feasible[rows[0]]
    assert expected.x[0] < raw.front.x[:, 0].min()
    assert expected.x[0] == polished.front.x[:, 0].min()
    assert polished.timing.n_evaluations == raw.timing.n_evaluations + expected.n_evaluations
    assert polished.algorithm_settings["polish"] == "fastest"
    assert raw.algorithm_settings["polish"] == "off"


@pytest.fixture(scope="module")
def time_optimal_result(problem: TrajectoryProblem):
    return plan(problem, "time-optimal", seed=1, n_starts=2)


def test_time_optimal_mode_gives_a_certified_result(time_optimal_result) -> None:
    result = time_optimal_result
    assert result.algorithm == "time-optimal"
    assert result.feasible
    assert result.front.n_certified == len(result.front.x)
    assert result.front.x[:, 0].min() <= 1.001 * DRAKE_T
    assert result.timing.n_generations == 0


def test_a_scene_without_obstacles_has_no_distance_rows(problem) -> None:
    """No obstacle: no distance row, the other rows as with obstacles, and the polish runs
    (the Jacobian's reshape failed on the empty distance block)."""
    empty = TrajectoryProblem(problem.robot, Scene(()), problem.start, problem.goal)
    x = lift_then_lower(problem)[None]
    lc = local_constraints(empty, x)
    assert not np.any(lc.kind == CONSTRAINT_KINDS.index("distance"))
    with_obstacles = local_constraints(problem, x)
    keep = with_obstacles.kind != CONSTRAINT_KINDS.index("distance")
    np.testing.assert_array_equal(lc.values, with_obstacles.values[:, keep])
    np.testing.assert_array_equal(lc.jacobian, with_obstacles.jacobian[:, keep])
    outcome = minimum_time(empty, x[0], max_iter=5)
    assert outcome.x[0] < x[0, 0]


def test_minimum_time_keeps_the_fastest_point_inside_when_slsqp_ends_outside(problem) -> None:
    """One SLSQP iteration from a feasible detour ends outside the constraints: the
    fastest visited point inside them is returned (here the start), evaluated."""
    x0 = lift_then_lower(problem)
    assert np.all(problem.evaluate_batch(x0).constraints <= 0.0)
    out = minimum_time(problem, x0, max_iter=1)
    assert out.feasible
    assert out.x[0] <= x0[0]
    assert np.all(problem.evaluate_batch(out.x).constraints <= 0.0)


def test_minimum_time_buffer_keeps_the_samples_farther(problem) -> None:
    """With ``buffer`` b every sample of the answer clears margin + search buffer + b (the
    distance rows of local_constraints, scaled by the influence distance); b < 0 refused."""
    x0 = problem.trajectory.straight_line(problem.xl[0])
    b = 0.003
    out = minimum_time(problem, x0, max_iter=30, buffer=b)
    assert out.feasible
    lc = local_constraints(problem, out.x)
    rows = lc.kind == CONSTRAINT_KINDS.index("distance")
    assert np.all(lc.values[0, rows] <= -b / problem.settings.influence + 1e-6)
    plain = minimum_time(problem, x0, max_iter=30)
    assert np.any(
        local_constraints(problem, plain.x).values[0, rows] > -b / problem.settings.influence
    )
    with pytest.raises(ConfigurationError, match="buffer"):
        minimum_time(problem, x0, buffer=-0.001)


@pytest.mark.parametrize(("seconds", "evaluating"), [(0.02, 0.01), (1.0, 0.8)])
def test_time_optimal_run_never_counts_more_evaluation_than_wall_time(
    problem, monkeypatch, seconds, evaluating
) -> None:
    """Two refinements of ``seconds`` [s] each, ``evaluating`` [s] of it spent evaluating:
    one after the other (0.02 s each inside a 0.05 s run) their evaluation times add up;
    at once on worker processes (1 s each inside the same run) their sum exceeds the run's
    wall time — ``plan`` then refused the result (the optimiser overhead; seen on the
    loaded machine, post_two_pendulums, seed 1) — and they count by their share of it."""
    import time
    from types import SimpleNamespace

    from adept_traj.analysis import optimizer_overhead
    from adept_traj.optimise.local import polish_modes

    x = problem.trajectory.straight_line(1.5)
    ev = problem.evaluate_batch(x)
    outcome = SimpleNamespace(
        x=x,
        objectives=ev.objectives,
        constraints=ev.constraints,
        n_evaluations=3,
        seconds=seconds,
        evaluation_s=evaluating,
    )

    def two_outcomes(*args, **kwargs):
        time.sleep(0.05)
        return [outcome, SimpleNamespace(**{**vars(outcome), "x": x + 0.0})]

    monkeypatch.setattr(polish_modes, "time_optimal", two_outcomes)
    state, _ = polish_modes.time_optimal_run(problem, 1)
    assert state.total_s >= 0.05
    if seconds < 0.025:  # one after the other (2 × 0.02 s inside ≥ 0.05 s): the sum
        assert state.evaluation_s == pytest.approx(2 * evaluating, rel=1e-12)
    else:  # at once (2 × 1 s inside a run of < 2 s): their share of the wall time
        assert state.total_s < 2 * seconds
        assert state.evaluation_s == pytest.approx(evaluating / seconds * state.total_s)
    assert 0.0 <= optimizer_overhead(state.total_s, state.evaluation_s) <= 1.0
