"""The certificate's distances (``CollisionChecker.distances(..., exact=True)``): every pair
at every sample against coal called directly, the closed form of a sphere and the checker's
one-pair narrow phase; chunks of samples give the same values as one."""

from __future__ import annotations

import dataclasses

import coal
import numpy as np
import pytest

import adept_traj.collision.exact_distances as exact_module
from adept_traj.collision import CollisionChecker
from adept_traj.collision.primitives import DISTANCE_TOLERANCE
from adept_traj.robot import Robot
from adept_traj.scene import Box, FixedPose, Mesh, Obstacle, Scene

RNG_SEED = 20261203


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.adept_one_xl()


@pytest.fixture(scope="module")
def checker(robot: Robot) -> CollisionChecker:
    """The paper scene (fixed boxes, the pendulum's moving rod and sphere bob), a closed
    box mesh, and one allowed contact."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * 0.1
    hull = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
            (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]  # fmt: skip
    paper = Scene.paper()
    mesh = Obstacle("mesh", Mesh(corners, np.array(hull)), FixedPose.from_xyz_rpy((0.7, -0.4, 0.3)))
    floor = Obstacle("floor", Box([3.0, 3.0, 0.02]), FixedPose.from_xyz_rpy((0.0, 0.0, -0.02)))
    scene = dataclasses.replace(
        paper,
        obstacles=(*paper.obstacles, mesh, floor),
        allowed_contacts=(("base_link", "floor"),),
    )
    return CollisionChecker(robot, scene)


def _motion(robot: Robot, n: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(RNG_SEED)
    q = rng.uniform(robot.limits.lower, robot.limits.upper, size=(n, robot.nq))
    return q, rng.uniform(0.0, 3.0, size=n)


def test_every_pair_is_coal_called_directly(robot: Robot, checker: CollisionChecker) -> None:
    """Per sample and pair: coal.distance on fresh transforms, request (the checker's GJK
    tolerance) and result for the primitive obstacles and for the sphere bob (its closed
    form), the checker's one-pair narrow phase for the mesh (signed inside), inf for the
    allowed pair."""
    n = 60
    q, t = _motion(robot, n)
    got = checker.distances(q, t, exact=True)
    assert got.exact.all()
    frames = robot.kinematics.joint_frames(q)
    poses = checker.obstacle_poses(t)
    broad = checker.broad_phase
    geometries = [g.geometry for g in robot.collision_model.geometryObjects]
    names = checker.obstacle_names
    kinds = {"primitive": 0, "sphere": 0, "mesh": 0, "allowed": 0, "static": 0}
    for k, geometry in enumerate(geometries):
        solid = broad.solid_poses(frames, np.arange(n), k)
        for o, name in enumerate(names):
            for i in range(n):
                pose_o = poses[o] if poses[o].ndim == 2 else poses[o][i]
                value = got.distance[i, k, o]
                if checker.allowed[k, o]:
                    kinds["allowed"] += 1
                    assert value == np.inf
                elif broad.static[k, o]:
                    kinds["static"] += 1
                    assert value == broad.static_distance[k, o]
                elif checker.closed_form[k, o]:
                    kinds["sphere"] += 1
                    assert name.endswith("bob")
                    # the closed form against coal on the solid and a sphere
                    ref = coal.distance(
                        geometry, _tf(solid[i]), coal.Sphere(broad.obstacle_shape[o].radius),
                        _tf(pose_o), _request(), coal.DistanceResult(),
                    )  # fmt: skip
                    assert value == pytest.approx(ref, abs=1e-6)
                elif name == "mesh":
                    kinds["mesh"] += 1
                    assert value == checker.narrow_distance(solid[i], pose_o, k, o)
                else:
                    kinds["primitive"] += 1
                    ref = coal.distance(
                        geometry, _tf(solid[i]), broad.obstacle_geometry[o], _tf(pose_o),
                        _request(), coal.DistanceResult(),
                    )  # fmt: skip
                    assert value == pytest.approx(ref, abs=1e-12)
    assert min(kinds[k] for k in ("primitive", "sphere", "mesh", "allowed")) > 0, kinds
    assert got.n_narrow == n * int((~(broad.static | checker.closed_form | checker.allowed)).sum())


def test_chunks_give_the_values_of_one(
    robot: Robot, checker: CollisionChecker, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Samples cut in chunks of 7 (the last one short) give the same values, bit for bit,
    as all the samples in one chunk."""
    q, t = _motion(robot, 45)
    whole = checker.distances(q, t, exact=True).distance
    monkeypatch.setattr(exact_module, "CHUNK", 7)
    np.testing.assert_array_equal(checker.distances(q, t, exact=True).distance, whole)


def _request() -> coal.DistanceRequest:
    """A fresh request at the checker's documented GJK tolerance."""
    request = coal.DistanceRequest()
    request.gjk_tolerance = DISTANCE_TOLERANCE
    return request


def _tf(pose: np.ndarray) -> coal.Transform3s:
    return coal.Transform3s(pose[:3, :3].copy(), pose[:3, 3].copy())
