"""Motion laws of machines (LinearMotion, RotationMotion, RecordedMotion): poses against the
closed forms evaluated by hand, point velocities against finite differences, the speed
bound of the continuous certificate against sampled speeds (sound and tight), scene files,
bad input, and the certificate's one-sided bound across a conveyor's wrap-around."""

from __future__ import annotations

import math

import numpy as np
import pytest

import adept_traj as at
from adept_traj.errors import MotionFileError, SceneError
from adept_traj.scene import (
    Box,
    LinearMotion,
    Obstacle,
    RecordedMotion,
    RotationMotion,
    Scene,
)

RNG = 2828


def _ball_points(rng, centre, radius, n):
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return centre + d * radius * rng.uniform(0.0, 1.0, (n, 1)) ** (1 / 3)


def _sampled_speed(law, local, t, h=1e-6):
    """Speeds (n,) of moving-frame points ``local`` (n, 3) at times t (n,) by central
    differences of the pose (a plain reference)."""
    a = np.einsum("nij,nj->ni", law.pose(t + h)[:, :3, :3], local) + law.pose(t + h)[:, :3, 3]
    b = np.einsum("nij,nj->ni", law.pose(t - h)[:, :3, :3], local) + law.pose(t - h)[:, :3, 3]
    return np.linalg.norm(a - b, axis=1) / (2 * h)


def test_linear_motion_by_hand():
    law = LinearMotion([0.3, 0.4, 0.0], wrap=2.0, phase=0.5)  # |v| = 0.5, u = (0.6, 0.8, 0)
    # s = (0.5 + 0.5 t) mod 2: t = 1 → 1.0; t = 3.5 → 2.25 → 0.25; t = -2 → -0.5 → 1.5
    want = {1.0: 1.0, 3.5: 0.25, -2.0: 1.5, 0.0: 0.5}
    poses = law.pose(np.array(list(want)))
    for (_t, s), pose in zip(want.items(), poses):
        np.testing.assert_allclose(pose[:3, 3], [0.6 * s, 0.8 * s, 0.0], atol=1e-15)
        np.testing.assert_array_equal(pose[:3, :3], np.eye(3))
    assert law.jump_interval == pytest.approx(4.0)
    free = LinearMotion([0.0, -0.2, 0.0])
    np.testing.assert_allclose(free.pose(10.0)[:3, 3], [0.0, -2.0, 0.0])
    assert free.jump_interval == math.inf
    centre, radius = law.swept_ball([0.1, 0, 0], 0.05)
    np.testing.assert_allclose(centre, [0.1 + 0.6, 0.8, 0.0])
    assert radius == pytest.approx(1.05)


def test_rotation_motion_by_hand():
    law = RotationMotion([0, 0, 2.0], [1.0, 0.0, 0.0], omega=0.5, angle=0.1)
    t = (math.pi - 0.2) / 1.0  # θ = 0.1 + 0.5 t = π/2
    pose = law.pose(t)
    np.testing.assert_allclose(
        pose[:3, :3] @ [2.0, 0, 0] + pose[:3, 3], [1.0, 1.0, 0.0], atol=1e-12
    )
    assert law.max_point_speed([2.0, 0.0, 5.0], 0.1) == pytest.approx(0.5 * 1.1)
    tilted = RotationMotion([1.0, 1.0, 0.0], [0.0, 0.0, 0.3], omega=-2.0)
    p = np.array([1.0, 0.0, 0.3])  # distance from the axis: |p × a| = 1/√2
    assert tilted.max_point_speed(p) == pytest.approx(2.0 / math.sqrt(2))
    pose = tilted.pose(np.array([0.0, math.pi / 2]))  # θ = -π: half a turn
    np.testing.assert_allclose(pose[1, :3, :3] @ p + pose[1, :3, 3], [0.0, 1.0, 0.3], atol=1e-12)


@pytest.fixture
def record_csv(tmp_path):
    path = tmp_path / "poses.csv"
    path.write_text(
        "t,x,y,z,roll,pitch,yaw\n"
        "# a machine slide with a turning spindle\n"
        "0.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0\n"
        "1.0, 0.4, 0.0, 0.5, 0.0, 0.0, 1.0\n"
        "3.0, 0.4, 0.6, 0.5, 0.0, 0.5, 1.0\n"
        "4.0, 0.0, 0.0, 0.5, 0.0, 0.0, 0.0\n",
        encoding="utf-8",
    )
    return path


def test_recorded_motion_by_hand(record_csv):
    law = RecordedMotion.from_csv(record_csv, periodic=True)
    # t = 0.5: halfway along segment 0: x = 0.2, yaw 0.5 (a pure yaw: Rz(0.5))
    pose = law.pose(0.5)
    np.testing.assert_allclose(pose[:3, 3], [0.2, 0.0, 0.5], atol=1e-15)
    c, s = math.cos(0.5), math.sin(0.5)
    np.testing.assert_allclose(pose[:3, :3], [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-12)
    # t = 2.0: halfway along segment 1: y = 0.3; the rotation Rz(1)·Ry(0.25)
    pose = law.pose(2.0)
    np.testing.assert_allclose(pose[:3, 3], [0.4, 0.3, 0.5], atol=1e-15)
    rz = np.array([[math.cos(1), -math.sin(1), 0], [math.sin(1), math.cos(1), 0], [0, 0, 1]])
    ry = np.array(
        [[math.cos(0.25), 0, math.sin(0.25)], [0, 1, 0], [-math.sin(0.25), 0, math.cos(0.25)]]
    )
    np.testing.assert_allclose(pose[:3, :3], rz @ ry, atol=1e-12)
    # periodic: t + 4 k is t
    t = np.array([0.3, 1.7, 3.9])
    np.testing.assert_allclose(law.pose(t + 8.0), law.pose(t), atol=1e-12)
    held = RecordedMotion.from_csv(record_csv)
    np.testing.assert_allclose(held.pose(-5.0), held.pose(0.0))
    np.testing.assert_allclose(held.pose(9.0), held.pose(4.0))
    # the bound, segment by segment: |Δo| / Δt + (rotation angle / Δt) · (|p| + r)
    rho = math.hypot(0.2, 0.1) + 0.05
    r2 = rz @ np.array(
        [[math.cos(0.5), 0, math.sin(0.5)], [0, 1, 0], [-math.sin(0.5), 0, math.cos(0.5)]]
    )
    angle2 = math.acos((np.trace(r2) - 1.0) / 2.0)  # the rotation back to the identity
    want = max(0.4 + 1.0 * rho, 0.3 + 0.25 * rho, math.sqrt(0.52) + angle2 * rho)
    assert law.max_point_speed([0.2, 0.1, 0.0], 0.05) == pytest.approx(want, rel=1e-12)


@pytest.mark.parametrize("which", ["linear", "rotation", "recorded"])
def test_speed_bound_is_sound_and_tight(which, record_csv):
    rng = np.random.default_rng(RNG)
    if which == "linear":
        law = LinearMotion([0.25, -0.1, 0.05], wrap=1.5)
        t = rng.uniform(0.0, 20.0, 4000)
        s = law.displacement(t)
        t = t[(s > 1e-3) & (s < 1.5 - 1e-3)]  # away from the jumps
    elif which == "rotation":
        law = RotationMotion([0.2, 0.0, 1.0], [0.5, 0.5, 0.0], omega=1.3)
        t = rng.uniform(-10.0, 10.0, 4000)
    else:
        law = RecordedMotion.from_csv(record_csv, periodic=True)
        t = rng.uniform(0.0, 8.0, 4000)
        t = t[np.abs(t % 4.0 - np.array([[0.0], [1.0], [3.0], [4.0]])).min(axis=0) > 1e-3]
    centre, radius = np.array([0.3, -0.2, 0.1]), 0.15
    local = _ball_points(rng, centre, radius, len(t))
    speeds = _sampled_speed(law, local, t)
    bound = law.max_point_speed(centre, radius)
    assert speeds.max() <= bound * (1 + 1e-6)
    # tight: points on the far side of the ball reach close to the bound
    far = _ball_points(rng, centre, radius, 20000)
    tt = rng.choice(t, 20000)
    assert _sampled_speed(law, far, tt).max() >= 0.9 * bound
    # the exact point velocity against the finite differences
    pose = law.pose(t)
    world = np.einsum("nij,nj->ni", pose[:, :3, :3], local) + pose[:, :3, 3]
    v = law.point_velocity(t, world)
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), speeds, rtol=1e-5, atol=1e-8)


def test_recorded_motion_bad_input(tmp_path, record_csv):
    bad = tmp_path / "bad.csv"
    bad.write_text("0,0,0,0,0,0,0\n1,0,0,0,0,0,0\n0.5,0,0,0,0,0,0\n", encoding="utf-8")
    with pytest.raises(MotionFileError, match=r"bad\.csv: line 3: time column not increasing"):
        RecordedMotion.from_csv(bad)
    bad.write_text("0,0,0,0,0,0\n1,0,0,0,0,0,0\n", encoding="utf-8")
    with pytest.raises(MotionFileError, match="line 1: expected 7 values"):
        RecordedMotion.from_csv(bad)
    bad.write_text("0,0,0,0,0,0,0\n1,0,0,x,0,0,0\n", encoding="utf-8")
    with pytest.raises(MotionFileError, match="line 2: not a number"):
        RecordedMotion.from_csv(bad)
    with pytest.raises(MotionFileError, match="not found"):
        RecordedMotion.from_csv(tmp_path / "none.csv")
    open_end = tmp_path / "open.csv"
    open_end.write_text("0,0,0,0,0,0,0\n1,1,0,0,0,0,0\n", encoding="utf-8")
    with pytest.raises(MotionFileError, match="periodic record must end"):
        RecordedMotion.from_csv(open_end, periodic=True)
    with pytest.raises(at.InvalidInputError, match="phase"):
        LinearMotion([1.0, 0, 0], wrap=1.0, phase=1.0)
    with pytest.raises(at.InvalidInputError, match="non-zero"):
        RotationMotion([0, 0, 1], [0, 0, 0], 0.0)


def test_scene_file_machines_round_trip(tmp_path, record_csv):
    text = (
        '[[obstacle]]\nname = "part"\nshape = "box"\nsize = [0.1, 0.1, 0.1]\n'
        "xyz = [0.5, 0.0, 0.1]\n"
        'motion = { kind = "linear", velocity = [0.2, 0.0, 0.0], wrap = 1.0, phase = 0.25 }\n'
        '[[obstacle]]\nname = "fixture"\nshape = "cylinder"\nradius = 0.05\nlength = 0.2\n'
        "xyz = [1.2, 0.0, 0.1]\n"
        'motion = { kind = "rotation", axis = [0, 0, 1], point = [1.0, 0.0, 0.0], omega = 0.4 }\n'
        '[[obstacle]]\nname = "slide"\nshape = "sphere"\nradius = 0.05\nxyz = [0.0, 0.0, 0.0]\n'
        'motion = { kind = "recorded", file = "poses.csv", periodic = true }\n'
    )
    (tmp_path / "cell.toml").write_text(text, encoding="utf-8")
    scene = Scene.from_file(tmp_path / "cell.toml")
    assert [type(ob.motion) for ob in scene.obstacles] == [
        LinearMotion,
        RotationMotion,
        RecordedMotion,
    ]
    assert Scene.from_dict(scene.to_dict()) == scene
    part = scene.obstacles[0]  # at t = 1: s = 0.25 + 0.2 = 0.45 m along +x from xyz
    np.testing.assert_allclose(part.pose(1.0)[:3, 3], [0.95, 0.0, 0.1], atol=1e-15)
    (tmp_path / "bad.toml").write_text(text.replace("poses.csv", "gone.csv"), "utf-8")
    with pytest.raises(MotionFileError, match=r"bad\.toml.*gone\.csv.*not found"):
        Scene.from_file(tmp_path / "bad.toml")
    with pytest.raises(SceneError, match="kind"):
        Scene.from_dict(
            {
                "obstacle": [
                    {
                        "name": "a",
                        "shape": "sphere",
                        "radius": 0.1,
                        "xyz": [0, 0, 0],
                        "motion": {"kind": "spin"},
                    }
                ]
            }
        )


def test_certificate_is_sound_across_a_wrap_around():
    """A conveyor part wrapping around above the paper's straight move: its closest
    approach (2 cm) is just before a jump (t = 2 s, then 29 cm), so the two-sided cone bound
    would claim about 15 cm on the interval holding the jump. The certificate's bound stays
    below the distance on a 5 kHz grid and is continuous; the jump interval is L / |v|."""
    paper = at.Scene.paper()
    law = LinearMotion([0.8, 0.0, 0.0], wrap=0.6, phase=0.2)  # jumps at 0.5 s + k 0.75 s
    offset = at.transforms.transform_from_xyz_rpy((0.45, 1.0, 0.85))
    part = Obstacle("part", Box([0.1, 0.1, 0.1]), law, offset)
    scene = Scene((part,), robot_base=paper.robot_base, start=paper.start, goal=paper.goal)
    problem = at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal)
    from adept_traj.certification import obstacle_jump_intervals

    assert obstacle_jump_intervals(problem)[0] == pytest.approx(0.75)
    x = problem.trajectory.straight_line(2.2)
    cert = at.certify(problem, x, rate_hz=200.0)
    t = np.linspace(0.0, float(x[0]), 11_001)
    q = problem.trajectory.sample(x, t / float(x[0]), orders=(0,)).q
    d = problem.checker.distances(q[None], t[None]).distance[0].min(axis=(1, 2))
    assert cert.guarantee == "continuous"
    assert 0.0 < cert.distance_bound <= d.min()
    before, after = d[np.searchsorted(t, 2.0) - 1], d[np.searchsorted(t, 2.0)]
    assert before < 0.03 < 0.2 < after  # the case the one-sided bound is for
