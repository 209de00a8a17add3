"""A frozen problem (issue #27): its settings, robot, scene, start and goal are fixed at
construction, changes are copies (``replace``), its arrays are read-only copies of the
caller's, and data derived from it is kept on it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from adept_traj.collision.checker import shared_motion_laws
from adept_traj.collision.joint_tables import kept_tables
from adept_traj.errors import AdeptTrajError, ConfigurationError, FrozenObjectError
from adept_traj.problem import ProblemSettings, TrajectoryProblem
from adept_traj.robot import Robot
from adept_traj.scene import PointCloud, Scene


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.adept_one_xl()


@pytest.fixture(scope="module")
def scene() -> Scene:
    return Scene.paper()


@pytest.fixture(scope="module")
def problem(robot, scene) -> TrajectoryProblem:
    return TrajectoryProblem(robot, scene, scene.start, scene.goal)


@pytest.mark.parametrize(
    "name",
    ["settings", "robot", "scene", "start", "goal", "trajectory", "checker", "xl", "n_var"],
)
def test_setting_or_deleting_a_part_of_the_problem_is_refused(problem, name):
    before = getattr(problem, name)
    with pytest.raises(FrozenObjectError, match=rf"TrajectoryProblem\.{name}.*replace") as err:
        setattr(problem, name, before)
    # the library's error, and what a frozen dataclass raises (an AttributeError)
    assert isinstance(err.value, AdeptTrajError)
    assert isinstance(err.value, dataclasses.FrozenInstanceError)
    with pytest.raises(FrozenObjectError):
        delattr(problem, name)
    assert getattr(problem, name) is before


def test_the_problem_keeps_read_only_copies_of_the_callers_arrays(robot, scene):
    start, goal = np.array(scene.start), np.array(scene.goal)  # writeable, the caller's
    problem = TrajectoryProblem(robot, scene, start, goal)
    for name in ("start", "goal", "s", "weights", "xl", "xu"):
        arr = getattr(problem, name)
        assert not arr.flags.writeable, name
        with pytest.raises(ValueError, match="read-only"):
            arr[0] = 0.0
    assert not np.shares_memory(problem.start, start)
    assert not np.shares_memory(problem.goal, goal)
    start[0] += 0.1  # the caller's array changes; the problem does not
    np.testing.assert_array_equal(problem.start, scene.start)
    np.testing.assert_array_equal(start, np.asarray(scene.start) + np.array([0.1, 0, 0, 0]))


def test_a_copy_with_another_setting_is_the_problem_built_with_it(problem, robot, scene):
    copy = problem.replace(margin=0.02, search_buffer=0.001)
    assert copy is not problem
    assert (copy.settings.margin, copy.settings.search_buffer) == (0.02, 0.001)
    assert copy.settings == dataclasses.replace(problem.settings, margin=0.02, search_buffer=0.001)
    assert (problem.settings.margin, problem.settings.search_buffer) == (0.01, 0.002)
    assert copy.robot is robot
    assert copy.scene is scene
    # the same numbers as a problem built directly with those settings
    direct = TrajectoryProblem(
        robot, scene, scene.start, scene.goal, margin=0.02, search_buffer=0.001
    )
    x = problem.trajectory.straight_line(1.5)
    a, b = copy.evaluate_batch(x), direct.evaluate_batch(x)
    np.testing.assert_array_equal(a.objectives, b.objectives)
    np.testing.assert_array_equal(a.constraints, b.constraints)
    # the distance row moved by the margin change over the influence (the constraint's
    # normalisation) and nothing else did
    c = problem.evaluate_batch(x)
    np.testing.assert_array_equal(c.constraints[:-1], a.constraints[:-1])
    shift = ((0.02 + 0.001) - (0.01 + 0.002)) / problem.settings.influence
    assert a.constraints[-1] - c.constraints[-1] == pytest.approx(shift, abs=1e-15)


def test_a_copy_with_other_parts(problem, robot, scene):
    goal = np.array(scene.goal)
    goal[2] = 0.5 * (goal[2] + scene.start[2])  # another d3 [m]
    moved = problem.replace(goal=goal, settings=ProblemSettings(n_knots=12))
    np.testing.assert_array_equal(moved.goal, goal)
    np.testing.assert_array_equal(moved.start, problem.start)
    assert moved.settings.n_knots == 12
    assert moved.trajectory.n_knots == 12
    assert moved.n_var == moved.trajectory.n_var < problem.n_var
    empty = Scene(robot_base=scene.robot_base, start=scene.start, goal=scene.goal, name="empty")
    assert problem.replace(scene=empty).checker.n_obstacles == 0
    assert problem.checker.n_obstacles == len(scene.obstacles)


def test_replace_names_what_it_takes(problem):
    with pytest.raises(ConfigurationError, match=r"robot, scene, start, goal, settings.*'T_max'"):
        problem.replace(T_max=3.0)
    with pytest.raises(ConfigurationError, match="margin"):  # checked as at construction
        problem.replace(margin=1.0)


def test_derived_data_is_made_once_per_problem(problem):
    calls = []

    def make(p):
        calls.append(p)
        return object()

    first = problem.derived("test.frozen", make)
    assert problem.derived("test.frozen", make) is first
    assert calls == [problem]
    copy = problem.replace(margin=0.02)
    assert copy.derived("test.frozen", make) is not first  # a copy derives its own
    assert calls == [problem, copy]


def test_the_robot_is_frozen_and_copies_with_other_limits(robot):
    with pytest.raises(FrozenObjectError, match=r"Robot\.limits"):
        robot.limits = robot.limits
    with pytest.raises(FrozenObjectError):
        robot.model = robot.model
    torque = np.array(robot.limits.torque) * 0.5
    half = robot.replace(limits=dataclasses.replace(robot.limits, torque=torque), name="half")
    np.testing.assert_array_equal(half.limits.torque, torque)
    assert half.name == "half"
    assert robot.name != "half"
    assert not np.array_equal(robot.limits.torque, torque)
    q = np.array([[0.1, 1.2, 0.05, -0.3]])
    v, a = np.full((1, 4), 0.3), np.full((1, 4), -0.7)
    np.testing.assert_array_equal(half.inverse_dynamics(q, v, a), robot.inverse_dynamics(q, v, a))
    with pytest.raises(ConfigurationError, match="tool_frame"):
        robot.replace(tool_frame="tool0")
    other = dataclasses.replace(robot.limits, names=("a", "b", "c", "d"))
    with pytest.raises(ConfigurationError, match="joints"):
        robot.replace(limits=other)


def test_the_scene_is_frozen(scene):
    with pytest.raises(dataclasses.FrozenInstanceError):
        scene.obstacles = ()
    with pytest.raises(dataclasses.FrozenInstanceError):
        scene.obstacles[0].offset = np.eye(4)
    for arr in (scene.robot_base, scene.start, scene.goal, scene.obstacles[0].offset):
        assert not arr.flags.writeable


def test_a_pendulums_rod_and_bob_share_their_motion_law(scene):
    names = [ob.name for ob in scene.obstacles]
    laws = shared_motion_laws(scene)
    rod, bob = names.index("pendulum.rod"), names.index("pendulum.bob")
    assert scene.obstacles[rod].motion is scene.obstacles[bob].motion  # as the scene makes it
    assert laws[rod] == laws[bob] == rod
    fixed = [i for i, ob in enumerate(scene.obstacles) if not ob.is_moving]
    assert fixed
    assert all(laws[i] == i for i in fixed)


def test_a_copy_takes_over_the_distance_tables_of_the_obstacles_it_keeps(robot):
    detour = Scene.shipped("detour")
    problem = TrajectoryProblem(robot, detour, detour.start, detour.goal)
    assert problem.checker.broad_phase.tables  # the post and the table are tabulated
    still = dataclasses.replace(detour, obstacles=detour.fixed)
    copies = {
        "relaxed": problem.replace(scene=still, workers=1),
        "certifying": problem.replace(influence=0.015, search_buffer=0.0),
    }
    directs = {
        "relaxed": TrajectoryProblem(robot, still, detour.start, detour.goal, problem.settings),
        "certifying": TrajectoryProblem(
            robot, detour, detour.start, detour.goal, problem.settings, influence=0.015,
            search_buffer=0.0,
        ),
    }  # fmt: skip
    x = np.stack([problem.trajectory.straight_line(t) for t in (1.2, 1.6, 2.4)])
    for name, copy in copies.items():
        direct = directs[name]
        mine, theirs = copy.checker.broad_phase.tables, direct.checker.broad_phase.tables
        assert mine, name
        assert mine.keys() == theirs.keys(), name
        for key, table in mine.items():
            k, o = key
            kept = copy.scene.obstacles[o]
            old = next(i for i, ob in enumerate(detour.obstacles) if ob is kept)
            assert table is problem.checker.broad_phase.tables[k, old], name  # taken over
            np.testing.assert_array_equal(table.values, theirs[key].values)
            assert (table.joint, table.start, table.step, table.lipschitz) == (
                theirs[key].joint, theirs[key].start, theirs[key].step, theirs[key].lipschitz
            )  # fmt: skip
        a, b = copy.evaluate_batch(x), direct.evaluate_batch(x)
        np.testing.assert_array_equal(a.constraints, b.constraints)
        np.testing.assert_array_equal(a.objectives, b.objectives)
    # another robot object, or a moved base: nothing taken over
    other = Robot.adept_one_xl()
    assert kept_tables(problem.checker, other, detour) == {}
    base = np.array(detour.robot_base, dtype=float)
    base[0, 3] += 0.01
    moved = dataclasses.replace(detour, robot_base=base)
    assert kept_tables(problem.checker, robot, moved) == {}
    assert (
        kept_tables(problem.checker, robot, detour).keys()
        == problem.checker.broad_phase.tables.keys()
    )


def test_every_frozen_object_keeps_its_derived_data_the_same_way(robot):
    """One mechanism (validation.DerivedData) for the problem, the robot, a point cloud and
    a cloud's leaves; the robot's collision matrix and a cloud's tree are kept on them, no
    cache keyed by identity."""
    from adept_traj.collision import robot_collision_matrix
    from adept_traj.collision.cloud_distance import CloudCells, cloud_cells
    from adept_traj.collision.cloud_tree import cloud_tree
    from adept_traj.validation import DerivedData

    cloud = PointCloud(points=np.random.default_rng(1).uniform(-0.1, 0.1, (200, 3)),
                          resolution=0.02)  # fmt: skip
    cells = cloud_cells(cloud.to_coal(), cloud)
    for kept in (robot, cloud, cells):
        assert isinstance(kept, DerivedData)
    assert cloud_cells(cloud.to_coal(), cloud) is cells
    assert isinstance(cells, CloudCells)
    tree = cloud_tree(cells)
    assert cloud_tree(cells) is tree
    assert cells.derived_made("collision.") == {"collision.cloud_tree": tree}
    matrix = robot_collision_matrix(robot)
    assert robot_collision_matrix(robot) is matrix
    assert robot.derived_made("collision.collision_matrix") == {
        "collision.collision_matrix": matrix
    }
    other = robot.replace(limits=robot.limits)
    assert other.derived_made("") == {}  # a changed copy starts without them
