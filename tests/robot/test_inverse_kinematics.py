"""Inverse kinematics: closed-form SCARA (both elbows) and numeric IK of a 6-axis arm.

References: the robot's forward kinematics (:meth:`Robot.tool_pose`) for the SCARA and
Pinocchio's ``framesForwardKinematics`` for the UR5 of example-robot-data."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from adept_traj.errors import (
    InputShapeError,
    InvalidInputError,
    RobotModelError,
    UnreachableLocationError,
)
from adept_traj.robot import (
    ELBOWS,
    Robot,
    ScaraGeometry,
    numeric_ik,
    scara_ik,
    scara_location,
    solve_location,
)

UR5 = (
    Path(pin.__file__).parents[4]
    / "share/example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
)


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.adept_one_xl()


@pytest.fixture(scope="module")
def geometry(robot: Robot) -> ScaraGeometry:
    return ScaraGeometry.of(robot)


def _xyz_yaw(robot: Robot, q: np.ndarray) -> np.ndarray:
    pose = robot.tool_pose(q)
    return np.array([*pose[:3, 3], np.arctan2(pose[1, 0], pose[0, 0])])


def _configurations(robot: Robot, elbow: str, n: int = 20) -> np.ndarray:
    """Seeded joints within the limits whose arm is ``elbow`` (θ2 < 0 is righty) and whose
    wrist angle lies in (-π, π] (the IK's nearest-to-0 choice)."""
    rng = np.random.default_rng(3)
    lo, hi = robot.limits.lower, robot.limits.upper
    q = rng.uniform(lo, hi, size=(n, 4))
    q[:, 1] = np.abs(q[:, 1]).clip(0.05) * (-1.0 if elbow == "righty" else 1.0)
    q[:, 3] = rng.uniform(-3.0, 3.0, size=n)
    return q


@pytest.mark.parametrize("elbow", ELBOWS)
def test_scara_round_trip_pose_joints_pose(robot, geometry, elbow):
    for q in _configurations(robot, elbow):
        location = _xyz_yaw(robot, q)
        joints = scara_ik(geometry, location, elbow)
        np.testing.assert_allclose(joints, q, atol=1e-9)
        np.testing.assert_allclose(_xyz_yaw(robot, joints), location, atol=1e-9)


def test_scara_location_is_the_forward_kinematics(robot, geometry):
    q = _configurations(robot, "lefty", n=5)
    want = np.array([_xyz_yaw(robot, qk) for qk in q])
    np.testing.assert_allclose(scara_location(geometry, q), want, atol=1e-12)
    with pytest.raises(InputShapeError):
        scara_location(geometry, np.zeros(3))


def test_both_elbows_reach_the_same_location_differently(robot, geometry):
    location = [0.5, 0.3, 0.6, 0.4]
    righty, lefty = (scara_ik(geometry, location, e) for e in ("righty", "lefty"))
    np.testing.assert_allclose(_xyz_yaw(robot, righty), location, atol=1e-12)
    np.testing.assert_allclose(_xyz_yaw(robot, lefty), location, atol=1e-12)
    # righty: seen from above, the elbow is right of the shoulder→wrist line.
    elbows = [robot.frame_pose(q, "joint2")[:3, 3] * [1, 1, 0] for q in (righty, lefty)]
    wrist = np.array([*location[:2], 0.0])
    side = [np.cross(wrist, e)[2] for e in elbows]  # > 0: left of the shoulder→wrist line
    assert side[0] < 0.0 < side[1]
    assert righty[1] < 0.0 < lefty[1]


def test_default_elbow_is_righty_else_lefty(robot):
    q, elbow = solve_location(robot, [0.5, 0.3, 0.6, 0.4])
    assert elbow == "righty"
    assert q[1] < 0
    # At (-0.5, -0.3) m righty would need θ1 = 2.985 rad, beyond 150°: lefty is used.
    q, elbow = solve_location(robot, [-0.5, -0.3, 0.6, 0.0])
    assert elbow == "lefty"
    np.testing.assert_allclose(_xyz_yaw(robot, q), [-0.5, -0.3, 0.6, 0.0], atol=1e-12)
    with pytest.raises(UnreachableLocationError, match="joint 1") as info:
        solve_location(robot, [-0.5, -0.3, 0.6, 0.0], elbow="righty")
    assert info.value.distance == pytest.approx(0.3669, abs=1e-4)


@pytest.mark.parametrize(
    ("location", "distance", "unit", "words"),
    [
        ([1.0, 0.0, 0.6, 0.0], 0.2, "m", "beyond the arm's reach"),
        ([0.03, 0.0, 0.6, 0.0], 0.02, "m", "inner dead zone"),
        ([0.5, 0.3, 0.75, 0.0], 0.078, "m", "stroke"),
        ([0.5, 0.3, 0.3, 0.0], 0.169, "m", "stroke"),
    ],
)
def test_unreachable_locations_say_how_far(geometry, location, distance, unit, words):
    with pytest.raises(UnreachableLocationError, match=words) as info:
        scara_ik(geometry, location, "righty", name="pick")
    assert info.value.location == "pick"
    assert "'pick'" in str(info.value)
    assert info.value.distance == pytest.approx(distance, abs=1e-9)
    assert info.value.unit == unit


def test_joint_limit_distance(robot, geometry):
    # Straight behind the robot: θ1 = ±π for a stretched arm, 0.5236 rad beyond ±150°.
    with pytest.raises(UnreachableLocationError, match="joint 1") as info:
        scara_ik(geometry, [-0.8, 0.0, 0.6, 0.0], "righty")
    assert info.value.distance == pytest.approx(np.pi - robot.limits.upper[0], abs=1e-6)


@pytest.mark.parametrize(
    ("location", "elbow", "error"),
    [
        ([0.5, 0.3, 0.6], "righty", InputShapeError),
        ([0.5, np.nan, 0.6, 0.0], "righty", InvalidInputError),
        ([0.5, 0.3, 0.6, "a"], "righty", InvalidInputError),
        ([0.5, 0.3, 0.6, 0.0], "up", InvalidInputError),
    ],
)
def test_malformed_locations_refused(geometry, location, elbow, error):
    with pytest.raises(error, match="location 'bad'"):
        scara_ik(geometry, location, elbow, name="bad")


@pytest.fixture(scope="module")
def ur5() -> tuple[pin.Model, int]:
    model = pin.buildModelFromUrdf(str(UR5))
    return model, model.getFrameId("tool0")


def test_numeric_ik_round_trip_six_axis(ur5):
    model, frame = ur5
    data = model.createData()
    rng = np.random.default_rng(5)
    for q in rng.uniform(-2.5, 2.5, size=(6, model.nq)):
        pin.framesForwardKinematics(model, data, q)
        target = data.oMf[frame].homogeneous.copy()
        joints = numeric_ik(model, frame, target, seed=1)
        assert np.all(joints >= model.lowerPositionLimit)
        assert np.all(joints <= model.upperPositionLimit)
        pin.framesForwardKinematics(model, data, joints)
        np.testing.assert_allclose(data.oMf[frame].homogeneous, target, atol=1e-6)


def test_numeric_ik_is_deterministic(ur5):
    model, frame = ur5
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.full(model.nq, 0.4))
    target = data.oMf[frame].homogeneous
    a = numeric_ik(model, frame, target, seed=7)
    b = numeric_ik(model, frame, target, seed=7)
    np.testing.assert_array_equal(a, b)


def test_numeric_ik_unreachable_and_malformed(ur5):
    model, frame = ur5
    target = np.eye(4)
    target[:3, 3] = [3.0, 0.0, 0.5]  # the UR5 reaches about 0.95 m
    with pytest.raises(UnreachableLocationError, match="'far'") as info:
        numeric_ik(model, frame, target, starts=3, max_iter=100, name="far")
    assert info.value.distance > 1.5
    assert info.value.unit == "m"
    bad = np.eye(4)
    bad[0, 0] = 2.0
    with pytest.raises(InvalidInputError, match="rigid transform"):
        numeric_ik(model, frame, bad, name="bad")


def _arm_urdf(path: Path) -> Path:
    """A 6R arm with sphere solids (no meshes): z, y, y, z, y, z axes, 1.08 m long."""
    inertial = (
        '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0"'
        ' izz="0.01"/></inertial><collision><geometry><sphere radius="0.03"/></geometry>'
        "</collision>"
    )
    offsets = ["0 0 0.1", "0 0.1 0", "0 0 0.4", "0 0 0.35", "0 0 0.1", "0 0 0.08"]
    axes = ["0 0 1", "0 1 0", "0 1 0", "0 0 1", "0 1 0", "0 0 1"]
    parts = ['<?xml version="1.0"?>', '<robot name="arm6">', f'<link name="l0">{inertial}</link>']
    for i, (xyz, axis) in enumerate(zip(offsets, axes, strict=True), start=1):
        parts += [
            f'<link name="l{i}">{inertial}</link>',
            f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>'
            '<limit lower="-3.1" upper="3.1" effort="100" velocity="3"/></joint>',
        ]
    parts += [
        f'<link name="tool0">{inertial}</link>',
        '<joint name="tool_joint" type="fixed"><parent link="l6"/><child link="tool0"/>'
        '<origin xyz="0 0 0.05"/></joint>',
        "</robot>",
    ]
    path.write_text("\n".join(parts))
    return path


def test_solve_location_of_a_six_axis_robot_is_numeric(tmp_path):
    robot = Robot.from_urdf(_arm_urdf(tmp_path / "arm6.urdf"), tool_frame="tool0")
    with pytest.raises(RobotModelError, match="not a SCARA"):
        ScaraGeometry.of(robot)
    target = robot.tool_pose(np.array([0.4, -0.6, 1.1, 0.3, 0.7, -0.2]))
    q, elbow = solve_location(robot, target, name="bin")
    assert elbow is None
    np.testing.assert_allclose(robot.tool_pose(q), target, atol=1e-6)
    with pytest.raises(InvalidInputError, match="only for SCARA"):
        solve_location(robot, target, elbow="righty", name="bin")
