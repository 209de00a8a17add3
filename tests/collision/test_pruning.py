"""Obstacle pruning (adept_traj.collision.pruning): never skips an obstacle that could come
within influence (randomised, against coal called directly), changes no distance within
influence, and leaves the paper scene's tables alone."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

from adept_traj import Box, FixedPose, Obstacle, Robot, Scene
from adept_traj.collision import CollisionChecker, ObstaclePruning, sweep_clearance
from adept_traj.problem import TrajectoryProblem

INFLUENCE = 0.05


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.adept_one_xl()


def _boxes(rng: np.random.Generator, n: int, base: np.ndarray) -> tuple[Obstacle, ...]:
    """n boxes of 5–30 cm, rotated about z, centred 0.3–1.6 m from the robot base axis."""
    radius, angle = rng.uniform(0.3, 1.6, n), rng.uniform(0, 2 * np.pi, n)
    out = []
    for k in range(n):
        xy = base[:2, 3] + radius[k] * np.array([np.cos(angle[k]), np.sin(angle[k])])
        pose = FixedPose.from_xyz_rpy([*xy, rng.uniform(0.0, 0.8)], [0, 0, rng.uniform(0, 3)])
        out.append(Obstacle(f"b{k}", Box(rng.uniform(0.05, 0.3, 3)), pose))
    return tuple(out)


def _coal_min(robot: Robot, scene: Scene, q: np.ndarray) -> np.ndarray:
    """(n_motions, n_obstacles) smallest distance [m] over samples and solids, one
    coal.distance per (sample, solid, obstacle); solids placed by Pinocchio."""
    model, gm = robot.model, robot.collision_model
    data, gdata = model.createData(), gm.createData()
    to_base = scene.base_from_world
    tf_o = []
    for ob in scene.obstacles:
        pose = to_base @ ob.pose(0.0)
        tf_o.append(coal.Transform3s(pose[:3, :3], pose[:3, 3]))
    shapes = [ob.shape.to_coal() for ob in scene.obstacles]
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    out = np.full((q.shape[0], len(shapes)), np.inf)
    for m in range(q.shape[0]):
        for n in range(q.shape[1]):
            pin.updateGeometryPlacements(model, data, gm, gdata, q[m, n])
            for s, g in enumerate(gm.geometryObjects):
                tf_s = coal.Transform3s(gdata.oMg[s].rotation, gdata.oMg[s].translation)
                for o, shape in enumerate(shapes):
                    result.clear()
                    d = coal.distance(g.geometry, tf_s, shape, tf_o[o], request, result)
                    out[m, o] = min(out[m, o], d)
    return out


@pytest.mark.parametrize("seed", [0, pytest.param(1, marks=pytest.mark.slow)])
def test_pruned_obstacles_are_beyond_influence_by_coal(robot: Robot, seed: int) -> None:
    """Random cells of 25 boxes, random motions: every obstacle reported as pruned (a
    bound above influence, no sample) is farther than that bound at every sample (coal);
    some are pruned, some kept."""
    rng = np.random.default_rng(seed)
    paper = Scene.paper()
    scene = Scene(_boxes(rng, 25, paper.robot_base), robot_base=paper.robot_base)
    checker = CollisionChecker(robot, scene, INFLUENCE)
    lo, hi = robot.limits.lower, robot.limits.upper
    start = lo + (hi - lo) * rng.uniform(size=(3, 1, robot.nq))
    q = start + 0.3 * np.cumsum(rng.normal(size=(3, 12, robot.nq)), axis=1) * (hi - lo) / 12
    q = np.clip(q, lo, hi)
    out = checker.min_distances(q, np.zeros(q.shape[:-1]))
    reference = _coal_min(robot, scene, q)
    pruned = (out.sample == -1) & (out.distance > INFLUENCE)
    assert 0 < pruned.sum() < pruned.size
    assert (reference[pruned] >= out.distance[pruned] - 1e-9).all()
    near = reference <= INFLUENCE
    np.testing.assert_allclose(out.distance[near], reference[near], atol=1e-6)


def test_pruning_changes_no_evaluation(robot: Robot, monkeypatch: pytest.MonkeyPatch) -> None:
    """A cell of the paper's obstacles and 30 boxes: the problem's evaluation with the
    pruning equals the one without it (every obstacle kept), bit for bit."""
    paper = Scene.paper()
    rng = np.random.default_rng(3)
    scene = Scene(
        paper.obstacles + _boxes(rng, 30, paper.robot_base),
        robot_base=paper.robot_base,
        start=paper.start,
        goal=paper.goal,
    )
    problem = TrajectoryProblem(robot, scene, scene.start, scene.goal)
    x = problem.xl + (problem.xu - problem.xl) * rng.uniform(size=(20, problem.n_var))
    kept, fewer = ObstaclePruning.kept, []

    def spy(self: ObstaclePruning, bounds: np.ndarray) -> np.ndarray:
        out = kept(self, bounds)
        fewer.append(len(out) < bounds.shape[1])
        return out

    monkeypatch.setattr(ObstaclePruning, "kept", spy)
    pruned = problem.evaluate_batch(x)
    assert any(fewer)  # some obstacles were left out
    monkeypatch.setattr(ObstaclePruning, "kept", lambda self, b: np.arange(b.shape[1]))
    every = problem.evaluate_batch(x)
    for name in ("objectives", "constraints", "min_distance"):
        np.testing.assert_array_equal(getattr(pruned, name), getattr(every, name))


def test_paper_scene_keeps_its_tables_and_a_far_box_gets_none(robot: Robot) -> None:
    paper = Scene.paper()
    far = Obstacle("far", Box((0.2, 0.2, 0.2)), FixedPose.from_xyz_rpy([4.0, 0.4, 0.1]))
    cell = Scene((*paper.obstacles, far), robot_base=paper.robot_base)
    tables = CollisionChecker(robot, cell).broad_phase.tables
    assert sorted(tables) == sorted(CollisionChecker(robot, paper).broad_phase.tables)
    assert len(tables) == 4  # the inner arm's two solids against each cube


def test_sweep_clearance_is_the_distance_to_the_swept_circle() -> None:
    """Against the swept circle sampled every 0.01°: a lower bound, and tight."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        origin, centre, point = rng.normal(size=(3, 3))
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        clearance = sweep_clearance(origin, axis, centre, 0.1, point, 0.2)
        angles = np.linspace(0, 2 * np.pi, 36_000, endpoint=False)
        rel = centre - origin
        along = (rel @ axis) * axis
        perp = rel - along
        circle = (
            origin
            + along
            + np.cos(angles)[:, None] * perp
            + np.sin(angles)[:, None] * np.cross(axis, perp)
        )
        brute = np.linalg.norm(circle - point, axis=1).min() - 0.3
        assert clearance <= brute + 1e-12
        assert clearance >= brute - 1e-6


def test_pruning_keeps_allowed_contacts(robot: Robot) -> None:
    """A scene with an allowed contact and an obstacle pruned away: the pruned view keeps
    the allowed pairs of the obstacles it keeps (it raised a shape error before), and the
    distances equal those of the scene without the far obstacle."""
    paper = Scene.paper()
    floor = Obstacle("floor", Box([3.0, 3.0, 0.02]), FixedPose.from_xyz_rpy([1.0, 0.5, -0.01]))
    far = Obstacle("far", Box([0.2, 0.2, 0.2]), FixedPose.from_xyz_rpy([6.0, 6.0, 0.1]))
    contact = (("base_link", "floor"),)
    near_only = Scene((*paper.obstacles, floor), paper.robot_base, allowed_contacts=contact)
    with_far = Scene((*paper.obstacles, floor, far), paper.robot_base, allowed_contacts=contact)
    s = np.linspace(0.0, 1.0, 40)[:, None]
    q = (paper.start + s * (paper.goal - paper.start))[None]  # (1, 40, 4) straight move
    t = 1.5 * s.T  # (1, 40) [s]
    got = CollisionChecker(robot, with_far).min_distances(q, t)
    want = CollisionChecker(robot, near_only).min_distances(q, t)
    np.testing.assert_array_equal(got.distance[..., :-1], want.distance)
    assert got.distance[0, -1] > INFLUENCE  # the far box: its bound
    assert got.distance[0, -2] > 0.0  # the floor: only the base touches it, and is allowed
