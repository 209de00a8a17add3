"""The continuous-time distance guarantee of the certificate (issue #11, step 1), and the
torque refined between the samples near its limit.

References are independent of the code under test: coal called directly on the solid and
obstacle poses (pinocchio's geometry placements), at 20–100 kHz, finite differences of
the pendulum's bob position, and pinocchio's RNEA called directly for the torque.
"""

from __future__ import annotations

import dataclasses

import coal
import numpy as np
import pinocchio as pin
import pytest

from adept_traj import PlanningResult, Robot, Scene
from adept_traj.certification import certify
from adept_traj.problem import TrajectoryProblem
from adept_traj.scene import Cylinder, FixedPose, Obstacle, PendulumMotion
from adept_traj.testing.paper_moves import lift_then_lower, single_result

START = np.array([0.0, 0.5, 0.1, 0.0])
GOAL = np.array([2.0, 0.5, 0.1, 0.0])
T = 1.4  # [s]: a fast θ1 swing within the limits, ≈ 2 m/s at the gripper mid-way


def _problem(obstacles: tuple[Obstacle, ...]) -> TrajectoryProblem:
    scene = Scene(obstacles=obstacles, start=START, goal=GOAL, name="thin")
    return TrajectoryProblem(Robot.adept_one_xl(), scene, START, GOAL)


def _reference_distances(
    problem: TrajectoryProblem,
    x: np.ndarray,
    t: np.ndarray,
    obstacles: tuple[Obstacle, ...] | None = None,
) -> np.ndarray:
    """(n,) smallest solid–obstacle distance [m] at times ``t`` by coal, called directly,
    to ``obstacles`` (default: the problem's scene's)."""
    robot = problem.robot
    obstacles = problem.scene.obstacles if obstacles is None else obstacles
    t = np.asarray(t, dtype=float)
    q = problem.trajectory.sample(x, t / x[0], orders=(0,)).q
    poses = robot.geometry_poses(q)  # (n, n_solids, 4, 4), world = base (identity)
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    request.gjk_tolerance = 1e-9
    out = np.full(len(t), np.inf)
    for ob in obstacles:
        geometry_o = ob.shape.to_coal()
        pose_o = ob.pose(t)
        for s, g in enumerate(robot.collision_model.geometryObjects):
            for k in range(len(t)):
                result.clear()
                d = coal.distance(
                    g.geometry,
                    coal.Transform3s(poses[k, s, :3, :3], poses[k, s, :3, 3]),
                    geometry_o,
                    coal.Transform3s(pose_o[k, :3, :3], pose_o[k, :3, 3]),
                    request,
                    result,
                )
                out[k] = min(out[k], d)
    return out


def _thin_post(angle: float, radius: float) -> Obstacle:
    """A 2 mm thin, 40 mm short vertical post at ``radius`` [m] from the first joint axis, at
    ``angle`` [rad], at the gripper's height (z = 0.53–0.57 m, below the arms)."""
    xyz = (radius * np.cos(angle), radius * np.sin(angle), 0.55)
    return Obstacle("post", Cylinder(0.002, 0.04), FixedPose.from_xyz_rpy(xyz))


def _dip_between_samples() -> tuple[TrajectoryProblem, np.ndarray]:
    """A fast swing past a thin post whose closest approach falls mid-way between two 1 kHz
    samples, 10 µm inside the margin, while every 1 kHz sample clears the margin.

    Only θ1 moves, so the robot turns rigidly about the first axis: turning the post by
    Δφ shifts the distance curve by Δφ in θ1, which places the minimum at the wanted time.
    """
    t_star = 0.7005  # between the 1 kHz samples 0.700 and 0.701 s
    problem = _problem((_thin_post(0.0, 1.5),))
    x = problem.trajectory.straight_line(T)
    theta1 = lambda t: problem.trajectory.sample(x, np.atleast_1d(t) / T, orders=(0,)).q[:, 0]  # noqa: E731
    tool = problem.robot.tool_pose(problem.trajectory.sample(x, [t_star / T], orders=(0,)).q)
    reach = float(np.hypot(*tool[0, :2, 3]))
    angle = float(np.arctan2(tool[0, 1, 3], tool[0, 0, 3]))
    margin = problem.settings.margin
    window = t_star + np.linspace(-0.05, 0.05, 2001)
    radius = reach + 0.05
    for _ in range(3):  # alternate: turn the post to t*, then move it to d(t*) = margin − 10 µm
        d = _reference_distances(problem, x, window, (_thin_post(angle, radius),))
        angle += float(theta1(t_star)[0] - theta1(window[np.argmin(d)])[0])
        lo, hi = radius - 0.1, radius + 0.1
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            d_star = _reference_distances(problem, x, [t_star], (_thin_post(angle, mid),))[0]
            lo, hi = (mid, hi) if d_star < margin - 1e-5 else (lo, mid)
        radius = hi
    return _problem((_thin_post(angle, radius),)), x


@pytest.fixture(scope="module")
def dip() -> tuple[TrajectoryProblem, np.ndarray]:
    return _dip_between_samples()


@pytest.mark.slow  # ≥ 3 s: kept out of the default tier (≤ 3 min)
def test_dip_is_between_the_1khz_samples(dip):
    problem, x = dip
    margin = problem.settings.margin
    grid = np.linspace(0.0, T, 1401)
    fine = np.linspace(0.69, 0.71, 2001)  # 100 kHz around the pass
    assert _reference_distances(problem, x, grid).min() >= margin
    assert _reference_distances(problem, x, fine).min() < margin


def test_sampled_certificate_accepts_the_dip(dip):
    problem, x = dip
    sampled = certify(problem, x, continuous=False)
    assert sampled.feasible
    assert sampled.guarantee == "sampled at 1000 Hz"
    assert sampled.distance_bound is None
    assert not sampled.certified


def test_continuous_certificate_rejects_the_dip(dip):
    problem, x = dip
    cert = certify(problem, x)
    assert not cert.feasible
    assert not cert.certified
    assert cert.min_distance < problem.settings.margin
    assert 0.7 < cert.t_min_distance < 0.701
    assert cert.closest_pair[1] == "post"
    assert any(v.startswith("distance:") for v in cert.violations)


def test_continuous_guarantee_clear_pass():
    problem = _problem((_thin_post(1.0, 1.2),))  # 1.2 m from the axis: beyond the arm's reach
    x = problem.trajectory.straight_line(T)
    cert = certify(problem, x)
    assert cert.certified
    assert cert.guarantee == "continuous"
    assert problem.settings.margin <= cert.distance_bound <= cert.min_distance


@pytest.mark.parametrize(
    "seed", [0, pytest.param(1, marks=pytest.mark.slow), pytest.param(2, marks=pytest.mark.slow)]
)
def test_bound_is_sound_on_random_moves(seed):
    """The certified lower bound never exceeds the true minimum (coal at 20 kHz), on random
    moves past the thin post, with a coarse 100 Hz grid and no refinement (loose bounds)."""
    rng = np.random.default_rng(seed)
    problem = _problem((_thin_post(1.0, 0.95),))
    x = problem.trajectory.straight_line(T)
    x[1:] += rng.normal(0.0, 0.1, x.size - 1)
    cert = certify(problem, x, rate_hz=100.0, max_depth=0)
    true = _reference_distances(problem, x, np.linspace(0.0, T, 28001)).min()
    assert cert.distance_bound <= true + 1e-9
    assert cert.min_distance >= true - 1e-9


def test_bound_is_sound_with_the_pendulum():
    """A moving obstacle: the paper's pendulum swinging through the arm's path."""
    rng = np.random.default_rng(7)
    law = PendulumMotion(pivot=(0.6, 0.6, 1.3), length=1.0, v0=2.0, omega=3.14)
    bob = Obstacle("bob", Cylinder(0.05, 0.1), law, FixedPose.from_xyz_rpy((0, 0, -1.0)).transform)
    problem = _problem((bob,))
    x = problem.trajectory.straight_line(T)
    x[1:] += rng.normal(0.0, 0.05, x.size - 1)
    cert = certify(problem, x, rate_hz=100.0, max_depth=0)
    true = _reference_distances(problem, x, np.linspace(0.0, T, 28001)).min()
    assert cert.distance_bound <= true + 1e-9


def test_pendulum_speed_bound_against_finite_differences():
    law = PendulumMotion(pivot=(0.0, 0.0, 1.0), length=1.0, v0=2.0, omega=3.14)
    t = np.linspace(0.0, 2.0 * law.period, 200001)
    bob = law.bob_position(t)
    speed = np.linalg.norm(np.diff(bob, axis=0), axis=1) / np.diff(t)
    bound = law.max_point_speed((0.0, 0.0, -1.0), 0.0)
    assert speed.max() <= bound
    assert speed.max() > 0.999 * bound  # the bound is reached at the bottom
    assert FixedPose.from_xyz_rpy((1, 2, 3)).max_point_speed((0.0, 0.0, 1.0), 0.5) == 0.0


def test_fast_certificate_same_verdict(dip):
    """exact=False (broad-phase bounds above the influence distance) decides as the exact
    certificate: on the dip (rejected) and on the clear pass (certified, same minimum)."""
    problem, x = dip
    assert not certify(problem, x, exact=False).feasible
    clear = _problem((_thin_post(1.0, 1.2),))
    x = clear.trajectory.straight_line(T)
    fast, exact = certify(clear, x, exact=False), certify(clear, x)
    assert fast.certified
    assert exact.certified
    assert fast.distance_bound <= exact.distance_bound
    assert fast.min_distance <= exact.min_distance


# ---------------------------------------------------------------- the torque between samples
def _reference_torques(problem: TrajectoryProblem, x: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(n, nq) joint torques [N·m | N] at times ``t`` [s]: pinocchio's RNEA called directly
    (it adds the rotor inertia, ``model.armature``) plus viscous and Coulomb friction."""
    model = problem.robot.model
    data = model.createData()
    smp = problem.trajectory.sample(x, np.asarray(t) / x[0])
    coulomb = model.friction * np.sign(smp.qd) * (np.abs(smp.qd) > 1e-9)
    rnea = [pin.rnea(model, data, q, v, a) for q, v, a in zip(smp.q, smp.qd, smp.qdd)]
    return np.array(rnea) + model.damping * smp.qd + coulomb


def test_torque_peak_between_samples_rejected_with_refinement():
    """A fast θ1 swing whose joint-1 torque peaks (at a spline knot, ≈ 0.3684 s) between two
    1 kHz samples; UC1 is set half-way between the 1 kHz and the 100 kHz maxima."""
    robot = Robot.adept_one_xl()
    scene = Scene(obstacles=(), start=START, goal=GOAL, name="empty")
    reference = TrajectoryProblem(robot, scene, START, GOAL)
    x = reference.trajectory.straight_line(T)
    sampled_max = np.abs(_reference_torques(reference, x, np.linspace(0.0, T, 1401))).max(0)
    fine_max = np.abs(_reference_torques(reference, x, np.linspace(0.0, T, 140001))).max(0)
    assert fine_max[0] - sampled_max[0] > 1e-2  # [N·m]: the peak is missed by the samples
    torque = robot.limits.torque.copy()
    torque[0] = 0.5 * (sampled_max[0] + fine_max[0])
    robot = robot.replace(limits=dataclasses.replace(robot.limits, torque=torque))
    problem = TrajectoryProblem(robot, scene, START, GOAL)

    sampled = certify(problem, x, continuous=False)
    assert sampled.feasible
    assert sampled.torque_guarantee == "sampled at 1000 Hz"

    refined = certify(problem, x)
    assert not refined.feasible
    assert refined.torque_guarantee == "sampled at 1000 Hz, refined to 64000 Hz near the limit"
    assert [v.split(":")[0] for v in refined.violations] == ["torque joint1"]
    assert 1.0 < refined.torque.dense[0] <= fine_max[0] / torque[0] + 1e-12
    assert 0.368 < refined.torque.t_worst[0] < 0.369


def test_paper_move_torque_unaffected(problem):
    """A normal paper move keeps its verdict and worst torques; the label says why."""
    x = lift_then_lower(problem)
    sampled, refined = certify(problem, x, continuous=False), certify(problem, x)
    assert refined.feasible == sampled.feasible
    assert refined.feasible
    np.testing.assert_allclose(refined.torque.dense, sampled.torque.dense, rtol=1e-3)
    assert refined.torque_guarantee == "sampled at 1000 Hz, below 0.9 × UC"


def test_torque_guarantee_round_trips_through_result_json(problem, tmp_path):
    result = single_result(problem, lift_then_lower(problem))
    loaded = PlanningResult.load(result.save(tmp_path / "run"))
    assert loaded.certificate.torque_guarantee == "sampled at 1000 Hz, below 0.9 × UC"
    assert loaded.certificate == result.certificate
