"""Dense certificate: feasible, colliding and too-fast moves; dense vs exact; independent loop."""

from __future__ import annotations

import math

import coal
import numpy as np
import pinocchio as pin
import pytest

from adept_traj import Scene
from adept_traj.analysis import LIMIT_KINDS
from adept_traj.certification import Certificate, certify
from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.problem import TrajectoryProblem
from adept_traj.testing.paper_moves import lift_then_lower


@pytest.fixture(scope="module")
def feasible_x(problem: TrajectoryProblem) -> np.ndarray:
    return lift_then_lower(problem)


@pytest.fixture(scope="module")
def feasible(problem: TrajectoryProblem, feasible_x: np.ndarray) -> Certificate:
    return certify(problem, feasible_x)


def test_feasible_move_is_certified(problem: TrajectoryProblem, feasible: Certificate) -> None:
    assert feasible.feasible
    assert feasible.violations == ()
    assert feasible.min_distance >= problem.settings.margin
    assert feasible.margin == problem.settings.margin
    assert [check.kind for check in feasible.checks] == list(LIMIT_KINDS)
    for check in feasible.checks:
        assert np.all(check.worst <= check.bound), check.kind
        assert check.within.all()
    # The grid: ceil(T · 1 kHz) + 1 samples, both ends, spacing ≤ 1 ms.
    dense = feasible.dense
    assert feasible.n_samples == math.ceil(2.1 * 1000 - 1e-9) + 1 == 2101
    assert dense.t[0] == 0.0
    assert dense.t[-1] == pytest.approx(2.1, abs=1e-15)
    assert np.diff(dense.t).max() <= 1e-3 + 1e-15
    np.testing.assert_allclose(dense.q[0], problem.start, atol=1e-12)
    np.testing.assert_allclose(dense.q[-1], problem.goal, atol=1e-12)
    assert dense.min_distance.shape == (2101,)
    assert dense.min_distance.min() == feasible.min_distance
    k = int(np.argmin(dense.min_distance))
    assert feasible.t_min_distance == dense.t[k]
    assert feasible.closest_pair is not None


def test_straight_move_hits_cube1(problem: TrajectoryProblem) -> None:
    cert = certify(problem, problem.trajectory.straight_line(1.5))
    # Independently, at the reported instant: coal pair by pair finds the same penetration.
    k = int(np.flatnonzero(cert.dense.t == cert.t_min_distance)[0])
    best, pairs = coal_min_distances(problem, cert.dense.q[k : k + 1], cert.dense.t[k : k + 1])
    assert best[0] == pytest.approx(cert.min_distance, abs=1e-9)
    assert pairs[0] == cert.closest_pair
    assert not cert.feasible
    assert cert.limits_ok
    assert not cert.distance_ok
    assert cert.min_distance < 0.0  # penetration
    assert cert.closest_pair is not None
    assert cert.closest_pair[1] == "cube1"
    distance = [v for v in cert.violations if v.startswith("distance")]
    assert len(distance) == 1
    assert "cube1" in distance[0]


def test_too_fast_names_the_joints(problem: TrajectoryProblem) -> None:
    x = lift_then_lower(problem, T=1.0)  # below the kinematic lower bound 1.073 s
    cert = certify(problem, x)
    assert not cert.feasible
    # Which (kind, joint) exceed their limit, from the exact spline bounds alone.
    b, lim = problem.trajectory.bounds(x), problem.robot.limits
    exact = {
        "velocity": b.qd_abs_max / lim.velocity,
        "acceleration": b.qdd_abs_max / lim.acceleration,
        "jerk": b.qddd_abs_max / lim.jerk,
    }
    expected = {
        f"{kind} {lim.names[i]}:"
        for kind, ratio in exact.items()
        for i in np.flatnonzero(ratio > 1.0 + 1e-9)
    }
    assert "jerk joint4:" in expected  # the limiting joint of the lower bound
    named = {" ".join(v.split(" ")[:2]) for v in cert.violations if not v.startswith("distance")}
    assert named == expected
    jerk = next(v for v in cert.violations if v.startswith("jerk joint4:"))
    assert f"{exact['jerk'][3]:.4g} × JC" in jerk


def test_dense_agrees_with_exact_bounds(problem: TrajectoryProblem, feasible: Certificate) -> None:
    dense, lim = feasible.dense, problem.robot.limits
    dt = float(np.diff(dense.t).max())
    b = problem.trajectory.bounds(feasible.x)
    span = lim.upper - lim.lower
    # |f(t*) − f(t_k)| ≤ max|f'| · dt/2 at the sample nearest the extremum t*.
    slack = {
        "position": b.qd_abs_max * dt / 2 / span,
        "velocity": b.qdd_abs_max * dt / 2 / lim.velocity,
        "acceleration": b.qddd_abs_max * dt / 2 / lim.acceleration,
        "jerk": np.zeros(problem.robot.nq),  # piecewise constant, every segment sampled
    }
    for kind, s in slack.items():
        check = getattr(feasible, kind)
        assert check.exact is not None
        assert np.all(check.dense <= check.exact + 1e-12), kind
        assert np.all(check.exact - check.dense <= s + 1e-12), kind
        np.testing.assert_array_equal(check.worst, np.maximum(check.dense, check.exact))
    assert feasible.torque.exact is None
    # The exact values are the problem's constraints g (+1 for the ratios).
    g = problem.evaluate_batch(feasible.x).constraints
    nq = problem.robot.nq
    for j, kind in enumerate(LIMIT_KINDS[:4]):
        offset = 0.0 if kind == "position" else 1.0
        np.testing.assert_allclose(
            getattr(feasible, kind).exact - offset, g[j * nq : (j + 1) * nq], atol=1e-12
        )


def test_dense_torques_and_ratios(problem: TrajectoryProblem, feasible: Certificate) -> None:
    robot, dense = problem.robot, feasible.dense
    np.testing.assert_allclose(
        dense.tau, robot.inverse_dynamics(dense.q, dense.qd, dense.qdd), rtol=1e-12
    )
    ratio = np.abs(dense.tau) / robot.limits.torque
    np.testing.assert_allclose(feasible.torque.dense, ratio.max(axis=0), rtol=1e-15)
    np.testing.assert_array_equal(feasible.torque.t_worst, dense.t[ratio.argmax(axis=0)])
    samples = problem.trajectory.sample(feasible.x, np.linspace(0, 1, dense.n_samples))
    for name in ("q", "qd", "qdd", "qddd"):
        np.testing.assert_array_equal(getattr(dense, name), getattr(samples, name))


def coal_min_distances(
    problem: TrajectoryProblem, q: np.ndarray, t: np.ndarray
) -> tuple[np.ndarray, list[tuple[str, str]]]:
    """Independent dense check: per sample, Pinocchio placements and one coal.distance per
    (solid, obstacle) pair (GJK tolerance 1e-9, as documented for the checker), obstacles
    (the pendulum moves) at their pose at that instant. Returns the smallest distance
    (n,) [m] and the closest (solid, obstacle) names per sample."""
    robot, scene = problem.robot, problem.scene
    model, gm = robot.model, robot.collision_model
    data, gdata = model.createData(), gm.createData()
    obstacles = [ob.shape.to_coal() for ob in scene.obstacles]
    poses = scene.obstacle_poses(t, in_base_frame=True)  # (n_obstacles, n, 4, 4)
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    request.gjk_tolerance = 1e-9
    best, pairs = np.full(len(t), np.inf), []
    for k in range(len(t)):
        pin.updateGeometryPlacements(model, data, gm, gdata, q[k])
        pair = ("", "")
        for o, geom in enumerate(obstacles):
            tf_o = coal.Transform3s(poses[o, k, :3, :3], poses[o, k, :3, 3])
            for g, obj in enumerate(gm.geometryObjects):
                placement = gdata.oMg[g]
                tf_g = coal.Transform3s(placement.rotation, placement.translation)
                result.clear()
                d = coal.distance(obj.geometry, tf_g, geom, tf_o, request, result)
                if d < best[k]:
                    best[k], pair = d, (obj.name, scene.obstacles[o].name)
        pairs.append(pair)
    return best, pairs


def test_min_distance_equals_independent_loop(
    problem: TrajectoryProblem, feasible: Certificate
) -> None:
    """Every one of the 2 101 dense samples against coal called pair by pair."""
    dense = feasible.dense
    best, pairs = coal_min_distances(problem, dense.q, dense.t)
    np.testing.assert_allclose(dense.min_distance, best, rtol=0, atol=1e-9)
    k = int(np.argmin(best))
    assert feasible.min_distance == pytest.approx(best[k], abs=1e-9)
    assert feasible.t_min_distance == dense.t[k]
    assert feasible.closest_pair == pairs[k]
    assert best.min() >= problem.settings.margin  # the verdict, independently


def test_rate_and_inputs(problem: TrajectoryProblem, feasible_x: np.ndarray) -> None:
    fast = certify(problem, feasible_x, rate_hz=2000.0)
    assert fast.n_samples == 4201
    assert fast.rate_hz == 2000.0
    assert fast.feasible
    with pytest.raises(InvalidInputError, match="rate_hz"):
        certify(problem, feasible_x, rate_hz=0.0)
    with pytest.raises(InvalidInputError, match="rate_hz"):
        certify(problem, feasible_x, rate_hz=float("nan"))
    with pytest.raises(InputShapeError):
        certify(problem, feasible_x[:-1])
    bad = feasible_x.copy()
    bad[0] = -1.0
    with pytest.raises(InvalidInputError, match="T"):
        certify(problem, bad)


def test_scene_without_obstacles(problem: TrajectoryProblem, feasible_x: np.ndarray) -> None:
    empty = Scene(robot_base=problem.scene.robot_base, name="empty")
    p = TrajectoryProblem(problem.robot, empty, problem.start, problem.goal)
    cert = certify(p, feasible_x)
    assert cert.feasible
    assert cert.min_distance == math.inf
    assert cert.closest_pair is None
    assert cert.t_min_distance is None
    assert np.all(cert.dense.min_distance == np.inf)


def test_certificate_equality(problem: TrajectoryProblem, feasible: Certificate) -> None:
    again = certify(problem, feasible.x)
    assert again == feasible
    assert again != certify(problem, feasible.x, rate_hz=500.0)
