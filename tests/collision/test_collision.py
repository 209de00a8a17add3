"""Tests of the collision checker: point distances, solid–obstacle distances, paper penalty."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import coal
import numpy as np
import pinocchio as pin
import pytest

from adept_traj.collision import BroadPhase, CollisionChecker, point_signed_distance
from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.robot import Robot
from adept_traj.scene import (
    Box,
    Capsule,
    Cylinder,
    FixedPose,
    Obstacle,
    PendulumMotion,
    Scene,
    Sphere,
    pendulum_obstacles,
)
from adept_traj.transforms import transform_from_xyz_rpy

INFLUENCE = 0.05
GRIPPER_HALF = np.array([0.06, 0.03, 0.025])  # urdf/adept_one_xl.toml, solid "gripper"
PROBE_RADIUS = 1e-4


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.adept_one_xl()


@pytest.fixture(scope="module")
def paper_checker(robot: Robot) -> CollisionChecker:
    return CollisionChecker(robot, Scene.paper(), influence=INFLUENCE)


def random_q(robot: Robot, rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    lo, hi = robot.limits.lower, robot.limits.upper
    return rng.uniform(lo, hi, size=(*shape, robot.nq))


def solid_index(checker: CollisionChecker, name: str) -> int:
    return checker.solid_names.index(name)


# ---------------------------------------------------------------------------------------
# 1. point_signed_distance
# ---------------------------------------------------------------------------------------
# (point, closed-form signed distance) per shape; points outside along faces, edges and
# corners, and inside (negative).
BOX = Box((0.4, 0.6, 1.0))  # half sizes 0.2, 0.3, 0.5
SPHERE = Sphere(0.3)
CYLINDER = Cylinder(0.2, 1.0)  # radius 0.2, z in [-0.5, 0.5]
CAPSULE = Capsule(0.2, 1.0)  # segment z in [-0.5, 0.5], radius 0.2

CLOSED_FORMS = [
    (BOX, (0.5, 0.0, 0.0), 0.3),  # face x
    (BOX, (0.0, -0.45, 0.1), 0.15),  # face -y
    (BOX, (0.1, 0.2, 0.75), 0.25),  # face z
    (BOX, (0.5, 0.7, 0.0), 0.5),  # edge: hypot(0.3, 0.4)
    (BOX, (-0.3, -0.5, 0.7), 0.3),  # corner: sqrt(0.1² + 0.2² + 0.2²)
    (BOX, (0.1, 0.0, 0.0), -0.1),  # inside, nearest face x
    (BOX, (0.0, 0.25, -0.1), -0.05),  # inside, nearest face y
    (BOX, (0.0, 0.0, 0.0), -0.2),  # centre
    (BOX, (0.2, 0.3, 0.5), 0.0),  # on the corner
    (SPHERE, (1.0, 2.0, 2.0), 2.7),
    (SPHERE, (0.0, 0.0, 0.0), -0.3),
    (SPHERE, (0.0, -0.1, 0.0), -0.2),
    (CYLINDER, (0.5, 0.0, 0.1), 0.3),  # side
    (CYLINDER, (0.3, 0.4, -0.2), 0.3),  # side, off-axis radial 0.5
    (CYLINDER, (0.1, 0.0, 0.8), 0.3),  # above the cap
    (CYLINDER, (0.0, 0.05, -0.9), 0.4),  # below the cap
    (CYLINDER, (0.5, 0.0, 0.9), 0.5),  # rim edge: hypot(0.3, 0.4)
    (CYLINDER, (0.15, 0.0, 0.0), -0.05),  # inside, nearest the side
    (CYLINDER, (0.0, 0.0, 0.45), -0.05),  # inside, nearest the cap
    (CYLINDER, (0.03, 0.04, 0.0), -0.15),  # inside, radial 0.05
    (CYLINDER, (0.0, 0.0, 0.0), -0.2),  # centre
    (CAPSULE, (0.5, 0.0, 0.3), 0.3),  # side
    (CAPSULE, (0.0, 0.0, 1.0), 0.3),  # above the tip (tip at 0.7)
    (CAPSULE, (0.0, 0.0, -1.0), 0.3),  # below the tip
    (CAPSULE, (0.3, 0.0, 0.9), 0.3),  # diagonal off the cap: hypot(0.3, 0.4) - 0.2
    (CAPSULE, (0.0, 0.0, 0.0), -0.2),  # centre
    (CAPSULE, (0.1, 0.0, 0.6), math.hypot(0.1, 0.1) - 0.2),  # inside the cap
]


@pytest.mark.parametrize(("shape", "point", "expected"), CLOSED_FORMS)
def test_point_signed_distance_closed_forms(shape: object, point: tuple, expected: float) -> None:
    d = point_signed_distance(shape, np.array(point))
    assert np.ndim(d) == 0
    assert float(d) == pytest.approx(expected, abs=1e-12)


def test_point_signed_distance_is_batched() -> None:
    for shape in (BOX, SPHERE, CYLINDER, CAPSULE):
        pts = np.array([p for s, p, _ in CLOSED_FORMS if s is shape])
        expected = np.array([e for s, _, e in CLOSED_FORMS if s is shape])
        grid = np.stack([pts, pts[::-1]])  # (2, n, 3)
        d = point_signed_distance(shape, grid)
        assert d.shape == grid.shape[:-1]
        np.testing.assert_allclose(d, np.stack([expected, expected[::-1]]), atol=1e-12)


def coal_point_distance(geometry: object, probe: object, points: np.ndarray) -> np.ndarray:
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    out = np.empty(len(points))
    for i, p in enumerate(points):
        result.clear()
        out[i] = coal.distance(
            geometry, coal.Transform3s(), probe, coal.Transform3s(np.eye(3), p), request, result
        )
    return out


def random_points_around(shape: object, rng: np.random.Generator, n: int) -> np.ndarray:
    """Points in 1.6 times the shape's bounding box: about a quarter of them inside."""
    if isinstance(shape, Box):
        extent = 0.5 * np.asarray(shape.size)
    elif isinstance(shape, Sphere):
        extent = np.full(3, shape.radius)
    else:
        cap = shape.radius if isinstance(shape, Capsule) else 0.0
        extent = np.array([shape.radius, shape.radius, 0.5 * shape.length + cap])
    return rng.uniform(-1.6, 1.6, size=(n, 3)) * extent


@pytest.mark.parametrize("shape", [BOX, SPHERE, CYLINDER, CAPSULE], ids=lambda s: s.kind)
def test_point_signed_distance_matches_coal(shape: object) -> None:
    """Against coal's distance to a tiny sphere (radius 1e-4) at random points."""
    rng = np.random.default_rng(11)
    points = random_points_around(shape, rng, 300)
    psd = point_signed_distance(shape, points)
    assert (psd < 0).sum() > 20  # both sides are exercised
    assert (psd > 0).sum() > 20
    ref = coal_point_distance(shape.to_coal(), coal.Sphere(PROBE_RADIUS), points)
    # coal 3.0.3's dedicated sphere–cylinder routine returns the *radial* depth for a sphere
    # inside a cylinder near a cap (e.g. 0.10 instead of 0.007 at z = 0.493 of 0.5): inside
    # a cylinder, compare with coal's GJK/EPA instead (tiny box probe, below).
    check = psd > 0 if isinstance(shape, Cylinder) else np.ones(len(points), bool)
    assert np.all(np.abs(psd - ref)[check] <= PROBE_RADIUS + 1e-6)
    np.testing.assert_allclose(psd[check], ref[check] + PROBE_RADIUS, atol=1e-6)


def test_point_signed_distance_inside_cylinder_matches_coal_epa() -> None:
    rng = np.random.default_rng(12)
    points = random_points_around(CYLINDER, rng, 600)
    psd = point_signed_distance(CYLINDER, points)
    inside = psd < 0
    assert inside.sum() > 50
    half = PROBE_RADIUS
    ref = coal_point_distance(CYLINDER.to_coal(), coal.Box(*(3 * [2 * half])), points[inside])
    # a cube of half side h: the depth grows by between h and h√3
    gap = psd[inside] - ref
    assert np.all(gap >= half - 1e-6)
    assert np.all(gap <= half * math.sqrt(3) + 1e-6)


def test_point_signed_distance_rejects_unknown_shape() -> None:
    with pytest.raises(InvalidInputError, match="no point distance"):
        point_signed_distance("box", np.zeros(3))


# ---------------------------------------------------------------------------------------
# 2. CollisionChecker.distances against closed forms (custom scene around the gripper)
# ---------------------------------------------------------------------------------------
Q_GRIPPER = np.array([0.3, -0.5, 0.1, 0.7])
BASE = transform_from_xyz_rpy((0.3, -0.2, 0.1), (0.1, -0.2, 0.4))


def gripper_scene(robot: Robot) -> tuple[Scene, np.ndarray, CollisionChecker]:
    """Obstacles placed relative to the gripper at Q_GRIPPER, with closed-form distances.

    Returns the scene, the expected gripper–obstacle distances and a checker.
    """
    names = [g.name for g in robot.collision_model.geometryObjects]
    gripper = robot.geometry_poses(Q_GRIPPER)[names.index("link4/gripper")]  # base frame
    hx, hy, hz = GRIPPER_HALF

    def world(local: np.ndarray) -> FixedPose:
        return FixedPose(BASE @ gripper @ local)

    specs = []
    # Sphere r = 0.04, centre 0.07 beyond the bottom (+z local) face: distance 0.07 - 0.04.
    specs.append(
        ("sphere_below", Sphere(0.04), transform_from_xyz_rpy((0.0, 0.0, hz + 0.07)), 0.03)
    )
    # Sphere r = 0.02 with its centre 0.005 inside the bottom face (well inside the face's
    # outline, other faces ≥ 0.025 away): penetration 0.005 + 0.02.
    specs.append(
        (
            "sphere_inside",
            Sphere(0.02),
            transform_from_xyz_rpy((0.01, 0.005, hz - 0.005)),
            -0.025,
        )
    )
    # Box face-to-face with the +x face, 0.02 away, turned about the face normal; its
    # (rotated) cross-section stays inside the gripper's face outline.
    specs.append(
        (
            "box_x",
            Box((0.1, 0.02, 0.02)),
            transform_from_xyz_rpy((hx + 0.02 + 0.05, 0.0, 0.0), (0.3, 0.0, 0.0)),
            0.02,
        )
    )
    # Box face-to-face with the -y face, 0.035 away, its cross-section offset in the face.
    specs.append(
        (
            "box_minus_y",
            Box((0.04, 0.06, 0.03)),
            transform_from_xyz_rpy((0.01, -(hy + 0.035 + 0.03), 0.005)),
            0.035,
        )
    )
    obstacles = tuple(Obstacle(n, s, world(local)) for n, s, local, _ in specs)
    scene = Scene(obstacles=obstacles, robot_base=BASE)
    expected = np.array([d for *_, d in specs])
    return scene, expected, CollisionChecker(robot, scene, influence=INFLUENCE)


def test_gripper_pose_is_as_assumed(robot: Robot) -> None:
    """The gripper's +z (bottom) face is the tool point: a precondition of the closed forms."""
    names = [g.name for g in robot.collision_model.geometryObjects]
    gripper = robot.geometry_poses(Q_GRIPPER)[names.index("link4/gripper")]
    tool = robot.tool_pose(Q_GRIPPER)
    np.testing.assert_allclose(
        gripper[:3, :3] @ [0, 0, GRIPPER_HALF[2]] + gripper[:3, 3], tool[:3, 3], atol=1e-12
    )
    geometry = robot.collision_model.geometryObjects[names.index("link4/gripper")].geometry
    np.testing.assert_allclose(geometry.halfSide, GRIPPER_HALF, atol=1e-15)


@pytest.mark.parametrize("exact", [True, False])
def test_distances_gripper_closed_forms(robot: Robot, exact: bool) -> None:
    _, expected, checker = gripper_scene(robot)
    g = solid_index(checker, "link4/gripper")
    out = checker.distances(Q_GRIPPER[None], 0.0, exact=exact)
    assert out.distance.shape == (1, checker.n_solids, 4)
    np.testing.assert_allclose(out.distance[0, g], expected, atol=1e-9)
    # all four are within the influence distance, hence exact (coal or closed form)
    assert out.exact[0, g].all()
    # sphere obstacles (closed form) and static pairs (computed once) need no coal call
    by_coal = out.exact & ~checker.closed_form & ~checker.static_pairs
    # exact=True computes every pair; otherwise the pairs beyond the influence distance
    # keep a lower bound
    assert bool(out.exact.all()) is exact
    assert out.n_narrow == int(by_coal.sum())


def test_distances_gripper_closed_forms_batched_and_broadcast(robot: Robot) -> None:
    """Same configuration repeated over a (2, 3) batch of motions with 2 samples each."""
    _, expected, checker = gripper_scene(robot)
    g = solid_index(checker, "link4/gripper")
    q = np.broadcast_to(Q_GRIPPER, (2, 3, 2, 4))
    out = checker.distances(q, np.array([0.0, 7.5]), exact=True)
    assert out.distance.shape == (2, 3, 2, checker.n_solids, 4)
    np.testing.assert_allclose(
        out.distance[..., g, :], np.broadcast_to(expected, (2, 3, 2, 4)), atol=1e-6
    )
    np.testing.assert_array_equal(out.min_distance, out.distance.min(axis=(-2, -1)))
    np.testing.assert_array_equal(out.per_obstacle, out.distance.min(axis=(-3, -2)))
    assert out.per_obstacle.shape == (2, 3, 4)
    assert np.all(out.min_distance <= expected.min() + 1e-6)


def test_distances_move_with_the_robot(robot: Robot) -> None:
    """Lowering the quill by 0.01 m changes the sphere-below distance by exactly -0.01."""
    _, expected, checker = gripper_scene(robot)
    g = solid_index(checker, "link4/gripper")
    q = np.array([Q_GRIPPER, Q_GRIPPER + np.array([0.0, 0.0, 0.01, 0.0])])
    out = checker.distances(q, 0.0, exact=True)
    assert out.distance[1, g, 0] == pytest.approx(expected[0] - 0.01, abs=1e-6)


# ---------------------------------------------------------------------------------------
# 3. Broad-phase soundness (paper scene, random configurations and times)
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("influence", [0.0, INFLUENCE, 0.3])
def test_broad_phase_is_sound(robot: Robot, influence: float) -> None:
    rng = np.random.default_rng(5)
    checker = CollisionChecker(robot, Scene.paper(), influence=influence)
    q = random_q(robot, rng, (6, 20))
    t = rng.uniform(0.0, 4.0, size=(6, 20))
    fast = checker.distances(q, t)
    ref = checker.distances(q, t, exact=True)
    assert ref.exact.all()
    no_call = checker.closed_form | checker.static_pairs
    assert ref.n_narrow == int((ref.exact & ~no_call).sum())
    assert fast.distance.shape == ref.distance.shape == (6, 20, checker.n_solids, 4)
    skipped = ~fast.exact
    assert skipped.any()  # both phases exercised
    assert fast.exact.any()
    assert fast.n_narrow == int((fast.exact & ~no_call).sum())
    assert np.all(fast.distance[skipped] > influence)
    assert np.all(fast.distance[skipped] <= ref.distance[skipped])
    np.testing.assert_allclose(fast.distance[fast.exact], ref.distance[fast.exact], atol=1e-12)
    # every pair at or below the influence distance was computed
    assert np.all(fast.exact[ref.distance <= influence])
    # exact values are signed: penetrations occur in this sample
    assert (ref.distance < 0).any()


def random_obstacles(rng: np.random.Generator, base: np.ndarray) -> tuple[Obstacle, ...]:
    """One obstacle of each kind at a random pose in the robot's reach (world frame)."""
    shapes = (
        Box(rng.uniform(0.05, 0.3, 3)),
        Sphere(rng.uniform(0.03, 0.15)),
        Cylinder(rng.uniform(0.02, 0.1), rng.uniform(0.1, 0.6)),
        Capsule(rng.uniform(0.02, 0.1), rng.uniform(0.1, 0.6)),
    )
    out = []
    for i, shape in enumerate(shapes):
        angle, reach = rng.uniform(-np.pi, np.pi), rng.uniform(0.3, 0.8)
        xyz = (reach * np.cos(angle), reach * np.sin(angle), rng.uniform(0.3, 0.9))
        pose = base @ transform_from_xyz_rpy(xyz, rng.uniform(-np.pi, np.pi, 3))
        out.append(Obstacle(f"{shape.kind}{i}", shape, FixedPose(pose)))
    return tuple(out)


@pytest.mark.parametrize("influence", [0.0, INFLUENCE, 0.2])
def test_broad_phase_is_sound_for_every_shape_kind(robot: Robot, influence: float) -> None:
    """Random rotated boxes, spheres, cylinders and capsules, a tilted robot base."""
    rng = np.random.default_rng(7)
    base = transform_from_xyz_rpy((0.2, -0.1, 0.05), (0.05, -0.03, 0.7))
    counts = np.zeros(4, int)  # pairs skipped, pairs computed, obstacles close, far
    for _ in range(8):
        scene = Scene(obstacles=random_obstacles(rng, base), robot_base=base)
        checker = CollisionChecker(robot, scene, influence=influence)
        q = random_q(robot, rng, (40,))
        fast = checker.distances(q, 0.0)
        ref = checker.distances(q, 0.0, exact=True).distance
        skipped = ~fast.exact
        assert np.all(fast.distance[skipped] > influence)
        assert np.all(fast.distance[skipped] <= ref[skipped])
        np.testing.assert_allclose(fast.distance[fast.exact], ref[fast.exact], atol=1e-12)
        m = checker.min_distances(q, 0.0)
        best = ref.min(axis=(0, 1))
        close = best <= influence
        np.testing.assert_allclose(m.distance[close], best[close], atol=1e-12)
        assert np.all(m.distance[~close] > influence)
        assert np.all(m.distance[~close] <= best[~close])
        counts += [skipped.sum(), fast.exact.sum(), close.sum(), (~close).sum()]
    # every branch above was exercised (measured: at least 6275, 1574, 25 and 1)
    assert np.all(counts > 0), counts


def broad_bounds_and_exact(
    robot: Robot, scene: Scene, q: np.ndarray, t: np.ndarray, influence: float
) -> tuple[Any, np.ndarray]:
    """BroadPhase bounds (N, n_solids, n_obs) of flat samples q (N, nq) at times t (N,) and
    the exact distances from the checker (coal for every pair)."""
    broad = BroadPhase(robot, scene, influence)
    poses = scene.obstacle_poses(t, in_base_frame=True)  # (n_obs, N, 4, 4)
    per_obstacle = [p[0] if not ob.is_moving else p for p, ob in zip(poses, scene.obstacles)]
    bounds = broad.bounds(robot.kinematics.joint_frames(q), per_obstacle, q)
    exact = CollisionChecker(robot, scene, influence).distances(q, t, exact=True).distance
    return bounds, exact


@pytest.mark.parametrize("influence", [0.0, INFLUENCE, 0.3])
def test_broad_phase_bounds_hold_under_penetration(robot: Robot, influence: float) -> None:
    """Every bound (separating axes included, negative ones too) is at most the exact signed
    distance; where a solid penetrates an obstacle the separating-axis bound is much
    tighter than the enclosing ball's (that is what keeps deep searches short)."""
    rng = np.random.default_rng(31)
    base = transform_from_xyz_rpy((0.2, -0.1, 0.05), (0.05, -0.03, 0.7))
    scenes = [Scene.paper()] + [
        Scene(obstacles=random_obstacles(rng, base), robot_base=base) for _ in range(6)
    ]
    slack = []
    for scene in scenes:
        q = random_q(robot, rng, (300,))
        t = rng.uniform(0.0, 4.0, size=300)
        bounds, exact = broad_bounds_and_exact(robot, scene, q, t, influence)
        assert np.all(bounds.lower <= exact + 1e-9)
        np.testing.assert_allclose(bounds.lower[bounds.exact], exact[bounds.exact], atol=1e-12)
        inside = (exact < -0.005) & ~bounds.exact
        slack.append((exact - bounds.lower)[inside])
    slack = np.concatenate(slack)
    assert len(slack) > 100  # penetrations were exercised
    # measured: 75th percentile 0.3 mm (18 mm with the balls and covers alone)
    assert np.percentile(slack, 75) < 0.005


def test_single_joint_tables_bound_the_inner_arm(robot: Robot) -> None:
    """The inner arm (joint 1 only) and the fixed cubes: tabulated, within 1 mm of the
    exact distance, and no information outside the joint range."""
    scene = Scene.paper()
    broad = BroadPhase(robot, scene, INFLUENCE)
    arm_solids = {k for k in range(broad.n_solids) if broad.parents[k] == 1}
    cubes = {o for o, ob in enumerate(scene.obstacles) if not ob.is_moving}
    assert arm_solids
    assert cubes
    assert set(broad.tables) == {(k, o) for k in arm_solids for o in cubes}
    rng = np.random.default_rng(8)
    q = random_q(robot, rng, (400,))
    exact = CollisionChecker(robot, scene, INFLUENCE).distances(q, 0.0, exact=True).distance
    for (k, o), table in broad.tables.items():
        assert table.joint == 0
        bound = table.lower_bound(q[:, 0])
        assert np.all(bound <= exact[:, k, o])
        assert np.all(exact[:, k, o] - bound < 1e-3)
        outside = np.array([robot.limits.lower[0] - 0.01, robot.limits.upper[0] + 0.01])
        assert np.all(table.lower_bound(outside) == -np.inf)
    # beyond the joint range the tables know nothing: there the bounds are those without
    # tables (level 1 and its refinements), and still valid
    q_out = q[:50].copy()
    q_out[:, 0] = np.where(np.arange(50) % 2, robot.limits.upper[0], robot.limits.lower[0])
    q_out[:, 0] += np.where(np.arange(50) % 2, 0.2, -0.2)
    bounds, exact = broad_bounds_and_exact(robot, scene, q_out, np.zeros(50), INFLUENCE)
    poses = [p[0] for p in scene.obstacle_poses(np.zeros(50), in_base_frame=True)]
    untabled = broad.bounds(robot.kinematics.joint_frames(q_out), poses, None)
    for k, o in broad.tables:
        np.testing.assert_array_equal(bounds.lower[:, k, o], untabled.lower[:, k, o])
    assert np.all(bounds.lower <= exact + 1e-9)
    with pytest.raises(InvalidInputError, match=r"q must have shape \(50, 4\)"):
        broad.bounds(robot.kinematics.joint_frames(q_out), poses, q_out[:1])


def test_no_table_for_an_unlimited_joint(robot: Robot) -> None:
    lower, upper = robot.limits.lower.copy(), robot.limits.upper.copy()
    lower[0], upper[0] = -np.inf, np.inf
    limits = dataclasses.replace(robot.limits, lower=lower, upper=upper)
    free = Robot(
        robot.model, robot.collision_model, robot.visual_model, limits,
        robot.tool_frame, robot.task_rows, robot.name,
    )  # fmt: skip
    assert BroadPhase(free, Scene.paper(), INFLUENCE).tables == {}


def test_coincident_centres_are_no_separating_axis(robot: Robot) -> None:
    """A box centred exactly on the gripper's centre: the centre line is undefined and must
    not give a bound (it once gave -1e-9 for a 5 cm penetration)."""
    q0 = np.array([0.3, 0.4, 0.1, 0.2])
    k = solid_index(CollisionChecker(robot, Scene.paper()), "link4/gripper")
    pose = np.eye(4)
    pose[:3, 3] = robot.geometry_poses(q0)[k][:3, 3]
    scene = Scene(obstacles=(Obstacle("box", Box((0.5, 0.5, 0.05)), FixedPose(pose)),))
    checker = CollisionChecker(robot, scene, INFLUENCE)
    q = np.stack([q0, q0 + np.array([0.0, 0.0, 0.03, 0.0])])[None]
    t = np.zeros((1, 2))
    exact = checker.distances(q, t, exact=True).distance
    assert exact.min() < -0.04
    np.testing.assert_allclose(checker.min_distances(q, t).distance[0], exact.min(), atol=1e-12)


def coal_distances(robot: Robot, scene: Scene, q: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Reference (n, n_solids, n_obstacles) [m]: one coal.distance per sample and (solid,
    obstacle) pair, solids placed by Pinocchio's updateGeometryPlacements, each obstacle at
    its pose at that sample's instant; q (n, nq), t (n,)."""
    model, gm = robot.model, robot.collision_model
    data, gdata = model.createData(), gm.createData()
    obstacles = scene.obstacle_poses(t, in_base_frame=True)  # (n_obstacles, n, 4, 4)
    shapes = [ob.shape.to_coal() for ob in scene.obstacles]
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    request.gjk_tolerance = 1e-9  # the checker's GJK tolerance (coal's default: 1e-6)
    out = np.empty((len(q), len(gm.geometryObjects), len(shapes)))
    for n in range(len(q)):
        pin.updateGeometryPlacements(model, data, gm, gdata, q[n])
        for s, g in enumerate(gm.geometryObjects):
            placement = gdata.oMg[s]
            tf_s = coal.Transform3s(placement.rotation, placement.translation)
            for o, shape in enumerate(shapes):
                result.clear()
                pose = obstacles[o, n]
                tf_o = coal.Transform3s(pose[:3, :3], pose[:3, 3])
                out[n, s, o] = coal.distance(g.geometry, tf_s, shape, tf_o, request, result)
    return out


def test_narrow_phase_matches_independent_coal(
    robot: Robot, paper_checker: CollisionChecker
) -> None:
    """Exact entries equal coal.distance with independently built transforms."""
    rng = np.random.default_rng(8)
    q = random_q(robot, rng, (5,))
    t = rng.uniform(0.0, 4.0, size=5)
    out = paper_checker.distances(q, t, exact=True)
    np.testing.assert_allclose(
        out.distance, coal_distances(robot, paper_checker.scene, q, t), rtol=0, atol=1e-9
    )
    # the column (fixed to the base) and the two cubes are static pairs, computed once at
    # construction: covered above against coal at five random configurations and times
    static = paper_checker.static_pairs
    column = solid_index(paper_checker, "base_link/column")
    assert static.sum() == 2
    assert static[column, [0, 1]].all()


# ---------------------------------------------------------------------------------------
# 4. min_distances
# ---------------------------------------------------------------------------------------
def test_min_distances_exact_below_influence(robot: Robot, paper_checker: CollisionChecker) -> None:
    rng = np.random.default_rng(21)
    q = random_q(robot, rng, (3, 4, 6))
    t = np.linspace(0.0, 2.0, 6)  # broadcast against the (3, 4) motions
    m = paper_checker.min_distances(q, t)
    ref = paper_checker.distances(q, t, exact=True).distance  # (3, 4, 6, n_solids, n_obs)
    best = ref.min(axis=(-3, -2))
    assert m.distance.shape == m.sample.shape == m.solid.shape == (3, 4, 4)
    close = best <= INFLUENCE
    assert close.any()
    assert (~close).any()
    assert (best < 0).any()
    np.testing.assert_allclose(m.distance[close], best[close], atol=1e-12)
    assert np.all(m.distance[~close] > INFLUENCE)
    # the indices point at an entry achieving the minimum
    i, j, o = np.nonzero(close)
    k, s = m.sample[i, j, o], m.solid[i, j, o]
    assert np.all((k >= 0) & (k < 6) & (s >= 0) & (s < paper_checker.n_solids))
    np.testing.assert_allclose(ref[i, j, k, s, o], best[i, j, o], atol=1e-12)


def test_min_distances_batched_equals_per_motion(
    robot: Robot, paper_checker: CollisionChecker
) -> None:
    rng = np.random.default_rng(22)
    q = random_q(robot, rng, (3, 4, 5))
    t = rng.uniform(0.0, 3.0, size=(3, 4, 5))
    m = paper_checker.min_distances(q, t)
    for i in range(3):
        for j in range(4):
            one = paper_checker.min_distances(q[i, j], t[i, j])
            assert one.distance.shape == (4,)
            np.testing.assert_array_equal(one.distance, m.distance[i, j])
            np.testing.assert_array_equal(one.sample, m.sample[i, j])
            np.testing.assert_array_equal(one.solid, m.solid[i, j])


def test_min_distances_accepts_precomputed_joint_frames(
    robot: Robot, paper_checker: CollisionChecker
) -> None:
    rng = np.random.default_rng(23)
    q = random_q(robot, rng, (2, 5))
    t = rng.uniform(0.0, 3.0, size=5)
    a = paper_checker.min_distances(q, t)
    b = paper_checker.min_distances(q, t, joint_frames=robot.forward_kinematics(q).joint_frames)
    np.testing.assert_array_equal(a.distance, b.distance)
    np.testing.assert_array_equal(a.sample, b.sample)
    np.testing.assert_array_equal(a.solid, b.solid)
    with pytest.raises(InputShapeError, match=r"joint_frames must have shape \(5, 3, 4, 10\)"):
        paper_checker.min_distances(q, t, joint_frames=robot.kinematics.joint_frames(q[0]))


def test_min_distances_penetration_depth_is_exact(robot: Robot) -> None:
    """In the gripper scene the deepest sample is exactly the closed-form penetration."""
    _, expected, checker = gripper_scene(robot)
    # joint 3 moves the quill down: sample 1 (q3 = 0.1) has the lowest gripper; samples 0
    # and 2 are 0.05 and 0.02 higher (sphere_inside: +0.025 and -0.005 there)
    q = np.array([Q_GRIPPER - [0, 0, 0.05, 0], Q_GRIPPER, Q_GRIPPER - [0, 0, 0.02, 0]])
    m = checker.min_distances(q, 0.0)
    g = solid_index(checker, "link4/gripper")
    d = checker.distances(q, 0.0, exact=True).distance
    np.testing.assert_allclose(d[:, g, 0], [0.08, 0.03, 0.05], atol=1e-6)
    np.testing.assert_allclose(d[:, g, 1], [0.025, -0.025, -0.005], atol=1e-6)
    # obstacles 0 and 1 (below the gripper) are closest at sample 1 (lowest gripper)
    np.testing.assert_allclose(m.distance[:2], expected[:2], atol=1e-6)
    assert (m.sample[1], m.solid[1]) == (1, g)
    assert (m.sample[0], m.solid[0]) == (1, g)
    ref = d.min(axis=(0, 1))
    close = ref <= INFLUENCE
    np.testing.assert_allclose(m.distance[close], ref[close], atol=1e-12)


def cubes_scene() -> Scene:
    """The paper's two cubes with a robot base at (0.4, 1.035, -0.25) (fixed obstacles)."""
    return Scene(
        obstacles=(
            Obstacle("cube1", Box((0.4, 0.2, 0.3)), FixedPose.from_xyz_rpy((0.9, 0.7, 0.15))),
            Obstacle("cube2", Box((0.4, 0.2, 0.21)), FixedPose.from_xyz_rpy((0.9, 1.37, 0.105))),
        ),
        robot_base=transform_from_xyz_rpy((0.4, 1.035, -0.25)),
    )


def test_min_distances_is_a_lower_bound_above_influence(robot: Robot) -> None:
    """Regression: the best coal distance over the candidates with a bound <= influence
    (0.15, elbow_housing) exceeds the exact minimum (0.0932, flange, bound above influence,
    never computed): the result must fall back to a lower bound above influence."""
    checker = CollisionChecker(robot, cubes_scene(), influence=INFLUENCE)
    q = np.array([[-0.99, -0.37, 0.17, -0.86]])
    m = checker.min_distances(q, 0.0)
    exact = checker.distances(q, 0.0, exact=True).distance.min(axis=(0, 1))
    assert exact[0] == pytest.approx(0.0932207, abs=1e-6)  # the case: above influence
    assert m.distance[0] > INFLUENCE
    assert m.distance[0] <= exact[0] + 1e-12


def test_min_distances_is_a_lower_bound_random(robot: Robot) -> None:
    checker = CollisionChecker(robot, cubes_scene(), influence=INFLUENCE)
    rng = np.random.default_rng(0)
    q = random_q(robot, rng, (3, 4, 10))
    m = checker.min_distances(q, 0.0)
    best = checker.distances(q, 0.0, exact=True).distance.min(axis=(-3, -2))
    assert np.all(m.distance <= best + 1e-12)
    close = best <= INFLUENCE
    np.testing.assert_allclose(m.distance[close], best[close], atol=1e-12)
    assert np.all(m.distance[~close] > INFLUENCE)


# ---------------------------------------------------------------------------------------
# 5. Moving obstacles
# ---------------------------------------------------------------------------------------
def test_moving_obstacles_taken_at_each_instant(
    robot: Robot, paper_checker: CollisionChecker
) -> None:
    """Each sample sees the pendulum where it is at that sample's instant (coal pair by pair
    as the reference); the same configurations at other instants see it elsewhere."""
    rng = np.random.default_rng(31)
    scene = paper_checker.scene
    moving_obstacles = [o for o, ob in enumerate(scene.obstacles) if ob.is_moving]
    assert moving_obstacles == [2, 3]  # the pendulum's rod and bob
    n = 6
    q = random_q(robot, rng, (n,))
    t = rng.uniform(0.0, 2.0, size=n)
    moving = paper_checker.distances(q, t, exact=True).distance
    np.testing.assert_allclose(moving, coal_distances(robot, scene, q, t), rtol=0, atol=1e-9)
    later = paper_checker.distances(q, t + 0.25, exact=True).distance
    assert np.all(np.abs(later - moving)[..., moving_obstacles].max(axis=1) > 1e-3)
    np.testing.assert_array_equal(later[..., :2], moving[..., :2])  # the cubes stand still


# Tool straight above (0.5, 0) in the base frame, quill fully up: tool at (0.5, 0, 0.672)
# (found by Newton iterations on the tool position).
Q_ABOVE_BOB = np.array([0.81981981, 1.79623034, 0.0, 0.3])
# A base turned about the vertical and moved: obstacles are given in the world frame.
PENDULUM_BASE = transform_from_xyz_rpy((1.0, 2.0, -0.3), (0.0, 0.0, 0.5 * math.pi))


def pendulum_scene() -> Scene:
    """The paper's pendulum law (l = 1, v0 = 2, ω = 3.14) with the pivot 1.6 m above the
    base point (0.5, 0): at its lowest the bob centre is at (0.5, 0, 0.6) in the base frame."""
    pivot = PENDULUM_BASE @ [0.5, 0.0, 1.6, 1.0]
    motion = PendulumMotion(pivot=pivot[:3], length=1.0, v0=2.0, omega=3.14, g=9.81)
    rod, bob = pendulum_obstacles("pendulum", motion, bob_radius=0.08, rod_radius=0.01)
    cube = Obstacle("cube", Box((0.2, 0.2, 0.2)), FixedPose(PENDULUM_BASE))
    return Scene(obstacles=(cube, rod, bob), robot_base=PENDULUM_BASE)


def test_pendulum_closed_forms_at_two_times(robot: Robot) -> None:
    scene = pendulum_scene()
    checker = CollisionChecker(robot, scene, influence=INFLUENCE)
    cube, rod, bob = 0, 1, 2
    t_bottom = math.pi / (2.0 * 3.14)  # φ = 0
    np.testing.assert_allclose(
        scene.obstacle_poses(t_bottom, in_base_frame=True)[bob, :3, 3], [0.5, 0, 0.6], atol=1e-12
    )
    np.testing.assert_allclose(robot.tool_pose(Q_ABOVE_BOB)[:3, 3], [0.5, 0, 0.672], atol=1e-7)
    g = solid_index(checker, "link4/gripper")
    f = solid_index(checker, "link4/flange")
    q = np.array([Q_ABOVE_BOB, Q_ABOVE_BOB])
    times = np.array([0.0, t_bottom])
    d = checker.distances(q, times, exact=True).distance
    # at the bottom: the bob (r = 0.08, centre 0.072 below the gripper's bottom face)
    # penetrates the gripper by 0.008; the flange's bottom face is 0.05 higher
    assert d[1, g, bob] == pytest.approx(-0.008, abs=1e-6)
    assert d[1, f, bob] == pytest.approx(0.042, abs=1e-6)
    # the vertical rod (r = 0.01) runs through the gripper (half width 0.03) and the flange
    # (r = 0.045): the penetration depths are 0.04 and 0.055. Coal's EPA between two
    # curved solids is approximate (here -0.05474): 1e-3 for the cylinder–cylinder pair.
    assert d[1, g, rod] == pytest.approx(-0.04, abs=1e-6)
    assert d[1, f, rod] == pytest.approx(-0.055, abs=1e-3)
    # at t = 0 the pendulum is at its extreme: far away
    assert d[0, g, bob] > 0.4
    assert d[0, g, rod] > 0.1
    # the fixed cube does not depend on time
    np.testing.assert_array_equal(d[0, :, cube], d[1, :, cube])
    # the broad phase keeps the close pairs
    fast = checker.distances(q, times)
    np.testing.assert_allclose(fast.distance[1, [g, f], bob], [-0.008, 0.042], atol=1e-6)
    m = checker.min_distances(q, times)
    assert m.distance[bob] == pytest.approx(-0.008, abs=1e-6)
    assert (m.sample[bob], m.solid[bob]) == (1, g)
    assert m.distance[rod] == pytest.approx(d[1, :, rod].min(), abs=1e-12)


# ---------------------------------------------------------------------------------------
# 7. Bad input to the checker
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("method", ["distances", "min_distances"])
def test_checker_bad_input(paper_checker: CollisionChecker, method: str) -> None:
    call = getattr(paper_checker, method)
    q = np.zeros((5, 4))
    with pytest.raises(InputShapeError):
        call(np.zeros((5, 3)), np.zeros(5))  # wrong nq
    with pytest.raises(InputShapeError):
        call(np.zeros(4), 0.0)  # no time axis
    bad = q.copy()
    bad[2, 1] = np.nan
    with pytest.raises(InvalidInputError, match="q"):
        call(bad, np.zeros(5))
    with pytest.raises(InvalidInputError, match="t"):
        call(q, np.array([0, 1, np.inf, 3, 4]))
    with pytest.raises(InputShapeError, match="t must broadcast"):
        call(q, np.zeros(4))
    with pytest.raises(InputShapeError, match="t must broadcast"):
        call(np.zeros((3, 5, 4)), np.zeros((2, 5)))
    with pytest.raises(InvalidInputError):
        call([["a", "b", "c", "d"]], 0.0)


@pytest.mark.parametrize("influence", [-1e-3, np.nan, np.inf])
def test_checker_bad_influence(robot: Robot, influence: float) -> None:
    with pytest.raises(InvalidInputError, match="influence"):
        CollisionChecker(robot, Scene.paper(), influence=influence)


def test_checker_zero_influence_allowed(robot: Robot) -> None:
    checker = CollisionChecker(robot, Scene.paper(), influence=0.0)
    assert checker.influence == 0.0
    assert checker.n_obstacles == 4
    assert checker.n_solids == 7


def test_distances_empty_scene(robot: Robot) -> None:
    checker = CollisionChecker(robot, Scene())
    out = checker.distances(np.zeros((2, 4)), 0.0)
    assert out.distance.shape == out.exact.shape == (2, checker.n_solids, 0)
    assert out.n_narrow == 0
    out = checker.distances(np.zeros((3, 2, 4)), np.zeros(2), exact=True)
    assert out.distance.shape == (3, 2, checker.n_solids, 0)


def test_min_distances_empty_scene(robot: Robot) -> None:
    checker = CollisionChecker(robot, Scene())
    out = checker.min_distances(np.zeros((3, 2, 4)), 0.0)
    assert out.distance.shape == (3, 0)
    assert out.n_narrow == 0


def test_sphere_obstacles_are_closed_form_and_match_coal_outside(robot: Robot) -> None:
    """Sphere obstacles are computed as d(centre, solid) - r (no coal call); where the
    sphere is outside the solid this equals coal's distance."""
    checker = CollisionChecker(robot, Scene.paper())
    bob = checker.obstacle_names.index("pendulum.bob")
    assert checker.closed_form[:, bob].all()
    assert not checker.closed_form[:, checker.obstacle_names.index("cube1")].any()
    rng = np.random.default_rng(21)
    q = random_q(robot, rng, (4, 30))
    t = rng.uniform(0.0, 4.0, size=(4, 30))
    ours = checker.distances(q, t, exact=True).distance[..., bob]
    solid_poses = robot.geometry_poses(q)
    bob_poses = Scene.paper().obstacle_poses(t, in_base_frame=True)[bob]
    sphere = coal.Sphere(0.08)
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    separated = 0
    for idx in np.ndindex(*q.shape[:2]):
        for k, g in enumerate(robot.collision_model.geometryObjects):
            if ours[idx][k] <= 0.0:
                continue  # coal's penetration depth near a cylinder cap is not reliable
            ps, pb = solid_poses[idx][k], bob_poses[idx]
            result.clear()
            d = coal.distance(
                g.geometry,
                coal.Transform3s(ps[:3, :3], ps[:3, 3]),
                sphere,
                coal.Transform3s(pb[:3, :3], pb[:3, 3]),
                request,
                result,
            )
            assert ours[idx][k] == pytest.approx(d, abs=1e-9)
            separated += 1
    assert separated > 500


# ---------------------------------------------------------------------------------------
# Accuracy of the coal distances (collision.primitives.distance_request)
# ---------------------------------------------------------------------------------------
CYLINDER_SOLIDS = ("column", "elbow_housing", "quill", "flange")  # urdf/adept_one_xl.toml


def test_cylinder_to_box_face_distances_are_within_2_nm(robot: Robot) -> None:
    """Each cylinder of the robot (the column: a static pair, computed at construction;
    the others: by the narrow phase) against big boxes whose top face, tilted at random,
    lies 1–50 mm from it. The closed form: with n the face's outward normal, a the
    cylinder's axis, c its centre, r its radius and h its half length, the cylinder's
    lowest point along n is at :math:`n·c − r\\sqrt{1 − (n·a)^2} − h|n·a|`, and the box
    is wide enough that the nearest box point lies on that face. coal's default tolerance
    (1e-6) left these up to 0.7 µm off; the documented bound is 0 ≤ error ≤ 2 nm."""
    rng = np.random.default_rng(5)
    q = np.array([[0.4, -0.9, 0.05, 0.3]])
    names = [g.name.split("/")[-1] for g in robot.collision_model.geometryObjects]
    poses = robot.geometry_poses(q[0])  # base frame
    base = transform_from_xyz_rpy((0.1, -0.2, 0.0), (0.0, 0.0, 0.3))
    obstacles, expected, pairs = [], [], []
    for name in CYLINDER_SOLIDS:
        k = names.index(name)
        geometry = robot.collision_model.geometryObjects[k].geometry
        r, h = float(geometry.radius), float(geometry.halfLength)
        centre, axis = poses[k, :3, 3], poses[k, :3, 2]
        for _ in range(4):
            n = rng.normal(size=3)
            n /= np.linalg.norm(n)
            gap = rng.uniform(1e-3, 0.05)
            na = float(n @ axis)
            lowest = float(n @ centre) - r * np.sqrt(max(0.0, 1.0 - na * na)) - h * abs(na)
            # Box 4 m × 4 m × 0.2 m, local +z = n, top face at n·p = lowest − gap, centred
            # under the cylinder.
            z = n
            x = np.cross(z, [1.0, 0.0, 0.0] if abs(z[0]) < 0.9 else [0.0, 1.0, 0.0])
            x /= np.linalg.norm(x)
            pose = np.eye(4)
            pose[:3, :3] = np.column_stack([x, np.cross(z, x), z])
            pose[:3, 3] = centre - (float(n @ centre) - (lowest - gap - 0.1)) * n
            obstacles.append(
                Obstacle(f"box{len(obstacles)}", Box((4.0, 4.0, 0.2)), FixedPose(base @ pose))
            )
            expected.append(gap)
            pairs.append(k)
    checker = CollisionChecker(robot, Scene(obstacles=tuple(obstacles), robot_base=base))
    assert checker.static_pairs[names.index("column")].all()
    d = checker.distances(q, np.zeros(1), exact=True).distance[0]  # (n_solids, n_obstacles)
    error = d[pairs, np.arange(len(obstacles))] - np.array(expected)
    assert error.min() >= -1e-12, error.min()
    assert error.max() <= 2e-9, error.max()
