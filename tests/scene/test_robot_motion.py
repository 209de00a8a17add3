"""Another robot's planned motion as moving obstacles (adept_traj.scene.robot_motion): the
solids' poses against forward kinematics at joint values interpolated by hand, the speed
bound against sampled speeds, the CSV reader's errors, scene files, and robot B's move
certified around robot A's."""

from __future__ import annotations

import numpy as np
import pytest

import adept_traj as at
from adept_traj.errors import MotionFileError
from adept_traj.robot import RobotSource
from adept_traj.scene import Scene
from adept_traj.scene.robot_motion import JointTrajectory, robot_obstacles
from adept_traj.transforms import transform_from_xyz_rpy

BASE_A = transform_from_xyz_rpy((0.0, 0.9, 0.3))


def _move() -> JointTrajectory:
    t = np.array([0.0, 0.5, 1.0, 1.5])
    q = np.array([[-0.8, 0.6, 0.05, 0.0], [-0.3, 0.7, 0.1, 0.5], [0.3, 0.6, 0.1, 1.0],
                  [0.8, 0.6, 0.05, 0.0]])  # fmt: skip
    return JointTrajectory(t, q)


def test_poses_follow_the_interpolated_joints():
    robot = at.Robot.adept_one_xl()
    obstacles = robot_obstacles("A", RobotSource(), _move(), BASE_A)
    assert [ob.name for ob in obstacles] == [
        f"A.{g.name}" for g in robot.collision_model.geometryObjects
    ]
    # t = 0.75: halfway between rows 1 and 2; t = -1 and 9: held at the ends
    q_mid = np.array([0.0, 0.65, 0.1, 0.75])
    for t, q in ((0.75, q_mid), (-1.0, _move().q[0]), (9.0, _move().q[-1])):
        want = BASE_A @ robot.geometry_poses(q[None])[0]
        for k, ob in enumerate(obstacles):
            np.testing.assert_allclose(ob.pose(t), want[k], atol=1e-12)


def test_speed_bound_is_sound():
    rng = np.random.default_rng(31)
    for ob in robot_obstacles("A", RobotSource(), _move(), BASE_A):
        centre, radius = ob.offset[:3, 3], ob.shape.bounding_radius
        bound = ob.motion.max_point_speed(centre, radius)
        d = rng.normal(size=(3000, 3))
        local = centre + radius * d / np.linalg.norm(d, axis=1, keepdims=True)
        t = rng.uniform(0.0, 1.5, 3000)
        t = t[np.abs(t[:, None] - np.array([0.0, 0.5, 1.0, 1.5])).min(axis=1) > 1e-4]
        h = 1e-6
        a, b = ob.pose(t + h), ob.pose(t - h)
        pa = np.einsum("nij,nj->ni", a[:, :3, :3], local[: len(t)]) + a[:, :3, 3]
        pb = np.einsum("nij,nj->ni", b[:, :3, :3], local[: len(t)]) + b[:, :3, 3]
        speed = np.linalg.norm(pa - pb, axis=1) / (2 * h)
        assert speed.max() <= bound * (1 + 1e-6) + 1e-9, ob.name


def test_joint_csv_errors(tmp_path):
    bad = tmp_path / "a.csv"
    bad.write_text("t,q_j1,q_j2,q_j3,q_j4\n0,0,0,0,0\n1,0,0,0,0\n0.5,0,0,0,0\n", "utf-8")
    with pytest.raises(MotionFileError, match=r"a\.csv: line 4: time column not increasing"):
        JointTrajectory.from_csv(bad)
    bad.write_text("time,x\n0,1\n", "utf-8")
    with pytest.raises(MotionFileError, match="header must start with 't'"):
        JointTrajectory.from_csv(bad)
    short = JointTrajectory(np.array([0.0, 1.0]), np.zeros((2, 3)))
    with pytest.raises(at.InvalidInputError, match="joint columns"):
        robot_obstacles("A", RobotSource(), short)


def test_scene_file_round_trip(tmp_path):
    move = _move()
    lines = ["t,q_joint1,q_joint2,q_joint3,q_joint4,tau_joint1"]
    lines += [",".join(map(repr, [float(t), *q.tolist(), 0.0])) for t, q in zip(move.times, move.q)]
    (tmp_path / "a_move.csv").write_text("\n".join(lines) + "\n", "utf-8")
    text = '[[robot_motion]]\nname = "A"\nxyz = [0.0, 0.9, 0.3]\ntrajectory = "a_move.csv"\n'
    (tmp_path / "cell.toml").write_text(text, "utf-8")
    scene = Scene.from_file(tmp_path / "cell.toml")
    assert len(scene.obstacles) == 7
    np.testing.assert_array_equal(scene.obstacles[0].motion.trajectory.q, move.q)
    assert Scene.from_dict(scene.to_dict()) == scene


@pytest.mark.slow  # about 6 s
def test_robot_b_certified_around_robot_a():
    """The paper's straight move (robot B) with robot A swinging its arm above B's cell:
    continuous guarantee, its bound below the exact distance on a 1 kHz grid."""
    paper = at.Scene.paper()
    obstacles = robot_obstacles("A", RobotSource(), _move(), BASE_A)
    scene = Scene(obstacles, robot_base=paper.robot_base, start=paper.start, goal=paper.goal)
    problem = at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal)
    x = problem.trajectory.straight_line(1.5)
    cert = at.certify(problem, x, rate_hz=500.0)
    t = np.linspace(0.0, 1.5, 1501)
    q = problem.trajectory.sample(x, t / 1.5, orders=(0,)).q
    d = problem.checker.distances(q[None], t[None], exact=True).distance[0].min(axis=(1, 2))
    assert cert.guarantee == "continuous"
    assert cert.distance_bound <= d.min() + 1e-9
    assert d.min() < 0.2  # A comes close
