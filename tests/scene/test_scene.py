"""Tests of adept_traj.scene.shapes, adept_traj.scene.motion_laws and adept_traj.scene.scene."""

from __future__ import annotations

import math
import re
import sys
from pathlib import Path

import coal
import numpy as np
import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

from adept_traj.errors import InputShapeError, InvalidInputError, SceneError
from adept_traj.scene import (
    Box,
    Capsule,
    Cylinder,
    FixedPose,
    Obstacle,
    PendulumMotion,
    Scene,
    SceneFileNotFoundError,
    Sphere,
    coal_transform,
    pendulum_obstacles,
)
from adept_traj.transforms import rotation_from_rpy, transform_from_xyz_rpy, xyz_rpy_from_transform

RNG = np.random.default_rng(20240611)

# The paper's pendulum: l = 1 m, v0 = 2 m/s, ω = 3.14 rad/s, g = 9.81 m/s².
L, V0, OMEGA, G = 1.0, 2.0, 3.14, 9.81
PIVOT = np.array([0.75, 1.15, 1.45])  # as in adept_traj/data/scenes/paper.toml


def paper_pendulum(**kw: object) -> PendulumMotion:
    args: dict[str, object] = {"pivot": PIVOT, "length": L, "v0": V0, "omega": OMEGA, "g": G}
    args.update(kw)
    return PendulumMotion(**args)  # type: ignore[arg-type]


def paper_formula_angle(t: float) -> float:
    """φ(t) written as in the docs: sign(cos ωt)·arccos(1 − h/l), h = (v0² − v²)/(2g)."""
    v = V0 * math.sin(OMEGA * t)
    h = (V0**2 - v**2) / (2 * G)
    return math.copysign(1.0, math.cos(OMEGA * t)) * math.acos(1 - h / L)


def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def coal_dist(shape1: object, pose1: np.ndarray, shape2: object, pose2: np.ndarray) -> float:
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    return coal.distance(
        shape1.to_coal(),  # type: ignore[attr-defined]
        coal_transform(pose1),
        shape2.to_coal(),  # type: ignore[attr-defined]
        coal_transform(pose2),
        req,
        res,
    )


# ============================================================================ shapes


def test_shape_dimensions_reach_coal() -> None:
    box = Box([0.4, 0.2, 0.3]).to_coal()
    assert isinstance(box, coal.Box)
    np.testing.assert_allclose(box.halfSide, [0.2, 0.1, 0.15])
    cyl = Cylinder(0.05, 0.8).to_coal()
    assert isinstance(cyl, coal.Cylinder)
    assert (cyl.radius, cyl.halfLength) == pytest.approx((0.05, 0.4))
    cap = Capsule(0.05, 0.8).to_coal()
    assert isinstance(cap, coal.Capsule)
    assert (cap.radius, cap.halfLength) == pytest.approx((0.05, 0.4))
    sph = Sphere(0.3).to_coal()
    assert isinstance(sph, coal.Sphere)
    assert sph.radius == pytest.approx(0.3)
    # a new coal object on every call
    s = Sphere(0.3)
    assert s.to_coal() is not s.to_coal()


def test_sphere_sphere_distance() -> None:
    for _ in range(5):
        r1, r2 = RNG.uniform(0.05, 0.5, 2)
        c1, c2 = RNG.uniform(-2, 2, (2, 3))
        expected = np.linalg.norm(c1 - c2) - r1 - r2
        d = coal_dist(
            Sphere(r1), transform_from_xyz_rpy(c1), Sphere(r2), transform_from_xyz_rpy(c2)
        )
        assert d == pytest.approx(expected, abs=1e-9)


def test_sphere_box_distance_rotated_box() -> None:
    size = np.array([0.4, 0.2, 0.3])
    rpy = np.array([0.3, -0.2, 1.1])
    box_pose = transform_from_xyz_rpy([0.5, -0.2, 0.1], rpy)
    for _ in range(10):
        # a point outside the box, in box coordinates
        local = RNG.uniform(-1.0, 1.0, 3)
        local[np.argmax(np.abs(local))] = math.copysign(0.9, local[np.argmax(np.abs(local))])
        closest = np.clip(local, -size / 2, size / 2)
        r = 0.1
        expected = np.linalg.norm(local - closest) - r
        centre = box_pose[:3, :3] @ local + box_pose[:3, 3]
        d = coal_dist(Box(size), box_pose, Sphere(r), transform_from_xyz_rpy(centre))
        assert d == pytest.approx(expected, abs=1e-8)


def test_box_box_distance_axis_aligned() -> None:
    # box A spans x in [-0.2, 0.2]; box B (size 0.6 along x) starts at x = 0.5
    a, b = Box([0.4, 0.2, 0.3]), Box([0.6, 0.1, 0.1])
    d = coal_dist(a, np.eye(4), b, transform_from_xyz_rpy([0.8, 0.0, 0.0]))
    assert d == pytest.approx(0.3, abs=1e-9)
    # corner to corner: gaps 0.1 (x), 0.2 (y), 0.0 (z) -> sqrt(0.05)
    d = coal_dist(a, np.eye(4), b, transform_from_xyz_rpy([0.6, 0.35, 0.0]))
    assert d == pytest.approx(math.sqrt(0.1**2 + 0.2**2), abs=1e-8)


def test_cylinder_and_capsule_axis_is_local_z_with_full_length() -> None:
    r_s = 0.1
    cyl, cap = Cylinder(0.05, 0.8), Capsule(0.05, 0.8)
    on_axis = transform_from_xyz_rpy([0.0, 0.0, 1.0])
    radial = transform_from_xyz_rpy([1.0, 0.0, 0.0])
    # cylinder: flat end at z = 0.4; side at radius 0.05
    assert coal_dist(cyl, np.eye(4), Sphere(r_s), on_axis) == pytest.approx(1.0 - 0.4 - r_s)
    assert coal_dist(cyl, np.eye(4), Sphere(r_s), radial) == pytest.approx(1.0 - 0.05 - r_s)
    # capsule: cap tip at z = 0.4 + 0.05
    assert coal_dist(cap, np.eye(4), Sphere(r_s), on_axis) == pytest.approx(
        1.0 - 0.45 - r_s, abs=1e-9
    )
    # tilted cylinder (axis along world x after Ry(π/2)): the sphere on world x faces its end
    tilted = transform_from_xyz_rpy([0, 0, 0], [0, math.pi / 2, 0])
    assert coal_dist(cyl, tilted, Sphere(r_s), radial) == pytest.approx(1.0 - 0.4 - r_s)


@pytest.mark.parametrize(
    ("shape", "extreme_points"),
    [
        (
            Box([0.4, 0.2, 0.3]),
            np.array(np.meshgrid(*[[-1, 1]] * 3)).reshape(3, -1).T * 0.5 * [0.4, 0.2, 0.3],
        ),
        (Sphere(0.3), np.array([[0.3, 0, 0], [0, 0, -0.3]])),
        (Cylinder(0.05, 0.8), np.array([[0.05, 0, 0.4], [0, -0.05, -0.4]])),
        (Capsule(0.05, 0.8), np.array([[0, 0, 0.45], [0, 0, -0.45]])),
    ],
)
def test_bounding_radius_is_tight(shape: object, extreme_points: np.ndarray) -> None:
    """The farthest points of each shape lie exactly on its bounding sphere."""
    radius = shape.bounding_radius  # type: ignore[attr-defined]
    np.testing.assert_allclose(np.linalg.norm(extreme_points, axis=1), radius, rtol=1e-12)
    # and coal agrees: a tiny sphere just outside the bounding sphere in a random
    # direction does not touch the shape
    for _ in range(20):
        u = RNG.normal(size=3)
        u /= np.linalg.norm(u)
        probe = transform_from_xyz_rpy(u * (radius + 1e-3 + 1e-6))
        assert coal_dist(shape, np.eye(4), Sphere(1e-3), probe) > 0.0


@pytest.mark.parametrize(
    ("make", "error"),
    [
        (lambda: Box([0.4, -0.2, 0.3]), InvalidInputError),
        (lambda: Box([0.4, 0.2]), InputShapeError),
        (lambda: Box([0.4, np.nan, 0.3]), InvalidInputError),
        (lambda: Sphere(0.0), InvalidInputError),
        (lambda: Sphere(np.inf), InvalidInputError),
        (lambda: Sphere([0.1, 0.2]), InputShapeError),
        (lambda: Sphere("big"), InvalidInputError),
        (lambda: Cylinder(0.1, -1.0), InvalidInputError),
        (lambda: Capsule(-0.1, 1.0), InvalidInputError),
    ],
)
def test_shape_validation(make: object, error: type[Exception]) -> None:
    with pytest.raises(error):
        make()  # type: ignore[operator]


def test_shapes_copy_inputs_and_are_read_only() -> None:
    size = np.array([0.4, 0.2, 0.3])
    box = Box(size)
    size[0] = 9.0
    assert box.size[0] == 0.4
    with pytest.raises(ValueError, match="read-only"):
        box.size[0] = 1.0
    assert Box([0.4, 0.2, 0.3]) == box
    assert hash(Box([0.4, 0.2, 0.3])) == hash(box)
    assert Box([0.4, 0.2, 0.31]) != box
    assert Sphere(0.2) != Cylinder(0.2, 1.0)


# ============================================================================ transforms


def test_rpy_is_urdf_convention_and_round_trips() -> None:
    for _ in range(20):
        rpy = RNG.uniform([-math.pi, -math.pi / 2, -math.pi], [math.pi, math.pi / 2, math.pi])
        xyz = RNG.uniform(-1, 1, 3)
        t = transform_from_xyz_rpy(xyz, rpy)
        np.testing.assert_allclose(
            t[:3, :3], rot_z(rpy[2]) @ rot_y(rpy[1]) @ rot_x(rpy[0]), atol=1e-14
        )
        np.testing.assert_array_equal(t[:3, 3], xyz)
        xyz2, rpy2 = xyz_rpy_from_transform(t)
        np.testing.assert_allclose(rpy2, rpy, atol=1e-12)
        np.testing.assert_array_equal(xyz2, xyz)
    # gimbal lock (both signs): the recovered angles give back the same rotation
    for pitch in (math.pi / 2, -math.pi / 2):
        t = transform_from_xyz_rpy([0, 0, 0], [0.4, pitch, 0.3])
        _, rpy = xyz_rpy_from_transform(t)
        np.testing.assert_allclose(rpy[1], pitch, atol=1e-7)
        np.testing.assert_allclose(rot_z(rpy[2]) @ rot_y(rpy[1]) @ rot_x(rpy[0]), t[:3, :3],
                                   atol=1e-12)  # fmt: skip


def test_transforms_are_batched() -> None:
    rpy = RNG.uniform(-1, 1, (5, 3))
    batch = rotation_from_rpy(rpy)
    assert batch.shape == (5, 3, 3)
    for i in range(5):
        np.testing.assert_array_equal(batch[i], rotation_from_rpy(rpy[i]))
    assert transform_from_xyz_rpy(np.zeros((2, 5, 3)), rpy).shape == (2, 5, 4, 4)
    xyz_b, rpy_b = xyz_rpy_from_transform(transform_from_xyz_rpy(np.zeros((2, 5, 3)), rpy))
    assert xyz_b.shape == rpy_b.shape == (2, 5, 3)
    np.testing.assert_allclose(rpy_b[1], rpy, atol=1e-12)


def test_transform_shapes_that_do_not_broadcast_are_input_errors() -> None:
    with pytest.raises(InputShapeError, match=r"xyz \(\.\.\., 3\) and rpy"):
        transform_from_xyz_rpy(np.zeros((2, 3)), np.zeros((3, 3)))


def test_fixed_pose() -> None:
    t = transform_from_xyz_rpy([0.1, 0.2, 0.3], [0.1, 0.2, 0.3])
    law = FixedPose(t)
    poses = law.pose(np.linspace(0, 1, 7))
    assert poses.shape == (7, 4, 4)
    np.testing.assert_array_equal(poses, np.broadcast_to(t, (7, 4, 4)))
    assert law.pose(0.5).shape == (4, 4)
    assert law.is_fixed
    t[0, 3] = 5.0  # the caller's array is not kept
    assert law.transform[0, 3] == 0.1
    with pytest.raises(InvalidInputError, match="rigid"):
        FixedPose(np.diag([2.0, 1.0, 1.0, 1.0]))
    with pytest.raises(InvalidInputError, match="rigid"):
        FixedPose(np.diag([1.0, 1.0, -1.0, 1.0]))  # a reflection
    with pytest.raises(InputShapeError):
        FixedPose(np.eye(3))


# ============================================================================ pendulum


def test_pendulum_extreme_at_t0() -> None:
    law = paper_pendulum()
    h = V0**2 / (2 * G)  # v(0) = 0: the bob is at its highest
    phi_max = math.acos(1 - h / L)
    assert law.angle(0.0) == pytest.approx(phi_max, abs=1e-14)
    assert law.max_angle == pytest.approx(phi_max, abs=1e-14)
    assert law.max_height == pytest.approx(h)
    expected = PIVOT + L * np.array([math.sin(phi_max), 0.0, -math.cos(phi_max)])
    np.testing.assert_allclose(law.bob_position(0.0), expected, atol=1e-14)
    assert law.bob_position(0.0)[2] - (PIVOT[2] - L) == pytest.approx(h, abs=1e-14)


def test_pendulum_bottom_and_other_extreme() -> None:
    law = paper_pendulum()
    t_bottom = (math.pi / 2) / OMEGA
    assert law.angle(t_bottom) == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(law.bob_position(t_bottom), PIVOT - [0, 0, L], atol=1e-12)
    assert law.angle(math.pi / OMEGA) == pytest.approx(-law.max_angle, abs=1e-12)
    assert law.angle(2 * math.pi / OMEGA) == pytest.approx(law.max_angle, abs=1e-12)
    assert law.period == pytest.approx(2 * math.pi / OMEGA)


def test_pendulum_matches_formula_and_symmetries() -> None:
    law = paper_pendulum()
    t = RNG.uniform(-3, 3, 50)
    expected = np.array([paper_formula_angle(x) for x in t])
    np.testing.assert_allclose(law.angle(t), expected, atol=1e-7)  # acos loses digits near 0
    np.testing.assert_allclose(law.angle(-t), law.angle(t), atol=1e-14)  # even in t
    np.testing.assert_allclose(law.angle(math.pi / OMEGA - t), -law.angle(t), atol=1e-12)
    np.testing.assert_allclose(law.height(t), (V0**2 - law.speed(t) ** 2) / (2 * G))
    # the bob height above its lowest point is h(t)
    bob = law.bob_position(t)
    np.testing.assert_allclose(bob[:, 2] - (PIVOT[2] - L), law.height(t), atol=1e-12)
    np.testing.assert_allclose(bob[:, 1], PIVOT[1])  # swing plane y = constant


def test_pendulum_angle_is_continuous() -> None:
    law = paper_pendulum()
    t = np.linspace(0.0, 2 * law.period, 200_001)
    dt = t[1] - t[0]
    phi = law.angle(t)
    # |dφ/dt| ≤ 2 a ω with a = v0 / (2 √(g l)), reached at the bottom
    bound = 2 * V0 / (2 * math.sqrt(G * L)) * OMEGA
    steps = np.abs(np.diff(phi))
    assert steps.max() <= bound * dt * (1 + 1e-6)
    assert steps.max() >= bound * dt * (1 - 1e-3)  # the bound is attained (not a flat law)
    # smooth through the bottom: second differences stay small (no kink)
    assert np.abs(np.diff(phi, 2)).max() <= 10 * bound * OMEGA * dt**2
    # the bob speed is close to the prescribed v(t) (small-amplitude pendulum)
    speed = L * np.abs(np.diff(phi)) / dt
    mid = 0.5 * (t[1:] + t[:-1])
    assert np.abs(speed - np.abs(law.speed(mid))).max() < 0.05


def test_pendulum_obstacles_rod_and_bob() -> None:
    law = paper_pendulum()
    rod, bob = pendulum_obstacles("p", law, bob_radius=0.08)
    assert (rod.name, bob.name) == ("p.rod", "p.bob")
    assert rod.shape == Cylinder(0.01, L)
    assert bob.shape == Sphere(0.08)
    t = np.linspace(0, 3, 61)
    rp, bp = rod.pose(t), bob.pose(t)
    np.testing.assert_allclose(bp[:, :3, 3], law.bob_position(t), atol=1e-14)
    # rod: centre at the middle of pivot-bob, z axis along the rod; its ends are the
    # pivot and the bob centre, so its length is preserved
    axis = rp[:, :3, 2]
    top = rp[:, :3, 3] + 0.5 * L * axis
    bottom = rp[:, :3, 3] - 0.5 * L * axis
    np.testing.assert_allclose(top, np.broadcast_to(PIVOT, top.shape), atol=1e-14)
    np.testing.assert_allclose(bottom, law.bob_position(t), atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(top - bottom, axis=1), L, atol=1e-14)
    # poses are rigid
    r = rp[:, :3, :3]
    np.testing.assert_allclose(
        np.swapaxes(r, 1, 2) @ r, np.broadcast_to(np.eye(3), r.shape), atol=1e-14
    )
    np.testing.assert_allclose(np.linalg.det(r), 1.0)


def test_scene_pendulums_by_name_in_obstacle_order() -> None:
    """Two pendulums (equal motion laws, other names), a lone obstacle on a pendulum law
    and a fixed box: one entry per pendulum name, the law of its first obstacle."""
    first, second, lone = paper_pendulum(), paper_pendulum(), paper_pendulum(omega=1.0)
    obstacles = (
        *pendulum_obstacles("b", second, bob_radius=0.08),
        Obstacle("box", Box([0.1, 0.1, 0.1])),
        Obstacle("swing", Sphere(0.05), lone),
        *pendulum_obstacles("a", first, bob_radius=0.05),
    )
    found = Scene(obstacles=obstacles).pendulums
    assert list(found) == ["b", "swing", "a"]
    assert found["b"] is second
    assert found["a"] is first
    assert found["swing"] is lone
    assert Scene(obstacles=(Obstacle("box", Box([0.1, 0.1, 0.1])),)).pendulums == {}


def test_pendulum_other_swing_axis() -> None:
    law = paper_pendulum(swing_axis=[0.0, -2.0, 0.0])
    np.testing.assert_array_equal(law.swing_axis, [0.0, -1.0, 0.0])
    bob = law.bob_position(np.linspace(0, 2, 41))
    np.testing.assert_allclose(bob[:, 0], PIVOT[0])
    assert bob[0, 1] == pytest.approx(PIVOT[1] - math.sin(law.max_angle))


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"v0": 7.0}, "v0"),  # v0² / (2g) = 2.5 m > 2 l
        ({"v0": -1.0}, "v0"),
        ({"length": 0.0}, "length"),
        ({"omega": 0.0}, "omega"),
        ({"g": -9.81}, "g"),
        ({"swing_axis": [0.0, 0.0, 1.0]}, "swing_axis"),
        ({"swing_axis": [0.0, 0.0, 0.0]}, "swing_axis"),
        ({"pivot": [0.0, 1.0]}, "pivot"),
    ],
)
def test_pendulum_validation(kwargs: dict[str, object], field: str) -> None:
    with pytest.raises(InvalidInputError, match=field):
        paper_pendulum(**kwargs)


def test_pendulum_at_its_limit_v0_squared_equals_4gl() -> None:
    law = paper_pendulum(v0=math.sqrt(4 * G * L))
    assert law.max_angle == pytest.approx(math.pi)
    assert np.isfinite(law.pose(np.linspace(0, 2, 11))).all()


# ============================================================================ swept balls


def _points_of(ob: Obstacle, t: np.ndarray) -> np.ndarray:
    """Extreme surface points of the obstacle's bounding sphere surface samples, (n, k, 3)."""
    poses = ob.pose(t)
    u = RNG.normal(size=(64, 3))
    u = u / np.linalg.norm(u, axis=1, keepdims=True) * ob.shape.bounding_radius
    return poses[:, None, :3, 3] + u[None]


@pytest.mark.parametrize("v0", [V0, 5.0])  # φ_max below and above π/2
def test_swept_ball_contains_the_moving_obstacle(v0: float) -> None:
    law = paper_pendulum(v0=v0)
    t = np.linspace(0, law.period, 2001)
    for ob in pendulum_obstacles("p", law, bob_radius=0.08):
        centre, radius = ob.swept_ball()
        dist = np.linalg.norm(_points_of(ob, t) - centre, axis=-1)
        assert dist.max() <= radius + 1e-12
        # and it is not grossly loose: within 1 cm of the farthest sampled point
        assert dist.max() >= radius - 0.01


def test_swept_ball_of_bob_is_the_arc_ball() -> None:
    law = paper_pendulum()
    _, bob = pendulum_obstacles("p", law, bob_radius=0.08)
    centre, radius = bob.swept_ball()
    a = law.max_angle
    np.testing.assert_allclose(centre, PIVOT - [0, 0, L * math.cos(a)], atol=1e-14)
    assert radius == pytest.approx(L * math.sin(a) + 0.08)


def test_swept_ball_of_fixed_obstacle() -> None:
    pose = transform_from_xyz_rpy([0.1, 0.2, 0.3], [0.0, 0.0, 0.5])
    ob = Obstacle("b", Box([0.4, 0.2, 0.3]), FixedPose(pose), transform_from_xyz_rpy([1, 0, 0]))
    centre, radius = ob.swept_ball()
    np.testing.assert_allclose(centre, ob.pose(0.0)[:3, 3])
    assert radius == pytest.approx(ob.shape.bounding_radius)


# ============================================================================ scene


def example_scene() -> Scene:
    law = paper_pendulum(swing_axis=[1.0, 1.0, 0.0])
    return Scene(
        obstacles=(
            Obstacle(
                "box", Box([0.4, 0.2, 0.3]), FixedPose.from_xyz_rpy([1, 2, 3], [0.1, 0.2, 0.3])
            ),
            Obstacle("ball", Sphere(0.1), FixedPose.from_xyz_rpy([0.5, 0.0, 0.2])),
            Obstacle("can", Cylinder(0.1, 0.5), FixedPose.from_xyz_rpy([0, 0.5, 0], [1.0, 0, 0])),
            Obstacle("pill", Capsule(0.05, 0.3), FixedPose.from_xyz_rpy([0, -0.5, 0])),
            *pendulum_obstacles("swing", law, bob_radius=0.1, rod_radius=0.02),
        ),
        robot_base=transform_from_xyz_rpy([0.1, -0.2, 0.05], [0.0, 0.0, 0.7]),
        start=[0.1682, 1.3849, 0.1, -0.7555],
        goal=[-0.7610, 0.2450, 0.1, 1.0095],
        name="example",
    )


def test_scene_queries() -> None:
    scene = example_scene()
    assert scene.names == ("box", "ball", "can", "pill", "swing.rod", "swing.bob")
    assert [ob.name for ob in scene.moving] == ["swing.rod", "swing.bob"]
    assert [ob.name for ob in scene.fixed] == ["box", "ball", "can", "pill"]
    assert scene.obstacle("ball").shape == Sphere(0.1)
    with pytest.raises(InvalidInputError, match="nope"):
        scene.obstacle("nope")


def test_obstacle_poses_batched_equals_loop() -> None:
    scene = example_scene()
    t = np.linspace(0.0, 2.5, 13)
    poses = scene.obstacle_poses(t)
    assert poses.shape == (6, 13, 4, 4)
    for i, ob in enumerate(scene.obstacles):
        for k, tk in enumerate(t):
            np.testing.assert_allclose(poses[i, k], ob.pose(float(tk)), atol=1e-15)
    base = scene.obstacle_poses(t, in_base_frame=True)
    np.testing.assert_allclose(scene.robot_base @ base, poses, atol=1e-14)
    assert Scene().obstacle_poses(t).shape == (0, 13, 4, 4)


def test_scene_validation_in_python() -> None:
    ball = Obstacle("a", Sphere(0.1))
    with pytest.raises(SceneError, match="'a'"):
        Scene(obstacles=(ball, Obstacle("a", Box([1, 1, 1]))))
    with pytest.raises(SceneError, match="together"):
        Scene(obstacles=(ball,), start=[0.0, 0.0])
    with pytest.raises(SceneError, match="same length"):
        Scene(start=[0.0, 0.0], goal=[0.0])
    with pytest.raises(InvalidInputError):
        Scene(obstacles=(ball, "not an obstacle"))  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="robot_base"):
        Scene(robot_base=np.ones((4, 4)))
    with pytest.raises(InvalidInputError, match="name"):
        Obstacle("", Sphere(0.1))
    start = np.array([0.0, 1.0])
    scene = Scene(start=start, goal=[1.0, 2.0])
    start[0] = 5.0
    assert scene.start is not None
    assert scene.start[0] == 0.0
    assert not scene.start.flags.writeable


def test_to_dict_round_trip() -> None:
    scene = example_scene()
    again = Scene.from_dict(scene.to_dict())
    assert again.names == scene.names
    t = np.linspace(0, 3, 31)
    np.testing.assert_allclose(again.obstacle_poses(t), scene.obstacle_poses(t), atol=1e-14)
    np.testing.assert_allclose(again.robot_base, scene.robot_base, atol=1e-15)
    assert [type(o.shape) for o in again.obstacles] == [type(o.shape) for o in scene.obstacles]
    assert again.obstacle("swing.bob").motion == scene.obstacle("swing.bob").motion
    np.testing.assert_array_equal(again.start, scene.start)  # type: ignore[arg-type]
    np.testing.assert_array_equal(again.goal, scene.goal)  # type: ignore[arg-type]
    assert again.name == "example"
    # rotations go through rpy: later trips agree to rounding
    third = Scene.from_dict(again.to_dict())
    np.testing.assert_allclose(third.obstacle_poses(t), again.obstacle_poses(t), atol=1e-15)


def test_save_and_load(tmp_path: Path) -> None:
    scene = example_scene()
    path = tmp_path / "example.toml"
    scene.save(path)
    text = path.read_text(encoding="utf-8")
    assert text.startswith("# adept_traj scene file")
    assert tomllib.loads(text) == scene.to_dict()  # an independent TOML reader
    loaded = Scene.from_file(path)
    assert loaded.to_dict() == Scene.from_dict(scene.to_dict()).to_dict()
    paper = Scene.paper()
    paper.save(tmp_path / "paper.toml")
    assert Scene.from_file(tmp_path / "paper.toml") == paper  # exact (no rotations)


def test_to_dict_refuses_what_it_cannot_write() -> None:
    law = paper_pendulum()
    lone = Obstacle("lonely", Sphere(0.1), law)
    with pytest.raises(SceneError, match="lonely"):
        Scene(obstacles=(lone,)).to_dict()
    rod, _ = pendulum_obstacles("p", law, bob_radius=0.1)
    with pytest.raises(SceneError, match=r"p\.rod"):
        Scene(obstacles=(rod,)).to_dict()


def test_paper_scene() -> None:
    scene = Scene.paper()
    assert scene.name == "paper"
    assert scene.names == ("cube1", "cube2", "pendulum.rod", "pendulum.bob")
    extents = {
        "cube1": ([0.7, 0.6, 0.0], [1.1, 0.8, 0.30]),
        "cube2": ([0.7, 1.27, 0.0], [1.1, 1.47, 0.21]),
    }
    for name, (lo, hi) in extents.items():
        ob = scene.obstacle(name)
        assert not ob.is_moving
        assert isinstance(ob.shape, Box)
        pose = ob.pose(0.0)
        np.testing.assert_array_equal(pose[:3, :3], np.eye(3))
        np.testing.assert_allclose(pose[:3, 3] - ob.shape.size / 2, lo, atol=1e-15)
        np.testing.assert_allclose(pose[:3, 3] + ob.shape.size / 2, hi, atol=1e-15)
    law = scene.obstacle("pendulum.bob").motion
    assert isinstance(law, PendulumMotion)
    assert (law.length, law.v0, law.omega, law.g) == (1.0, 2.0, 3.14, 9.81)
    np.testing.assert_array_equal(law.swing_axis, [1.0, 0.0, 0.0])
    assert scene.obstacle("pendulum.bob").shape == Sphere(0.08)
    assert scene.obstacle("pendulum.rod").shape == Cylinder(0.01, 1.0)
    # The reconstruction (docs/paper-scenario.md): theta1, theta2, theta4 as printed.
    np.testing.assert_array_equal(scene.start[[0, 1, 3]], [0.1682, 1.3849, -0.7555])
    np.testing.assert_array_equal(scene.goal[[0, 1, 3]], [-0.7610, 0.2450, 1.0095])
    assert 0.0 <= scene.start[2] <= 0.203
    assert 0.0 <= scene.goal[2] <= 0.203


# ============================================================================ bad files

GOOD = """\
name = "t"
[robot]
xyz = [0.0, 0.0, 0.0]
[[obstacle]]
name = "cube1"
shape = "box"
size = [0.4, 0.2, 0.3]
xyz = [0.9, 0.7, 0.15]
[[pendulum]]
name = "pend"
pivot = [0.9, 1.0, 1.3]
length = 1.0
v0 = 2.0
omega = 3.14
bob_radius = 0.08
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad_scene.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_good_template_loads(tmp_path: Path) -> None:
    scene = Scene.from_file(write(tmp_path, GOOD))
    assert scene.names == ("cube1", "pend.rod", "pend.bob")
    assert scene.obstacle("pend.rod").shape == Cylinder(0.01, 1.0)  # default rod radius
    assert scene.obstacle("pend.bob").motion.g == 9.81  # type: ignore[attr-defined]


IN_CUBE = "(in obstacle 'cube1')"
IN_PEND = "(in pendulum 'pend')"
SIZE_1 = "field 'obstacle[0].size[1]': must be a finite number > 0 [m]; got"


@pytest.mark.parametrize(
    ("old", "new", "fragments"),
    [
        ("size = [0.4, 0.2, 0.3]", "size = [0.4, -0.2, 0.3]", [f"{SIZE_1} -0.2 {IN_CUBE}"]),
        (
            "size = [0.4, 0.2, 0.3]",
            "size = [0.4, 0.2]",
            [
                "field 'obstacle[0].size': must be a list of 3 finite numbers > 0 [m]; "
                f"got a list of 2: [0.4, 0.2] {IN_CUBE}"
            ],
        ),
        ("size = [0.4, 0.2, 0.3]", 'size = [0.4, "a", 0.3]', [f"{SIZE_1} the string 'a'"]),
        ("size = [0.4, 0.2, 0.3]", "size = [0.4, true, 0.3]", [f"{SIZE_1} true {IN_CUBE}"]),
        ("size = [0.4, 0.2, 0.3]", "size = [0.4, nan, 0.3]", [f"{SIZE_1} nan {IN_CUBE}"]),
        (
            "size = [0.4, 0.2, 0.3]\n",
            "",
            [
                "field 'obstacle[0].size': missing; must be a list of 3 finite numbers > 0 [m] "
                + IN_CUBE
            ],
        ),
        (
            'shape = "box"',
            'shape = "cone"',
            [
                "field 'obstacle[0].shape': must be one of 'box', 'sphere', 'cylinder', "
                f"'capsule', 'mesh', 'cloud'; got the string 'cone' {IN_CUBE}"
            ],
        ),
        ('shape = "box"\n', "", ["field 'obstacle[0].shape': missing; must be one of 'box'"]),
        ('name = "cube1"\n', "", ["field 'obstacle[0].name': missing; must be a non-empty string"]),
        (
            "xyz = [0.9, 0.7, 0.15]",
            "xyz = [0.9, 0.7, 0.15]\ncolour = 1",
            [
                "field 'obstacle[0].colour': unknown field; allowed fields: 'name', 'shape'",
                IN_CUBE,
            ],
        ),
        (
            "xyz = [0.9, 0.7, 0.15]",
            "xyz = [0.9, 0.7, 0.15]\nradius = 1.0",
            ["field 'obstacle[0].radius': unknown field", "'size', 'min', 'max' " + IN_CUBE],
        ),
        (
            'name = "t"',
            'name = "t"\nunits = "mm"',
            ["field 'units': unknown field; allowed fields: 'name', 'robot', 'task', 'obstacle'"],
        ),
        ("[robot]", "[robot]\nz = 1.0", ["field 'robot.z': unknown field; allowed fields: 'xyz'"]),
        (
            "xyz = [0.0, 0.0, 0.0]",
            'xyz = "origin"',
            ["field 'robot.xyz': must be a list of 3 finite numbers [m]; got the string 'origin'"],
        ),
        (
            "[[pendulum]]",
            '[[obstacle]]\nname = "cube1"\nshape = "sphere"\nradius = 0.1\nxyz = [0, 0, 0]\n'
            "[[pendulum]]",
            ["'cube1'", "'name'", "unique"],
        ),
        (
            "[[pendulum]]",
            '[[obstacle]]\nname = "pend.bob"\nshape = "sphere"\nradius = 0.1\nxyz = [0, 0, 0]\n'
            "[[pendulum]]",
            ["'pend.bob'", "'name'", "unique"],
        ),
        ("v0 = 2.0", "v0 = 7.0", ["field 'pendulum[0]': ", "v0", IN_PEND]),
        (
            "v0 = 2.0",
            'v0 = "fast"',
            [
                "field 'pendulum[0].v0': must be a finite number ≥ 0 [m/s]; "
                f"got the string 'fast' {IN_PEND}"
            ],
        ),
        (
            "length = 1.0",
            "length = -1.0",
            [f"field 'pendulum[0].length': must be a finite number > 0 [m]; got -1.0 {IN_PEND}"],
        ),
        (
            "bob_radius = 0.08\n",
            "",
            [f"field 'pendulum[0].bob_radius': missing; must be a finite number > 0 [m] {IN_PEND}"],
        ),
        (
            "bob_radius = 0.08",
            "bob_radius = 0.08\nswing_axis = [0, 0, 1]",
            ["field 'pendulum[0]': ", "swing_axis", IN_PEND],
        ),
        (
            "bob_radius = 0.08",
            "bob_radius = 0.08\nmass = 1.0",
            ["field 'pendulum[0].mass': unknown field; allowed fields: 'name', 'pivot'", IN_PEND],
        ),
        (
            "size = [0.4, 0.2, 0.3]\nxyz = [0.9, 0.7, 0.15]",
            "min = [0.7, 0.6, 0.0]\nmax = [1.1, 0.6, 0.3]",
            [
                "field 'obstacle[0].max': must be greater than 'min' = [0.7, 0.6, 0.0] in every "
                f"axis [m]; got [1.1, 0.6, 0.3] {IN_CUBE}"
            ],
        ),
        (
            "size = [0.4, 0.2, 0.3]\nxyz = [0.9, 0.7, 0.15]",
            "min = [0.7, 0.6, 0.0]\nmax = [1.1, 0.8, 0.3]\nxyz = [0.0, 0.0, 0.0]",
            ["field 'obstacle[0].xyz': cannot be combined with 'min'/'max'", IN_CUBE],
        ),
        (
            "size = [0.4, 0.2, 0.3]\nxyz = [0.9, 0.7, 0.15]",
            "min = [0.7, 0.6, 0.0]",
            ["field 'obstacle[0].max': missing; must be a list of 3 finite numbers [m]", IN_CUBE],
        ),
        (
            'name = "t"',
            'name = "t"\n[task]\nstart = [0.0, 1.0]\ngoal = [1.0]',
            ["field 'task': 'start' and 'goal' must have the same length; got 2 and 1"],
        ),
        (
            "[[obstacle]]",
            "[obstacle]",
            ["field 'obstacle': must be an array of tables ([[obstacle]]); got a table"],
        ),
    ],
)
def test_bad_scene_files(tmp_path: Path, old: str, new: str, fragments: list[str]) -> None:
    assert old in GOOD
    path = write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(SceneError) as info:
        Scene.from_file(path)
    message = str(info.value)
    assert message.startswith(str(path) + ":")
    for fragment in fragments:
        assert fragment in message, (fragment, message)


def test_malformed_toml_names_file_and_line(tmp_path: Path) -> None:
    path = write(tmp_path, GOOD.replace("length = 1.0", "length = = 1.0"))
    with pytest.raises(SceneError, match=r"bad_scene\.toml: invalid TOML.*line 12"):
        Scene.from_file(path)


def test_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "nowhere.toml"
    with pytest.raises(SceneFileNotFoundError, match=r"nowhere\.toml") as info:
        Scene.from_file(path)
    assert isinstance(info.value, FileNotFoundError)
    assert isinstance(info.value, SceneError)


def test_from_dict_names_its_source() -> None:
    with pytest.raises(
        SceneError,
        match=r"^my-source: field 'obstacle\[0\]\.radius': must be a finite number > 0 \[m\]; "
        r"got 0 \(in obstacle 'x'\)$",
    ):
        Scene.from_dict(
            {"obstacle": [{"name": "x", "shape": "sphere", "radius": 0, "xyz": [0, 0, 0]}]},
            source="my-source",
        )
    with pytest.raises(SceneError, match=r"^<dict>: must be a table; got a list of 2: \[1, 2\]$"):
        Scene.from_dict([1, 2])  # type: ignore[arg-type]


# ================================================================ docs agree with the file

ROOT = Path(__file__).resolve().parents[2]


def _numbers_in(text: str) -> list[float]:
    """The decimal numbers of a piece of prose ("−" read as a minus, "–" as a range dash)."""
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?", text.replace("−", "-"))]


def _table_cell(markdown: str, label: str) -> str:
    """The second cell of the table row whose first cell is ``label``."""
    rows = [line for line in markdown.splitlines() if line.startswith(f"| {label} |")]
    assert len(rows) == 1, f"expected one table row {label!r}; found {rows}"
    return rows[0].split("|")[2]


def test_docs_quote_the_shipped_paper_scene() -> None:
    """Every number docs/scene-files.md and docs/paper-scenario.md quote from the paper's
    scene is the number in adept_traj/data/scenes/paper.toml (read with tomllib)."""
    toml = tomllib.loads((ROOT / "adept_traj/data/scenes/paper.toml").read_text("utf-8"))
    robot, task, (pendulum,) = toml["robot"], toml["task"], toml["pendulum"]
    cubes = {ob["name"]: ob for ob in toml["obstacle"]}

    scene_files = (ROOT / "docs/scene-files.md").read_text("utf-8")
    section = scene_files[scene_files.index("## The paper's scene") :]
    assert "adept_traj/data/scenes/paper.toml" in section.splitlines()[0]
    assert "placeholder" not in scene_files
    quoted = {
        key: _numbers_in(values)
        for key, values in re.findall(r"`(\w+) = \[([^\]]*)\]`", section)
    }  # fmt: skip
    expected = {
        "xyz": robot["xyz"], "rpy": robot["rpy"], "start": task["start"],
        "goal": task["goal"], "pivot": pendulum["pivot"],
    }  # fmt: skip
    assert quoted == expected
    for key in ("bob_radius", "rod_radius"):
        assert f"`{key} = {pendulum[key]}`" in section

    scenario = (ROOT / "docs/paper-scenario.md").read_text("utf-8")
    assert "adept_traj/data/scenes/paper.toml" in scenario
    assert _numbers_in(_table_cell(scenario, "robot base position")) == robot["xyz"]
    yaw = _numbers_in(_table_cell(scenario, "robot base yaw"))
    assert robot["rpy"][:2] == [0.0, 0.0]
    assert yaw == [pytest.approx(math.degrees(robot["rpy"][2]))]
    assert _numbers_in(_table_cell(scenario, "pendulum pivot")) == pendulum["pivot"]
    assert _numbers_in(_table_cell(scenario, "start d3")) == [task["start"][2]]
    assert _numbers_in(_table_cell(scenario, "goal d3")) == [task["goal"][2]]
    assert _numbers_in(_table_cell(scenario, "bob radius")) == [pendulum["bob_radius"]]
    assert _numbers_in(_table_cell(scenario, "rod radius")) == [pendulum["rod_radius"]]
    thetas = _numbers_in(_table_cell(scenario, "θ1, θ2, θ4 of start and goal"))
    assert thetas == [task[k][i] for k in ("start", "goal") for i in (0, 1, 3)]
    for label, cube in (("Cube 1", cubes["cube1"]), ("Cube 2", cubes["cube2"])):
        ranges = _numbers_in(_table_cell(scenario, label).replace("–", " "))
        assert ranges == [v for lo, hi in zip(cube["min"], cube["max"]) for v in (lo, hi)]
    law = _table_cell(scenario, "pendulum")
    for symbol, key in (("l", "length"), ("v0", "v0"), ("g", "g")):
        assert float(re.search(rf"\b{symbol} = (\d+(?:\.\d+)?)", law)[1]) == pendulum[key]
    assert float(re.search(r"sin\((\d+(?:\.\d+)?) t\)", law)[1]) == pendulum["omega"]
