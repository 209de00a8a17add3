"""Real robots from example-robot-data (UR5, Panda, Kinova Jaco2): package:// meshes,
continuous and mimic joints, locked joints, the tool frame, sound mesh collision.

References are independent of the code under test: Pinocchio's own models of the same
URDFs (Pinocchio's RUBZ joints for continuous joints, no mimic), coal against the raw
meshes, and a ray-parity test for "inside a mesh".
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
import pytest

from adept_traj.cli import main
from adept_traj.collision import CollisionChecker, SelfCollision
from adept_traj.errors import RobotModelError, SceneError
from adept_traj.optimise import plan
from adept_traj.problem import CONSTRAINT_KINDS, TrajectoryProblem, local_constraints
from adept_traj.results import PlanningResult, RobotInfo
from adept_traj.robot import Robot, installed_data_dirs
from adept_traj.scene import Box, FixedPose, Obstacle, Scene, Sphere

ROBOTS = next(
    (
        d / "example-robot-data" / "robots"
        for d in installed_data_dirs()
        if (d / "example-robot-data" / "robots").is_dir()
    ),
    None,
)
pytestmark = pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
UR5 = ROBOTS / "ur_description/urdf/ur5_robot.urdf" if ROBOTS else None
PANDA = ROBOTS / "panda_description/urdf/panda.urdf" if ROBOTS else None
JACO = ROBOTS / "kinova_description/robots/kinova.urdf" if ROBOTS else None


@pytest.fixture(scope="module")
def ur5() -> Robot:
    return Robot.from_urdf(UR5)


def _pin_reference(path: Path) -> tuple[pin.Model, pin.GeometryModel]:
    """Pinocchio's own model of the URDF (continuous joints as RUBZ, mimic joints free)."""
    share = ROBOTS.parents[1]
    model = pin.buildModelFromUrdf(str(path))
    geom = pin.buildGeomFromUrdf(model, str(path), pin.COLLISION, package_dirs=[str(share)])
    return model, geom


def _joint_poses(model: pin.Model, q: np.ndarray) -> np.ndarray:
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    return np.array([m.homogeneous for m in data.oMi])


def test_package_meshes_are_found_without_ros_package_path(monkeypatch, ur5: Robot) -> None:
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    robot = Robot.from_urdf(UR5)
    assert robot.package_dirs == (ROBOTS.parents[1].resolve(),)
    assert robot.nq == 6
    assert len(robot.mesh_hulls) == 7  # seven link meshes (and a box)


def test_a_missing_package_mesh_names_the_folders_searched(tmp_path: Path) -> None:
    text = UR5.read_text().replace("package://example-robot-data/", "package://no-such-pkg/")
    path = tmp_path / "ur5.urdf"
    path.write_text(text)
    with pytest.raises(RobotModelError, match=r"no-such-pkg.*not found in the package folders"):
        Robot.from_urdf(path)
    (tmp_path / "no-such-pkg").symlink_to(ROBOTS.parent)  # the package, found by package_dirs
    robot = Robot.from_urdf(path, package_dirs=[tmp_path])
    assert robot.package_dirs == (tmp_path.resolve(),)


def test_a_continuous_joint_has_one_angle_coordinate(tmp_path: Path) -> None:
    planar = Path(__file__).resolve().parents[2] / "examples" / "data" / "planar_2link.urdf"
    text = planar.read_text().replace('type="revolute"', 'type="continuous"', 1)
    path = tmp_path / "continuous.urdf"
    path.write_text(text)
    robot = Robot.from_urdf(path)
    reference = pin.buildModelFromUrdf(str(path))  # Pinocchio: (cos θ, sin θ) for it
    assert (robot.nq, reference.nq) == (2, 3)
    assert (robot.limits.lower[0], robot.limits.upper[0]) == (-2 * np.pi, 2 * np.pi)
    q = np.random.default_rng(2).uniform(-7.0, 7.0, (20, 2))
    q[:, 1] = np.clip(q[:, 1], robot.limits.lower[1], robot.limits.upper[1])
    poses = robot.kinematics.joint_poses(q)
    for k in range(len(q)):
        q_ref = np.array([np.cos(q[k, 0]), np.sin(q[k, 0]), q[k, 1]])
        np.testing.assert_allclose(poses[k], _joint_poses(reference, q_ref), atol=1e-12)
    # without a <limit> element: unlimited speed and effort, as Pinocchio reads it
    bare = tmp_path / "bare.urdf"
    bare.write_text(re.sub(r"<limit [^>]*/>", "", text, count=1))
    unlimited = Robot.from_urdf(bare).limits
    assert (unlimited.velocity[0], unlimited.torque[0]) == (np.inf, np.inf)
    assert unlimited.upper[0] == 2 * np.pi


@pytest.mark.slow
def test_continuous_joints_of_the_jaco2_have_one_angle_coordinate() -> None:
    robot = Robot.from_urdf(JACO)
    reference, _ = _pin_reference(JACO)
    assert (robot.nq, reference.nq) == (6, 9)  # three continuous joints: (cos, sin) in Pinocchio
    continuous = [reference.joints[i].nq == 2 for i in range(1, reference.njoints)]
    assert np.array_equal(robot.limits.upper[continuous], np.full(3, 2 * np.pi))
    assert np.array_equal(robot.limits.lower[continuous], np.full(3, -2 * np.pi))
    rng = np.random.default_rng(3)
    q = rng.uniform(np.maximum(robot.limits.lower, -7), np.minimum(robot.limits.upper, 7), (20, 6))
    poses = robot.kinematics.joint_poses(q)
    for k in range(len(q)):
        q_ref = np.concatenate(
            [[np.cos(v), np.sin(v)] if c else [v] for v, c in zip(q[k], continuous)]
        )
        np.testing.assert_allclose(poses[k], _joint_poses(reference, q_ref), atol=1e-12)


def test_mimic_fingers_follow_their_leader() -> None:
    robot = Robot.from_urdf(PANDA)
    reference, _ = _pin_reference(PANDA)
    assert (robot.nq, reference.nq) == (8, 9)
    assert robot.joint_names[-1] == "panda_finger_joint1"
    rng = np.random.default_rng(4)
    q = rng.uniform(robot.limits.lower, robot.limits.upper, (20, 8))
    poses = robot.kinematics.joint_poses(q)
    for k in range(len(q)):
        q_ref = np.concatenate([q[k], q[k, -1:]])  # finger 2 mimics finger 1 (multiplier 1)
        np.testing.assert_allclose(poses[k], _joint_poses(reference, q_ref), atol=1e-12)
    # The Jacobian sums a mimic's motion into its leader's column: central differences of
    # the right finger (moved by the mimic joint only) against it.
    finger = Robot.from_urdf(PANDA, tool_frame="panda_rightfinger")
    eps = 1e-6
    dq = np.zeros(8)
    dq[-1] = eps
    moved = finger.tool_pose(q + dq)[:, :3, 3] - finger.tool_pose(q - dq)[:, :3, 3]
    column = finger.tool_jacobian(q)[:, :3, -1]
    np.testing.assert_allclose(column, moved / (2 * eps), atol=1e-8)
    assert np.linalg.norm(column, axis=1).min() > 0.99  # a prismatic finger: unit speed


def test_locked_joints_are_fixed_at_their_value(ur5: Robot) -> None:
    robot = Robot.from_urdf(UR5, locked_joints={"wrist_3_joint": 0.3})
    assert robot.nq == 5
    assert "wrist_3_joint" not in robot.joint_names
    q = np.random.default_rng(5).uniform(-2, 2, (10, 5))
    full = np.concatenate([q, np.full((10, 1), 0.3)], axis=1)
    np.testing.assert_allclose(robot.tool_pose(q), ur5.tool_pose(full), atol=1e-12)
    with pytest.raises(RobotModelError, match=r"locked joint 'nope'.*shoulder_pan_joint"):
        Robot.from_urdf(UR5, locked_joints={"nope": 0.0})


def test_an_unknown_tool_frame_lists_the_frames() -> None:
    with pytest.raises(RobotModelError, match=r"no frame 'tcp'.*'tool0'"):
        Robot.from_urdf(UR5, tool_frame="tcp")
    assert Robot.from_urdf(UR5, tool_frame="wrist_2_link").tool_frame == "wrist_2_link"


def _inside(point: np.ndarray, triangles: np.ndarray, direction: np.ndarray) -> bool:
    """Ray-parity test (Möller–Trumbore): is ``point`` inside the closed mesh?"""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    e1, e2 = b - a, c - a
    p = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-12
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = point - a
    u = np.einsum("ij,ij->i", s, p) * inv
    qv = np.cross(s, e1)
    v = (qv @ direction) * inv
    t = np.einsum("ij,ij->i", e2, qv) * inv
    hits = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    return bool(hits.sum() % 2)


def test_an_obstacle_inside_a_link_mesh_is_a_collision(ur5: Robot) -> None:
    _, raw = _pin_reference(UR5)
    k = [g.name for g in raw.geometryObjects].index("forearm_link_0")
    mesh = raw.geometryObjects[k].geometry
    vertices = np.asarray(mesh.vertices())
    index = np.array(
        [[t[0], t[1], t[2]] for t in map(mesh.tri_indices, range(mesh.num_tris))], dtype=int
    )
    triangles = vertices[index]
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    local = 0.5 * (lo + hi)
    local[2] = lo[2] + 0.5 * (hi[2] - lo[2])
    for direction in np.eye(3):
        assert _inside(local, triangles, direction)  # the centre is inside the forearm
    q = np.array([0.3, -1.0, 1.2, -0.5, 0.4, 0.0])
    pose = ur5.geometry_poses(q)[k]
    centre = pose[:3, :3] @ local + pose[:3, 3]
    ball = Obstacle("ball", Sphere(0.01), FixedPose.from_xyz_rpy(tuple(centre)))
    checker = CollisionChecker(ur5, Scene(obstacles=(ball,)))
    d = checker.distances(q[None], np.zeros(1), exact=True).distance[0, k, 0]
    assert d < -0.01
    # coal against the raw (hollow) mesh reports a clearance: what the hull fixes
    tf = coal.Transform3s(pose[:3, :3], pose[:3, 3])
    raw_d = coal.distance(
        mesh,
        tf,
        coal.Sphere(0.01),
        coal.Transform3s(np.eye(3), centre),
        coal.DistanceRequest(),
        coal.DistanceResult(),
    )
    assert raw_d > 0.01


def test_hull_distance_brackets_the_mesh_distance(ur5: Robot) -> None:
    _, raw = _pin_reference(UR5)
    k = [g.name for g in raw.geometryObjects].index("wrist_3_link_0")
    mesh, hull = raw.geometryObjects[k].geometry, ur5.collision_model.geometryObjects[k].geometry
    report = next(r for r in ur5.mesh_hulls if r.solid == "wrist_3_link_0")
    assert 0 < report.gap < 0.05
    rng = np.random.default_rng(6)
    ident = coal.Transform3s()
    for _ in range(200):
        centre = rng.uniform(-0.2, 0.2, 3)
        ball, at = coal.Sphere(0.005), coal.Transform3s(np.eye(3), centre)
        d_mesh = coal.distance(mesh, ident, ball, at, coal.DistanceRequest(), coal.DistanceResult())
        d_hull = coal.distance(hull, ident, ball, at, coal.DistanceRequest(), coal.DistanceResult())
        if d_mesh > 0:  # outside the mesh surface (inside points: the hull is in penetration)
            assert d_hull <= d_mesh + 1e-6  # coal's GJK tolerance
            assert d_mesh <= max(d_hull, 0.0) + report.gap + 1e-6


EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "data"


@pytest.mark.slow  # ≥ 3 s: kept out of the default tier (≤ 3 min)
def test_a_result_verifies_in_a_fresh_process_without_environment(tmp_path: Path) -> None:
    """The meshes come from a package only ``package_dirs`` names (not installed, no
    ROS_PACKAGE_PATH): the result records the folder, and ``verify`` finds it again."""
    (tmp_path / "pkgs").mkdir()
    (tmp_path / "pkgs" / "my_ur").symlink_to(ROBOTS / "ur_description")
    text = UR5.read_text().replace(
        "package://example-robot-data/robots/ur_description/", "package://my_ur/"
    )
    urdf = tmp_path / "ur5.urdf"
    urdf.write_text(text)
    robot = Robot.from_urdf(urdf, EXAMPLES / "ur5.toml", package_dirs=[tmp_path / "pkgs"])
    scene = Scene.from_file(EXAMPLES / "ur5_box.toml")
    problem = TrajectoryProblem(robot, scene, scene.start, scene.goal, n_knots=6)
    result = plan(problem, "nsga2", seed=1, pop_size=12, n_gen=3)
    result.save(tmp_path / "run")
    env = {"PATH": os.environ["PATH"], "PYTHONPATH": os.environ.get("PYTHONPATH", "")}
    done = subprocess.run(
        [sys.executable, "-m", "adept_traj.cli", "verify", str(tmp_path / "run")],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert "no mismatch" in done.stdout, done.stdout + done.stderr
    assert "not found" not in done.stderr


def test_plan_refuses_a_start_of_the_wrong_joint_count(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["plan", "--scene", str(EXAMPLES / "ur5_box.toml"), "--start", "0,0,0,0", "--out", "x"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "start must hold 6 joint values for robot 'ur5'" in err


@pytest.mark.slow
def test_the_command_line_plans_the_robot_a_scene_file_names(tmp_path: Path) -> None:
    out = tmp_path / "run"
    argv = ["plan", "--scene", str(EXAMPLES / "ur5_box.toml"), "--pop", "16", "--gens", "4"]
    assert main([*argv, "--out", str(out), "--quiet", "--no-html", "--no-plots"]) == 0
    result = PlanningResult.load(out)
    assert result.robot.name == "ur5"
    assert len(result.robot.joint_names) == 6
    assert main(["verify", str(out)]) in (0, 1)  # 1: a certificate failure, reported


@pytest.mark.slow  # ≥ 3 s: kept out of the default tier (≤ 3 min)
def test_missing_acceleration_and_jerk_limits_warn(ur5: Robot) -> None:
    """(verify's "no limit" for such joints: tests/cli/test_cli.py)"""
    scene = Scene.from_file(EXAMPLES / "ur5_box.toml")
    problem = TrajectoryProblem(ur5, scene, scene.start, scene.goal, n_knots=6)
    with pytest.warns(UserWarning, match=r"no acceleration limit for joint\(s\) shoulder_pan"):
        plan(problem, "nsga2", seed=1, pop_size=8, n_gen=1, max_certify=1)


def _reference_self_distance(robot: Robot, q: np.ndarray, a: str, b: str) -> float:
    """coal distance of two solids placed by Pinocchio (not by the code under test)."""
    gm = robot.collision_model
    data, gdata = robot.model.createData(), gm.createData()
    pin.updateGeometryPlacements(robot.model, data, gm, gdata, q)
    ia, ib = gm.getGeometryId(a), gm.getGeometryId(b)
    pa, pb = gdata.oMg[ia], gdata.oMg[ib]
    return coal.distance(
        gm.geometryObjects[ia].geometry, coal.Transform3s(pa.rotation, pa.translation),
        gm.geometryObjects[ib].geometry, coal.Transform3s(pb.rotation, pb.translation),
        coal.DistanceRequest(), coal.DistanceResult(),
    )  # fmt: skip


def test_self_collision_finds_a_folded_pose_and_skips_adjacent_links(ur5: Robot) -> None:
    srdf = ROBOTS / "ur_description/srdf/ur5.srdf"
    robot = Robot.from_urdf(UR5, srdf=srdf)
    check = SelfCollision(robot)
    names = {frozenset(p) for p in check.pair_names}
    # adjacent links (sharing a joint) are never checked, with or without the SRDF
    for a, b in [("upper_arm_link_0", "forearm_link_0"), ("shoulder_link_0", "upper_arm_link_0")]:
        assert frozenset((a, b)) not in names
        assert frozenset((a, b)) not in {frozenset(p) for p in SelfCollision(ur5).pair_names}
    # ... and they touch at every pose: they would be flagged
    home = np.array([0.0, -1.57, 0.0, -1.57, 0.0, 0.0])
    assert _reference_self_distance(robot, home, "upper_arm_link_0", "forearm_link_0") <= 0.0
    # the SRDF pairs are left out
    assert len(check.pair_names) < len(SelfCollision(ur5).pair_names)
    assert frozenset(("wrist_1_link_0", "wrist_3_link_0")) not in names
    folded = np.array([0.0, -1.57, 3.1, 0.0, 0.0, 0.0])  # the elbow folded flat
    d = check.distances(np.stack([home, folded]))
    assert d[0].min() > 0.0
    assert d[1].min() < 0.0
    k = int(np.argmin(d[1]))
    a, b = check.pair_names[k]
    assert d[1, k] == pytest.approx(_reference_self_distance(robot, folded, a, b), abs=1e-6)
    with pytest.raises(RobotModelError, match=r"link\(s\) \['nope'\] have no collision solid"):
        SelfCollision(robot, disabled=[("nope", "base_link")])


def test_a_permanent_floor_contact_is_allowed_by_name(ur5: Robot, tmp_path: Path) -> None:
    text = (EXAMPLES / "ur5_box.toml").read_text() + (
        '\n[[obstacle]]\nname = "floor"\nshape = "box"\nsize = [2.0, 2.0, 0.02]\n'
        "xyz = [0.0, 0.0, -0.005]\n"
    )
    touching = tmp_path / "floor.toml"
    touching.write_text(text)
    allowed = tmp_path / "allowed.toml"
    allowed.write_text('allowed_contacts = [["base_link", "floor"]]\n' + text)
    scene_touching, scene_allowed = Scene.from_file(touching), Scene.from_file(allowed)
    assert scene_allowed.allowed_contacts == (("base_link", "floor"),)
    assert Scene.from_dict(scene_allowed.to_dict()) == scene_allowed  # written and read back
    q = np.stack([scene_allowed.start, scene_allowed.goal])[None]
    t = np.zeros((1, 2))
    floor = scene_touching.obstacles[-1].name
    for exact in (False, True):
        touch = CollisionChecker(ur5, scene_touching).distances(q, t, exact=exact).distance
        free = CollisionChecker(ur5, scene_allowed).distances(q, t, exact=exact).distance
        k = [g.name for g in ur5.collision_model.geometryObjects].index("base_link_0")
        assert floor == "floor"
        assert touch[0, :, k, -1].max() < 0.0  # the base sits in the floor: a collision
        assert np.all(free[0, :, k, -1] == np.inf)  # allowed: never checked
        np.testing.assert_array_equal(free[0, :, :, 0], touch[0, :, :, 0])  # the box unchanged
    mind = CollisionChecker(ur5, scene_allowed).min_distances(q, t)
    assert mind.distance[0, -1] > 0.0  # the other links clear the floor
    with pytest.raises(SceneError, match=r"obstacle\(s\) \['nope'\]"):
        Scene(obstacles=scene_allowed.obstacles, allowed_contacts=(("base_link", "nope"),))


def test_a_result_records_locked_joints_srdf_and_mesh_folders(tmp_path: Path) -> None:
    srdf = ROBOTS / "ur_description/srdf/ur5.srdf"
    robot = Robot.from_urdf(UR5, srdf=srdf, locked_joints={"wrist_3_joint": 0.25})
    info = RobotInfo.of(robot)
    assert info.locked_joints == {"wrist_3_joint": 0.25}
    assert info.srdf == str(srdf.resolve())
    assert info.package_dirs == (str(ROBOTS.parents[1].resolve()),)
    again = info.load()
    assert again.joint_names == robot.joint_names
    assert again.disabled_pairs == robot.disabled_pairs
    q = np.zeros((1, 5))
    np.testing.assert_allclose(again.tool_pose(q), robot.tool_pose(q), atol=0.0)
    assert RobotInfo(**info.as_json()) == info  # what result.json holds rebuilds it


@pytest.mark.slow
@pytest.mark.parametrize("name", ["panda", "jaco2"])
def test_panda_and_a_robot_with_continuous_joints_plan_a_certified_move(name: str) -> None:
    path = PANDA if name == "panda" else JACO
    robot = Robot.from_urdf(path)
    box = Obstacle("box", Box((0.1, 0.1, 0.1)), FixedPose.from_xyz_rpy((0.0, -0.6, 0.8)))
    start = np.clip(np.zeros(robot.nq), robot.limits.lower + 0.3, robot.limits.upper - 0.3)
    goal = start.copy()
    goal[0] += 1.0
    if name == "panda":
        start[-1] = goal[-1] = 0.02  # the finger half open
    # the links against each other off: this clipped start has the Panda's wrist in contact
    # with its hand (self-collision is on by default since issue #26; every arm plans with it
    # from its own poses in tests/robot/test_robot_data.py)
    problem = TrajectoryProblem(
        robot, Scene(obstacles=(box,)), start, goal, n_knots=6, self_collision=False
    )
    with pytest.warns(UserWarning, match="no acceleration limit"):
        result = plan(problem, "nsga2", seed=1, pop_size=20, n_gen=5)
    assert result.certificate.feasible
    assert result.certificate.min_distance > problem.settings.margin


def test_the_robot_command_reports_self_collision_with_an_srdf(
    capsys: pytest.CaptureFixture[str],
) -> None:
    srdf = ROBOTS / "ur_description/srdf/ur5.srdf"
    folded = ["--start", "0,-1.57,0,-1.57,0,0", "--goal", "0,-1.57,3.1,-1.57,0,0"]
    assert main(["robot", "--robot", str(UR5), "--srdf", str(srdf), *folded]) == 0
    line = capsys.readouterr().out.splitlines()[-1]
    assert line.startswith("  self-collision: min distance -0.")
    assert main(["robot", "--srdf", str(srdf)]) == 2  # the AdeptOne XL: no --robot


def test_the_panda_torque_rows_have_a_jacobian_despite_its_mimic_finger() -> None:
    """Pinocchio's RNEA derivatives refuse mimic joints: the Panda's torque rows take
    central differences in the state; checked against central differences through x."""
    robot = Robot.from_urdf(PANDA)
    start = np.clip(np.zeros(robot.nq), robot.limits.lower + 0.3, robot.limits.upper - 0.3)
    start[-1] = 0.02
    goal = start + np.r_[1.0, -0.5, 0.4, 0.3, -0.2, 0.4, 0.5, 0.0]
    problem = TrajectoryProblem(robot, Scene(), start, goal, n_knots=6)
    x = 0.5 * (problem.xl + problem.xu)
    x[0] = 2.0 * problem.xl[0]
    lc = local_constraints(problem, x)
    torque = lc.kind == CONSTRAINT_KINDS.index("torque")
    assert torque.sum() > 0
    h = 1e-5
    for c in (0, 3, problem.n_var - 2):
        e = np.zeros(problem.n_var)
        e[c] = h
        fd = (
            local_constraints(problem, x + e).values[0]
            - local_constraints(problem, x - e).values[0]
        ) / (2 * h)
        np.testing.assert_allclose(lc.jacobian[0, torque, c], fd[torque], rtol=1e-4, atol=1e-6)
