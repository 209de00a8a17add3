"""Robot model tests against independent references.

References: the paper's DH product (Table 1) written out here, the closed-form SCARA tool
position and manipulability, a Lagrangian model built in this file from its own link
kinematics (mass matrix from geometric Jacobians, Coriolis terms by finite differences),
and the textbook planar 2-link arm.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import adept_traj as at
from adept_traj import Robot
from adept_traj.errors import (
    InputShapeError,
    InvalidInputError,
    JointLimitError,
    RobotModelError,
)
from adept_traj.robot import RobotParameters

DATA = Path(__file__).parents[1] / "data"
A1, A2, D1, D4 = 0.425, 0.375, 0.876, 0.204
G0 = 9.81


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.adept_one_xl()


def random_q(robot: Robot, shape: tuple[int, ...], seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    lo, hi = robot.limits.lower, robot.limits.upper
    return lo + (hi - lo) * rng.uniform(size=(*shape, robot.nq))


# --------------------------------------------------------------------------- kinematics
def dh(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """Standard DH transform Rz(theta) Tz(d) Tx(a) Rx(alpha)."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def dh_tool(q: np.ndarray) -> np.ndarray:
    """The paper's Table 1 DH product for one configuration (theta1, theta2, d3, theta4)."""
    t1, t2, d3, t4 = q
    return dh(t1, D1, A1, np.pi) @ dh(t2, 0.0, A2, 0.0) @ dh(0.0, d3, 0.0, 0.0) @ dh(t4, D4, 0, 0)


def test_tool_pose_equals_dh_product_and_closed_form(robot: Robot) -> None:
    q = random_q(robot, (40,), seed=1)
    poses = robot.tool_pose(q)
    assert poses.shape == (40, 4, 4)
    for qi, pose in zip(q, poses):
        np.testing.assert_allclose(pose, dh_tool(qi), atol=1e-12)
    t1, t2, d3 = q[:, 0], q[:, 1], q[:, 2]
    x = A1 * np.cos(t1) + A2 * np.cos(t1 - t2)
    y = A1 * np.sin(t1) + A2 * np.sin(t1 - t2)
    z = D1 - d3 - D4
    np.testing.assert_allclose(poses[:, :3, 3], np.stack([x, y, z], axis=-1), atol=1e-12)


def test_tool_pose_keeps_leading_axes(robot: Robot) -> None:
    q = random_q(robot, (3, 5), seed=2)
    poses = robot.tool_pose(q)
    assert poses.shape == (3, 5, 4, 4)
    np.testing.assert_allclose(poses[2, 4], robot.tool_pose(q[2, 4]), atol=0)


def test_manipulability_is_a1_a2_sin_theta2(robot: Robot) -> None:
    q = random_q(robot, (7, 30), seed=3)
    w = robot.manipulability(q)
    assert w.shape == (7, 30)
    np.testing.assert_allclose(w, A1 * A2 * np.abs(np.sin(q[..., 1])), rtol=1e-12, atol=1e-15)
    assert robot.manipulability([0.2, 0.0, 0.1, 0.3]) == pytest.approx(0.0, abs=1e-15)


def test_tool_jacobian_matches_pinocchio_and_finite_differences(robot: Robot) -> None:
    q = random_q(robot, (10,), seed=4)
    jac = robot.tool_jacobian(q)
    data = robot.model.createData()
    fid = robot.model.getFrameId(robot.tool_frame)
    h = 1e-6
    for qi, ji in zip(q, jac):
        ref = pin.computeFrameJacobian(robot.model, data, qi, fid, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(ji, ref, atol=1e-12)
        for k in range(robot.nq):
            dq = np.zeros(robot.nq)
            dq[k] = h
            fd = (dh_tool(qi + dq)[:3, 3] - dh_tool(qi - dq)[:3, 3]) / (2 * h)
            np.testing.assert_allclose(ji[:3, k], fd, atol=1e-8)


def test_geometry_poses_match_pinocchio(robot: Robot) -> None:
    q = random_q(robot, (6,), seed=5)
    poses = robot.geometry_poses(q)
    gm = robot.collision_model
    assert poses.shape == (6, gm.ngeoms, 4, 4)
    data, gdata = robot.model.createData(), gm.createData()
    for qi, pi in zip(q, poses):
        pin.updateGeometryPlacements(robot.model, data, gm, gdata, qi)
        for k in range(gm.ngeoms):
            np.testing.assert_allclose(pi[k], gdata.oMg[k].homogeneous, atol=1e-12)


def test_collision_model_is_four_cylinders_and_three_prisms(robot: Robot) -> None:
    kinds = sorted(type(g.geometry).__name__ for g in robot.collision_model.geometryObjects)
    assert kinds == ["Box"] * 3 + ["Cylinder"] * 4
    names = [g.name for g in robot.collision_model.geometryObjects]
    assert "link4/gripper" in names
    assert "base_link/column" in names


# --------------------------------------------------------------------------- limits
def test_limits_are_table_2_in_si(robot: Robot) -> None:
    lim = robot.limits
    assert lim.names == ("joint1", "joint2", "joint3", "joint4")
    assert lim.units == ("rad", "rad", "m", "rad")
    np.testing.assert_allclose(lim.upper, [2.6180, 2.4435, 0.203, 4.7124])
    np.testing.assert_allclose(lim.lower, [-2.6180, -2.4435, 0.0, -4.7124])
    np.testing.assert_allclose(lim.velocity, [11.3446, 16.057, 1.2, 57.5959])
    np.testing.assert_allclose(lim.acceleration, [9.5] * 4)
    np.testing.assert_allclose(lim.jerk, [50.0] * 4)
    np.testing.assert_allclose(lim.torque, [400, 280, 100, 100])
    with pytest.raises(ValueError, match="read-only"):
        lim.torque[0] = 1.0


def test_check_position_names_joint_value_and_range(robot: Robot) -> None:
    ok = robot.limits.check_position([0.1, 0.2, 0.1, 0.0])
    assert ok.shape == (4,)
    with pytest.raises(JointLimitError, match=r"joint3.*0\.25 m.*\[0, 0\.203\] m"):
        robot.limits.check_position([0.1, 0.2, 0.25, 0.0], name="start")
    with pytest.raises(JointLimitError, match=r"start\[1\]: joint 'joint1' = 3 rad"):
        robot.limits.check_position([[0, 0, 0.1, 0], [3.0, 0, 0.1, 0]], name="start")


# --------------------------------------------------------------------------- dynamics
def scara_link_frames(q: np.ndarray) -> list[np.ndarray]:
    """World poses of link1..link4 of the shipped URDF, written from Table 1 by hand."""
    t1, t2, d3, t4 = q
    link1 = dh(t1, 0.0, 0.0, 0.0)
    link2 = link1 @ dh(0.0, D1, A1, np.pi) @ dh(t2, 0.0, 0.0, 0.0)
    link3 = link2 @ dh(0.0, d3, A2, 0.0)  # Tx(a2) Tz(d3): the two commute
    link4 = link3 @ dh(t4, 0.0, 0.0, 0.0)
    return [link1, link2, link3, link4]


def scara_axes(frames: list[np.ndarray]) -> list[tuple[np.ndarray, np.ndarray, bool]]:
    """(origin, world axis, revolute?) of joints 1..4 (each joint's axis is its link's z)."""
    return [(f[:3, 3], f[:3, 2], k != 2) for k, f in enumerate(frames)]


def lagrangian_torque(robot: Robot, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
    """Inverse dynamics by Euler–Lagrange: M(q) from geometric link Jacobians, Coriolis by
    central differences of M, gravity by differences of the potential energy, plus rotor
    inertia and viscous + Coulomb friction. Independent of Pinocchio's algorithms; the link
    inertial data (mass, centre of mass, inertia) is read from the model."""
    inertias = [robot.model.inertias[i] for i in range(1, 5)]

    def mass_matrix(qq: np.ndarray) -> np.ndarray:
        frames = scara_link_frames(qq)
        axes = scara_axes(frames)
        m = np.diag(robot.model.armature.copy())
        for b, (frame, inertia) in enumerate(zip(frames, inertias)):
            if inertia.mass == 0:
                continue
            rot = frame[:3, :3]
            com = frame[:3, 3] + rot @ inertia.lever
            jv, jw = np.zeros((3, 4)), np.zeros((3, 4))
            for k in range(b + 1):
                origin, z, revolute = axes[k]
                if revolute:
                    jv[:, k] = np.cross(z, com - origin)
                    jw[:, k] = z
                else:
                    jv[:, k] = z
            i_world = rot @ inertia.inertia @ rot.T
            m += inertia.mass * jv.T @ jv + jw.T @ i_world @ jw
        return m

    def potential(qq: np.ndarray) -> float:
        frames = scara_link_frames(qq)
        return sum(
            inertia.mass * G0 * (f[:3, 3] + f[:3, :3] @ inertia.lever)[2]
            for f, inertia in zip(frames, inertias)
        )

    h = 1e-6
    eye = np.eye(4)
    dm = [(mass_matrix(q + h * e) - mass_matrix(q - h * e)) / (2 * h) for e in eye]
    m_dot = sum(dmk * vk for dmk, vk in zip(dm, v))
    coriolis = m_dot @ v - 0.5 * np.array([v @ dmk @ v for dmk in dm])
    gravity = np.array([(potential(q + h * e) - potential(q - h * e)) / (2 * h) for e in eye])
    friction = robot.model.damping * v + robot.model.friction * np.sign(v)
    return mass_matrix(q) @ a + coriolis + gravity + friction


def test_inverse_dynamics_matches_independent_lagrangian(robot: Robot) -> None:
    rng = np.random.default_rng(6)
    q = random_q(robot, (8,), seed=7)
    v = rng.normal(scale=2.0, size=(8, 4))
    a = rng.normal(scale=5.0, size=(8, 4))
    tau = robot.inverse_dynamics(q, v, a)
    for qi, vi, ai, ti in zip(q, v, a, tau):
        np.testing.assert_allclose(ti, lagrangian_torque(robot, qi, vi, ai), rtol=1e-6, atol=1e-6)


def test_static_holding_force_of_joint_3_is_quill_weight(robot: Robot) -> None:
    # d3 moves along -z (down): holding the quill still needs -m g (pushing up).
    moving_mass = sum(robot.model.inertias[i].mass for i in (3, 4))
    tau = robot.inverse_dynamics([0.3, 0.5, 0.1, 0.2], np.zeros(4), np.zeros(4))
    assert tau[2] == pytest.approx(-moving_mass * G0, rel=1e-12)
    np.testing.assert_allclose(tau[[0, 1, 3]], 0.0, atol=1e-12)  # vertical axes: no gravity


def test_rotor_inertia_and_friction_terms(robot: Robot) -> None:
    params = RobotParameters.from_file(robot.params_path)
    expected = [j.rotor_inertia * j.gear_ratio**2 for j in params.joints]
    np.testing.assert_allclose(robot.model.armature, expected)
    np.testing.assert_allclose(robot.model.friction, [j.coulomb for j in params.joints])
    np.testing.assert_allclose(robot.model.damping, [j.viscous for j in params.joints])
    q = np.array([0.1, 0.4, 0.05, 0.0])
    v = np.array([0.5, -0.2, 0.1, -1.0])
    a = np.array([1.0, 2.0, -3.0, 4.0])
    rigid = pin.rnea(robot.model, robot.model.createData(), q, v, a)  # includes armature
    tau = robot.inverse_dynamics(q, v, a)
    np.testing.assert_allclose(
        tau - rigid, robot.model.damping * v + robot.model.friction * np.sign(v), atol=1e-12
    )
    # The armature contribution is exactly armature * a.
    model0 = robot.model.copy()
    model0.armature[:] = 0.0
    no_rotor = pin.rnea(model0, model0.createData(), q, v, a)
    np.testing.assert_allclose(rigid - no_rotor, robot.model.armature * a, atol=1e-12)


def test_batched_equals_per_sample(robot: Robot) -> None:
    rng = np.random.default_rng(8)
    q = random_q(robot, (4, 25), seed=9)  # 100 samples: the parallel path
    v = rng.normal(size=(4, 25, 4))
    a = rng.normal(size=(4, 25, 4))
    batched = robot.inverse_dynamics(q, v, a)
    assert batched.shape == (4, 25, 4)
    single = np.array(
        [[robot.inverse_dynamics(q[i, j], v[i, j], a[i, j]) for j in range(25)] for i in range(4)]
    )
    np.testing.assert_allclose(batched, single, rtol=0, atol=1e-10)
    again = robot.inverse_dynamics(q, v, a)
    np.testing.assert_array_equal(batched, again)  # deterministic


def test_inverse_dynamics_broadcasts(robot: Robot) -> None:
    q = random_q(robot, (20,), seed=10)
    tau = robot.inverse_dynamics(q, np.zeros(4), np.zeros(4))
    assert tau.shape == (20, 4)
    np.testing.assert_allclose(tau[5], robot.inverse_dynamics(q[5], np.zeros(4), np.zeros(4)))


def test_model_edits_are_seen_by_inverse_dynamics() -> None:
    robot = Robot.adept_one_xl()
    q = np.tile([0.0, 0.5, 0.1, 0.0], (20, 1))
    v = a = np.ones((20, 4))
    before = robot.inverse_dynamics(q, v, a)
    robot.model.armature[0] += 1.0
    robot.model.friction[1] += 2.0
    after = robot.inverse_dynamics(q, v, a)
    np.testing.assert_allclose(after - before, np.tile([1.0, 2.0, 0.0, 0.0], (20, 1)), atol=1e-12)


# --------------------------------------------------------------------------- second robot
@pytest.fixture(scope="module")
def planar() -> Robot:
    return Robot.from_urdf(DATA / "planar_2link.urdf", DATA / "planar_2link.toml")


def test_planar_arm_against_textbook_closed_form(planar: Robot) -> None:
    m1, m2, l1, lc1, lc2 = 2.0, 1.0, 0.6, 0.3, 0.2
    i1, i2 = 0.06, 0.0133333333333
    jr = 0.01 * 3.0**2
    rng = np.random.default_rng(11)
    q = rng.uniform(-2, 2, size=(50, 2))
    v = rng.normal(size=(50, 2))
    a = rng.normal(size=(50, 2))
    tau = planar.inverse_dynamics(q, v, a)
    c2 = np.cos(q[:, 1])
    m11 = i1 + i2 + m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + jr
    m12 = i2 + m2 * (lc2**2 + l1 * lc2 * c2)
    m22 = i2 + m2 * lc2**2
    hh = m2 * l1 * lc2 * np.sin(q[:, 1])
    g1 = (m1 * lc1 + m2 * l1) * G0 * np.cos(q[:, 0]) + m2 * lc2 * G0 * np.cos(q.sum(1))
    g2 = m2 * lc2 * G0 * np.cos(q.sum(1))
    tau1 = m11 * a[:, 0] + m12 * a[:, 1] - hh * (2 * v[:, 0] * v[:, 1] + v[:, 1] ** 2) + g1
    tau2 = m12 * a[:, 0] + m22 * a[:, 1] + hh * v[:, 0] ** 2 + g2
    friction = np.array([0.2, 0.1]) * v + np.array([0.5, 0.3]) * np.sign(v)
    expected = np.stack([tau1, tau2], axis=-1) + friction
    np.testing.assert_allclose(tau, expected, rtol=1e-9, atol=1e-9)


def test_planar_arm_limits_tool_and_manipulability(planar: Robot) -> None:
    assert planar.tool_frame == "hand"
    np.testing.assert_allclose(planar.limits.acceleration, [20.0, 30.0])
    np.testing.assert_allclose(planar.limits.torque, [50.0, 20.0])
    q = np.array([[0.3, 0.9], [1.0, -0.4]])
    pose = planar.tool_pose(q)
    x = 0.6 * np.cos(q[:, 0]) + 0.4 * np.cos(q.sum(1))
    z = 0.6 * np.sin(q[:, 0]) + 0.4 * np.sin(q.sum(1))
    np.testing.assert_allclose(pose[:, [0, 2], 3], np.stack([x, z], -1), atol=1e-12)
    np.testing.assert_allclose(planar.manipulability(q), 0.24 * np.abs(np.sin(q[:, 1])))


def test_robot_without_parameters_has_infinite_acc_jerk_and_asks_for_task_rows() -> None:
    robot = Robot.from_urdf(DATA / "planar_2link.urdf")
    assert np.all(np.isinf(robot.limits.acceleration))
    assert robot.tool_frame == "hand"  # the last frame of the model
    with pytest.raises(RobotModelError, match="task_rows"):
        robot.manipulability([0.1, 0.2])
    # Three rows for two joints: the volume of the 2-D velocity ellipsoid, sqrt(det(J^T J)).
    tall = Robot.from_urdf(DATA / "planar_2link.urdf", task_rows=["vx", "vz", "wy"])
    q = np.array([0.3, 0.9])
    jac = tall.tool_jacobian(q)[[0, 2, 4]]
    assert tall.manipulability(q) == pytest.approx(np.sqrt(np.linalg.det(jac.T @ jac)))
    # Yoshikawa's sqrt(det(J J^T)) with fewer rows than joints: one row here.
    wide = Robot.from_urdf(DATA / "planar_2link.urdf", task_rows=["vx"])
    row = wide.tool_jacobian(q)[[0]]
    assert wide.manipulability(q) == pytest.approx(np.sqrt(float((row @ row.T)[0, 0])))


# --------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    ("args", "error", "pattern"),
    [
        (([0.1, 0.2, 0.1], [0] * 4, [0] * 4), InputShapeError, r"q must have shape \(\.\.\., 4\)"),
        (([0.1, np.nan, 0.1, 0], [0] * 4, [0] * 4), InvalidInputError, r"q must be finite.*nan"),
        (([0.1, 0.2, 0.1, 0], [0] * 4, "fast"), InvalidInputError, "a must be numeric"),
        ((np.zeros((3, 4)), np.zeros((2, 4)), np.zeros(4)), InputShapeError, "broadcast"),
    ],
)
def test_inverse_dynamics_bad_input(robot: Robot, args, error, pattern) -> None:
    with pytest.raises(error, match=pattern):
        robot.inverse_dynamics(*args)


def test_other_methods_bad_input(robot: Robot) -> None:
    with pytest.raises(InputShapeError, match=r"got shape \(\)"):
        robot.manipulability(0.3)
    with pytest.raises(InvalidInputError, match="inf"):
        robot.tool_pose([0.0, np.inf, 0.0, 0.0])
    with pytest.raises(InvalidInputError, match="frame 'nope' does not exist"):
        robot.frame_pose([0, 0, 0, 0], "nope")


def test_missing_and_malformed_urdf(tmp_path: Path) -> None:
    with pytest.raises(RobotModelError, match="URDF not found"):
        Robot.from_urdf(tmp_path / "missing.urdf")
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'></robot>")
    with pytest.raises(RobotModelError, match="malformed XML"):
        Robot.from_urdf(bad)
    other = tmp_path / "other.urdf"
    other.write_text("<model/>")
    with pytest.raises(RobotModelError, match="expected <robot>"):
        Robot.from_urdf(other)


def test_unsupported_joint_type(tmp_path: Path) -> None:
    text = (DATA / "planar_2link.urdf").read_text().replace('type="revolute"', 'type="floating"', 1)
    path = tmp_path / "floating.urdf"
    path.write_text(text)
    with pytest.raises(RobotModelError, match="only 1-DoF revolute and prismatic"):
        Robot.from_urdf(path)


def test_bad_parameter_files(tmp_path: Path) -> None:
    urdf = DATA / "planar_2link.urdf"
    cases = {
        '[[joint]]\nname = "wrist"\njerk = 1.0\n': r"joint\(s\) \['wrist'\] are not in",
        '[[joint]]\nname = "elbow"\njerk = -1.0\n': (
            r"p1\.toml: field 'joint\[0\]\.jerk': must be a finite number > 0 "
            r"\[rad/s³ \| m/s³\]; got -1\.0 \(in joint 'elbow'\)$"
        ),
        '[[joint]]\nname = "elbow"\nstiffness = 1.0\n': (
            r"p2\.toml: field 'joint\[0\]\.stiffness': unknown field; allowed fields: 'name', "
            r".*'viscous' \(in joint 'elbow'\)$"
        ),
        'task_rows = ["vx", "spin"]\n': (
            r"p3\.toml: field 'task_rows\[1\]': must be one of 'vx', .*'wz'; got the string 'spin'"
        ),
        'task_rows = ["vx", "vx"]\n': r"field 'task_rows': must hold distinct strings; got 'vx'",
        '[[joint]]\nname = "elbow"\nlower = 1.0\nupper = 0.5\n': (
            r"field 'joint\[0\]\.upper': must be above 'lower' \(1\.0\); got 0\.5"
        ),
        '[[joint]]\nname = "elbow"\n[[joint]]\nname = "elbow"\n': (
            r"field 'joint': names must be distinct; got 'elbow' more than once"
        ),
        "tool_frame = [": "invalid TOML",
        'tool_frame = "paw"\n': "no frame 'paw'",
    }
    for k, (text, pattern) in enumerate(cases.items()):
        path = tmp_path / f"p{k}.toml"
        path.write_text(text)
        with pytest.raises(RobotModelError, match=pattern):
            Robot.from_urdf(urdf, path)
    with pytest.raises(RobotModelError, match="file not found"):
        Robot.from_urdf(urdf, tmp_path / "nothing.toml")


def test_coulomb_friction_dead_band(robot: Robot) -> None:
    q = np.tile([0.1, 0.4, 0.05, 0.0], (3, 1))
    v = np.array([[0.0] * 4, [1e-12] * 4, [1e-6] * 4])
    tau = robot.inverse_dynamics(q, v, np.zeros((3, 4)))
    np.testing.assert_allclose(tau[1], tau[0], atol=1e-9)  # rounding noise: still at rest
    np.testing.assert_allclose(tau[2] - tau[0], robot.model.friction, atol=1e-4)


def test_more_task_rows_than_joints_and_read_only_tool_frame() -> None:
    robot = Robot.from_urdf(
        Path(__file__).resolve().parents[2] / "urdf" / "adept_one_xl.urdf",
        Path(__file__).resolve().parents[2] / "urdf" / "adept_one_xl.toml",
        task_rows=["vx", "vy", "vz", "wx", "wy", "wz"],
    )
    q = np.array([0.1, 0.7, 0.1, 0.2])
    jac = robot.tool_jacobian(q)
    assert robot.manipulability(q) == pytest.approx(np.sqrt(np.linalg.det(jac.T @ jac)))
    assert robot.manipulability(q) == pytest.approx(A1 * A2 * abs(np.sin(0.7)))
    with pytest.raises(AttributeError):
        robot.tool_frame = "link2"


def test_batch_kinematics_any_axis_matches_pinocchio() -> None:
    """Joint poses and Jacobians of a chain with x, y, oblique revolute and prismatic axes
    (the z-axis fast path and the general U Rz U^T path) against Pinocchio, per sample."""
    from adept_traj.robot import BatchKinematics

    model = pin.Model()
    oblique = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
    joints = [
        pin.JointModelRZ(),
        pin.JointModelRX(),
        pin.JointModelRevoluteUnaligned(*oblique),
        pin.JointModelPY(),
        pin.JointModelPrismaticUnaligned(*oblique),
        pin.JointModelRY(),
    ]
    rng = np.random.default_rng(3)
    parent = 0
    for k, jm in enumerate(joints):
        placement = pin.SE3(pin.rpy.rpyToMatrix(*rng.uniform(-1, 1, 3)), rng.uniform(-0.5, 0.5, 3))
        parent = model.addJoint(parent, jm, placement, f"j{k}")
        model.appendBodyToJoint(parent, pin.Inertia.Random(), pin.SE3.Identity())
    kin = BatchKinematics(model)
    q = rng.uniform(-2.0, 2.0, size=(2, 3, model.nq))
    poses = kin.joint_poses(q)
    assert poses.shape == (2, 3, model.njoints, 4, 4)
    data = model.createData()
    point = np.array([0.1, -0.2, 0.3])
    for idx in np.ndindex(2, 3):
        pin.forwardKinematics(model, data, q[idx])
        for i in range(model.njoints):
            np.testing.assert_allclose(poses[idx][i], data.oMi[i].homogeneous, atol=1e-12)
        last = model.njoints - 1
        world = data.oMi[last].act(point)
        pin.computeJointJacobians(model, data, q[idx])
        ref = pin.getJointJacobian(model, data, last, pin.LOCAL_WORLD_ALIGNED).copy()
        ref[:3] += np.cross(ref[3:].T, world - data.oMi[last].translation).T  # move to point
        jac = kin.jacobian(poses[idx][None], last, world[None])[0]
        np.testing.assert_allclose(jac, ref, atol=1e-12)


@pytest.mark.parametrize("k", [1, 2, 3, 4, 5])
def test_small_determinants_match_lapack(k: int) -> None:
    from adept_traj.robot.manipulability import _det

    a = np.random.default_rng(k).normal(size=(7, 3, k, k))
    np.testing.assert_allclose(_det(a), np.linalg.det(a), rtol=1e-12, atol=1e-12)
    if k == 1:
        return
    singular = a.copy()
    singular[..., -1, :] = singular[..., 0, :]  # two equal rows
    np.testing.assert_allclose(_det(singular), 0.0, atol=1e-12)


def test_joint_limits_effort_keyword_is_deprecated_but_works():
    """``effort=`` (the name before the limit-kind vocabulary) still builds the same limits."""
    args = (("a",), ("rad",), [-1.0], [1.0], [2.0], [3.0], [4.0])
    with pytest.warns(DeprecationWarning, match="use torque"):
        old = at.JointLimits(*args, effort=[5.0])
    assert old == at.JointLimits(*args, torque=[5.0])
    shipped = Robot.adept_one_xl().limits  # 4 joints: arrays compared element-wise
    assert shipped == dataclasses.replace(shipped)
    assert shipped != dataclasses.replace(shipped, torque=shipped.torque * 2)
    np.testing.assert_array_equal(old.torque, [5.0])
    with pytest.warns(DeprecationWarning, match="use JointLimits.torque"):
        np.testing.assert_array_equal(old.effort, [5.0])
    assert dataclasses.replace(old, torque=[6.0]).torque[0] == 6.0
    with pytest.raises(at.InvalidInputError, match="not both"):
        at.JointLimits(*args, [5.0], effort=[5.0])
    with pytest.raises(at.InvalidInputError, match="torque limits"):
        at.JointLimits(*args)
