"""The best-first cloud distance (adept_traj.collision.cloud_distance) and the point-cloud
level of the broad phase, against coal's own octree distance called directly and against
closed-form point–cube distances to every leaf (numpy, no code shared)."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

import adept_traj as at
from adept_traj.collision import CollisionChecker, distance_request
from adept_traj.collision.cloud_distance import CloudDistance, cloud_cells
from adept_traj.scene import FixedPose, Obstacle, PointCloud, Scene

CAP = 0.05


def _poses(rng, n):
    """Solid poses near the fence (some through it), the cloud's pose off the origin."""
    out = []
    for i in range(n):
        ang, rad = rng.uniform(0, 2 * np.pi), rng.uniform(0.8, 1.08)
        t = np.array([rad * np.cos(ang), rad * np.sin(ang), rng.uniform(-0.1, 0.7)])
        out.append(coal.Transform3s(Rotation.random(random_state=i).as_matrix(), t))
    return out


def _hull():
    """A URDF-like link hull: coal's convex hull of 60 points of an elongated blob."""
    rng = np.random.default_rng(60)
    vertices = coal.StdVec_Vec3s()
    for p in rng.normal(size=(60, 3)) * [0.15, 0.05, 0.04]:
        vertices.append(p)
    return coal.ConvexBase.convexHull(vertices, False, "Qt")


SOLIDS = {
    "hull": _hull(),
    "box": coal.Box(0.45, 0.1, 0.05),
    "cylinder": coal.Cylinder(0.05, 0.3),
    "capsule": coal.Capsule(0.04, 0.2),
    "sphere": coal.Sphere(0.07),
}


@pytest.mark.parametrize("kind", sorted(SOLIDS))
def test_equals_coal_octree_distance(fence, kind):
    """Within the cap: coal's octree distance, to 1e-6 m, and coal's witness points are
    the nearest leaf's (their gap is the distance); beyond it: a lower bound above the cap;
    a penetration: negative, as coal's."""
    solid, octree = SOLIDS[kind], fence.to_coal()
    ours, ref = CloudDistance(solid, octree, fence, CAP), coal.ComputeDistance(solid, octree)
    tf_cloud = coal.Transform3s(Rotation.from_euler("z", 0.3).as_matrix(), np.zeros(3))
    request = coal.DistanceRequest()
    seen = {"near": 0, "far": 0, "inside": 0}
    for tf in _poses(np.random.default_rng(len(kind)), 80):
        r1, r2 = coal.DistanceResult(), coal.DistanceResult()
        d1, d2 = ours(tf, tf_cloud, request, r1), ref(tf, tf_cloud, request, r2)
        if d2 < 0:
            assert d1 < 0
            seen["inside"] += 1
        elif d2 <= CAP:
            assert abs(d1 - d2) <= 1e-6
            gap = np.linalg.norm(r1.getNearestPoint1() - r1.getNearestPoint2())
            assert abs(gap - d1) <= 1e-6
            seen["near"] += 1
        else:
            assert CAP < d1 <= d2 + 1e-9
            seen["far"] += 1
    assert min(seen.values()) > 0, seen


def test_point_bound_never_above_the_leaves(fence):
    """The broad phase's point bound against every leaf's closed-form point–cube distance:
    never above it, and within two field cubes' diagonal of it."""
    cells = cloud_cells(fence.to_coal(), fence)
    rng = np.random.default_rng(5)
    p = rng.uniform([-1.3, -1.3, -0.3], [1.3, 1.3, 0.9], (300, 3))
    gap = np.abs(p[:, None, :] - cells.centre[None]) - cells.half[None, :, None]
    exact = np.linalg.norm(np.maximum(gap, 0.0), axis=2).min(axis=1)
    bound = cells.point_bound(p)
    assert (bound <= exact).all()
    origin, h, field = cells.field
    grid = ((p >= origin) & (p <= origin + h * np.array(field.shape))).all(axis=1)
    assert grid.sum() > 50
    assert (exact - bound)[grid].max() <= 2 * h * np.sqrt(3)
    assert (exact - bound)[grid].mean() < h


@pytest.mark.slow  # coal's octree distance, the reference, takes ms a call
def test_checker_with_a_cloud_matches_coal_pair_by_pair(fence):
    fence = PointCloud(fence.points * [0.85, 0.85, 1.0], 0.01)  # within the arm's reach
    """The checker's smallest distance (broad phase with the cloud level, the best-first
    narrow phase) against coal's octree distance of every solid, at 100 configurations:
    equal where within the influence, a lower bound above it beyond, negative where coal
    finds a penetration."""
    robot, paper = at.Robot.adept_one_xl(), Scene.paper()
    base = paper.robot_base[:3, 3]
    ob = Obstacle("fence", fence, FixedPose.from_xyz_rpy((base[0], base[1], 0.2)))
    scene = Scene((ob,), robot_base=paper.robot_base, start=paper.start, goal=paper.goal)
    checker = CollisionChecker(robot, scene, influence=CAP)
    rng = np.random.default_rng(3)
    lo, hi = robot.limits.lower, robot.limits.upper
    q = lo + (hi - lo) * rng.uniform(size=(100, 1, robot.nq))  # one sample a motion
    got = checker.min_distances(q, np.zeros(q.shape[:-1])).distance[..., 0]
    octree, request = fence.to_coal(), distance_request()  # the checker's coal settings
    pose = scene.base_from_world @ ob.pose(0.0)
    tf_cloud = coal.Transform3s(pose[:3, :3], pose[:3, 3])
    model, gm = robot.model, robot.collision_model
    data, gdata = model.createData(), gm.createData()
    ref = np.full(q.shape[0], np.inf)
    for m in range(q.shape[0]):
        for n in range(q.shape[1]):
            pin.updateGeometryPlacements(model, data, gm, gdata, q[m, n])
            for k, obj in enumerate(gm.geometryObjects):
                place = gdata.oMg[k]
                tf = coal.Transform3s(place.rotation, place.translation)
                d = coal.distance(obj.geometry, tf, octree, tf_cloud, request,
                                  coal.DistanceResult())  # fmt: skip
                ref[m] = min(ref[m], d)
    inside, far = ref <= 0.0, ref > CAP
    near = ~inside & ~far
    assert min(inside.sum(), near.sum(), far.sum()) >= 5, (inside.sum(), near.sum(), far.sum())
    assert (got[inside] <= 0.0).all()
    np.testing.assert_allclose(got[near], ref[near], atol=1e-6)
    assert (got[far] > CAP).all()
    assert (got[far] <= ref[far] + 1e-9).all()


@pytest.mark.slow  # coal's octree distance, the reference, takes ms a call
def test_cloud_level_bounds_never_above_coal(fence_checker):
    """The broad phase's point-cloud level (coarse cells, finer cells looked up only under
    a parent within the influence, squares on the faces) against coal's octree distance
    of each solid called directly: never above it at any of 60 configurations × 7 solids,
    and above the influence for at least 95 % of the pairs coal puts 3 cm beyond it (the
    hierarchy keeps the bounds useful)."""
    robot, checker = fence_checker  # the fence within the arm's reach
    assert checker.influence == CAP
    scene = checker.scene
    (ob,) = scene.obstacles
    fence = ob.shape
    rng = np.random.default_rng(11)
    lo, hi = robot.limits.lower, robot.limits.upper
    q = lo + (hi - lo) * rng.uniform(size=(60, robot.nq))
    frames = robot.kinematics.joint_frames(q)
    pose = scene.base_from_world @ ob.pose(0.0)
    lower = checker.broad_phase.bounds(frames, [pose], q).lower[..., 0]  # (60, n_solids)
    octree, request = fence.to_coal(), distance_request()
    tf_cloud = coal.Transform3s(pose[:3, :3], pose[:3, 3])
    model, gm = robot.model, robot.collision_model
    data, gdata = model.createData(), gm.createData()
    ref = np.empty_like(lower)
    for m in range(len(q)):
        pin.updateGeometryPlacements(model, data, gm, gdata, q[m])
        for k, obj in enumerate(gm.geometryObjects):
            tf = coal.Transform3s(gdata.oMg[k].rotation, gdata.oMg[k].translation)
            ref[m, k] = coal.distance(obj.geometry, tf, octree, tf_cloud, request,
                                      coal.DistanceResult())  # fmt: skip
    assert (lower <= ref + 1e-9).all(), (lower - ref).max()
    close = ref <= CAP + 0.03
    assert close.sum() >= 20, close.sum()
    assert (~close).sum() >= 20, close.sum()
    # outside the field's grid (above the fence) a bound is looser: most, not all
    assert (lower[~close] > CAP).mean() >= 0.95, (lower[~close] > CAP).mean()


@pytest.mark.slow  # coal's octree distance of a hull, the reference, takes ms a call
def test_urdf_hull_links_against_a_cloud_match_coal():
    """A URDF arm (the UR5 of example-robot-data: its link meshes as convex hulls) beside
    a scanned wall: the checker takes the cloud's fast path for the hulls (not coal's
    octree call) and its smallest distance per configuration equals coal's octree distance
    of every hull called directly (to 1e-6 m within the influence, a lower bound above the
    influence beyond it, negative where coal finds a penetration)."""
    from adept_traj.collision.mesh_distance import distance_functor

    path = None
    for d in at.robot.installed_data_dirs():
        candidate = d / "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
        path = candidate if candidate.is_file() else path
    if path is None:
        pytest.skip("example-robot-data is not installed")
    robot = at.Robot.from_urdf(path)
    rng = np.random.default_rng(41)
    wall = np.column_stack([  # a wall 0.45 m in front of the base, 1.2 m × 1.2 m
        np.full(30_000, 0.45), rng.uniform(-0.6, 0.6, 30_000), rng.uniform(-0.2, 1.0, 30_000)
    ])  # fmt: skip
    cloud = PointCloud(wall, 0.01)
    ob = Obstacle("wall", cloud, FixedPose(np.eye(4)))
    scene = Scene((ob,))
    checker = CollisionChecker(robot, scene, influence=CAP)
    hulls = [g.geometry for g in robot.collision_model.geometryObjects]
    assert any(isinstance(h, coal.ConvexBase) for h in hulls)
    octree = checker.broad_phase.obstacle_geometry[0]
    for h in hulls:
        if isinstance(h, coal.ConvexBase):
            assert isinstance(distance_functor(h, octree, cloud, CAP), CloudDistance)
    lo, hi = np.maximum(robot.limits.lower, -np.pi), np.minimum(robot.limits.upper, np.pi)
    q = lo + (hi - lo) * rng.uniform(size=(200, 1, robot.nq))
    got = checker.min_distances(q, np.zeros(q.shape[:-1])).distance[..., 0]
    request = distance_request()
    model, gm = robot.model, robot.collision_model
    data, gdata = model.createData(), gm.createData()
    ref = np.full(len(q), np.inf)
    for m in range(len(q)):
        pin.updateGeometryPlacements(model, data, gm, gdata, q[m, 0])
        for k, obj in enumerate(gm.geometryObjects):
            tf = coal.Transform3s(gdata.oMg[k].rotation, gdata.oMg[k].translation)
            d = coal.distance(obj.geometry, tf, octree, coal.Transform3s(), request,
                              coal.DistanceResult())  # fmt: skip
            ref[m] = min(ref[m], d)
    inside, far = ref <= 0.0, ref > CAP
    near = ~inside & ~far
    assert near.sum() >= 3, (inside.sum(), near.sum(), far.sum())
    assert far.sum() >= 3, (inside.sum(), near.sum(), far.sum())
    assert (got[inside] <= 0.0).all()
    np.testing.assert_allclose(got[near], ref[near], atol=1e-6)
    assert (got[far] > CAP).all()
    assert (got[far] <= ref[far] + 1e-9).all()
