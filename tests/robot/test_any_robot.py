"""Any robot from the command line, safely (issue 26): robots with missing limits, negative
numbers as option values, reversed URDF limits, a start or goal checked before any search,
the exit status of a run without a certified move.

References are independent of the code under test: closed forms (the kinematic bound with
a velocity limit only), the figure's own artists, the URDF text.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from adept_traj.cli import main
from adept_traj.problem import TrajectoryProblem
from adept_traj.robot import Robot
from adept_traj.scene import Scene

ROOT = Path(__file__).resolve().parents[2]
PLANAR = ROOT / "tests" / "data" / "planar_2link.urdf"
FAR_BOX = {"name": "box", "shape": "box", "min": [2.0, 2.0, 2.0], "max": [2.1, 2.1, 2.1]}
TINY = ["--pop", "8", "--gens", "2", "--no-html", "--quiet", "--no-polish"]


def _planar_files(tmp_path: Path, joints: str = "") -> tuple[Path, Path]:
    """The planar 2-link arm's URDF and a parameter file with the tool frame, the task rows
    and ``joints`` (no acceleration or jerk limit unless given), and a scene file."""
    params = tmp_path / "planar.toml"
    params.write_text(f'tool_frame = "hand"\ntask_rows = ["vx", "vz"]\n{joints}')
    scene = tmp_path / "far.toml"
    scene.write_text(
        'name = "far"\n[task]\nstart = [0.0, 0.0]\ngoal = [1.0, 1.0]\n'
        '[[obstacle]]\nname = "box"\nshape = "box"\nmin = [2.0, 2.0, 2.0]\nmax = [2.1, 2.1, 2.1]\n'
    )
    return params, scene


# ---------------------------------------------------------------- case 1: missing limits
def test_a_robot_without_acceleration_and_jerk_limits_plans_draws_and_verifies(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    params, scene = _planar_files(tmp_path)
    out = tmp_path / "run"
    argv = ["plan", *TINY, "--robot", str(PLANAR), "--params", str(params), "--scene", str(scene)]
    assert main([*argv, "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert sorted(p.name for p in (out / "figures").iterdir())  # the figures were drawn
    assert (out / "figures" / "joint_motion_nsga2.png").is_file()
    stored = json.loads((out / "result.json").read_text())["unchecked"]
    assert stored[:2] == [
        "acceleration (WC): no limit for shoulder, elbow: not constrained, not certified",
        "jerk (JC): no limit for shoulder, elbow: not constrained, not certified",
    ]
    for line in stored:  # said once in the summary, as stored
        assert text.count(f"unchecked: {line}") == 1
    assert main(["verify", str(out)]) == 0
    verified = capsys.readouterr().out
    for line in stored:
        assert f"  unchecked: {line}" in verified


def test_a_joint_without_limits_beside_limited_joints_is_named(
    tmp_path: Path,
) -> None:
    params, _ = _planar_files(
        tmp_path, '[[joint]]\nname = "shoulder"\nacceleration = 20.0\njerk = 200.0\n'
    )
    robot = Robot.from_urdf(PLANAR, params)
    scene = Scene.from_dict({"name": "far", "obstacle": [FAR_BOX]})
    problem = TrajectoryProblem(robot, scene, [0.0, 0.0], [1.0, 1.0], self_collision=False)
    from adept_traj.results.unchecked import unchecked

    assert unchecked(robot.limits, problem.settings)[:2] == (
        "acceleration (WC): no limit for elbow: not constrained, not certified",
        "jerk (JC): no limit for elbow: not constrained, not certified",
    )
    problem.close()


def test_the_motion_figure_draws_no_line_for_a_missing_limit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("matplotlib")
    from adept_traj.optimise import plan
    from adept_traj.viz.plots import motion

    params, _ = _planar_files(tmp_path)
    robot = Robot.from_urdf(PLANAR, params)
    scene = Scene.from_dict({"name": "far", "obstacle": [FAR_BOX]})
    problem = TrajectoryProblem(robot, scene, [0.0, 0.0], [1.0, 1.0])
    try:
        result = plan(problem, "nsga2", seed=1, pop_size=8, n_gen=2, polish="off")
    finally:
        problem.close()
    seen = []
    monkeypatch.setattr(motion, "save_figure", lambda fig, out: seen.append(fig) or out)
    motion.joint_motion(result, tmp_path / "motion.png")
    (fig,) = seen
    from matplotlib.collections import LineCollection

    ax = fig.axes[0]
    dashed = [c for c in ax.collections if isinstance(c, LineCollection) and c.get_linestyle()
              and c.get_linestyle()[0][1] is not None]  # fmt: skip
    (limit_lines,) = dashed
    # position (lower, upper), velocity (±), torque (±) per joint; none for acceleration, jerk
    assert len(limit_lines.get_segments()) == 3 * 2 * robot.nq
    notes = [t.get_text() for t in ax.texts]
    assert notes.count("no limit") == 2 * robot.nq


def test_without_a_jerk_limit_z5_is_unchanged_and_the_bound_uses_the_known_limits(
    tmp_path: Path,
) -> None:
    params, _ = _planar_files(tmp_path)
    free = Robot.from_urdf(PLANAR, params)  # velocity limits only
    limited = Robot.from_urdf(
        PLANAR,
        _planar_files(
            tmp_path,
            '[[joint]]\nname = "shoulder"\nacceleration = 20.0\njerk = 200.0\n'
            '[[joint]]\nname = "elbow"\nacceleration = 30.0\njerk = 300.0\n',
        )[0],
    )
    scene = Scene.from_dict({"name": "far", "obstacle": [FAR_BOX]})
    start, goal = np.array([0.0, 0.0]), np.array([1.0, 1.0])
    a = TrajectoryProblem(free, scene, start, goal, t_bounds=(0.5, 3.0))
    b = TrajectoryProblem(limited, scene, start, goal, t_bounds=(0.5, 3.0))
    x = a.trajectory.straight_line(1.2)
    ea, eb = a.evaluate_batch(x[None]), b.evaluate_batch(x[None])
    assert np.array_equal(ea.objectives, eb.objectives)  # z5 (and every other) the same
    # the bound: h / v with a velocity limit only (closed form)
    v = free.limits.velocity
    assert a.lower_bound.T_min == pytest.approx(np.max(np.abs(goal - start) / v), rel=1e-12)
    assert set(a.lower_bound.cases) == {"vel"}
    # the acceleration and jerk constraints of the unlimited robot: always met
    g = ea.constraints.reshape(-1)
    assert np.all(np.isfinite(g))
    a.close()
    b.close()


# ---------------------------------------------------- case 7: negative numbers as values
def test_negative_numbers_are_option_values(tmp_path: Path) -> None:
    from adept_traj.cli.app import negative_values_attached

    argv = ["plan", "--start", "-1.2,0.3", "--goal", "-1e-3,-.5", "--seed", "-1", "--quiet"]
    assert negative_values_attached(argv) == [
        "plan", "--start=-1.2,0.3", "--goal=-1e-3,-.5", "--seed=-1", "--quiet"
    ]  # fmt: skip
    params, scene = _planar_files(tmp_path)
    out = tmp_path / "run"
    argv = ["plan", *TINY, "--no-plots", "--robot", str(PLANAR), "--params", str(params)]
    argv += ["--scene", str(scene), "--start", "-0.5,0.2", "--goal", "0.5,-0.25"]
    assert main([*argv, "--out", str(out)]) == 0
    stored = json.loads((out / "result.json").read_text())
    assert (stored["start"], stored["goal"]) == ([-0.5, 0.2], [0.5, -0.25])


# ------------------------------------------------------------ case 9: reversed limits
def test_reversed_urdf_limits_are_refused_naming_joint_file_and_values(tmp_path: Path) -> None:
    from adept_traj.errors import RobotModelError

    text = PLANAR.read_text()
    import re

    first = re.search(r'lower="([^"]+)" upper="([^"]+)"', text)
    reversed_text = text.replace(first.group(0), 'lower="1.0" upper="-1.0"', 1)
    path = tmp_path / "reversed.urdf"
    path.write_text(reversed_text)
    with pytest.raises(RobotModelError) as info:
        Robot.from_urdf(path)
    message = str(info.value)
    assert str(path) in message
    assert "'shoulder'" in message
    assert "lower = 1 > upper = -1" in message
    params = tmp_path / "reversed.toml"
    params.write_text('[[joint]]\nname = "elbow"\nlower = 3.5\n')  # above the URDF's upper
    with pytest.raises(RobotModelError, match=r"reversed.toml: joint 'elbow' .*3.5 > upper = 3\b"):
        Robot.from_urdf(PLANAR, params)


def test_every_out_of_range_joint_of_a_start_is_named(tmp_path: Path) -> None:
    from adept_traj.errors import JointLimitError

    params, _ = _planar_files(tmp_path)
    robot = Robot.from_urdf(PLANAR, params)
    lo, hi = robot.limits.lower, robot.limits.upper
    with pytest.raises(JointLimitError) as info:
        robot.limits.check_position([hi[0] + 1.0, lo[1] - 1.0], "start")
    message = str(info.value)
    assert "joint 'shoulder'" in message
    assert "joint 'elbow'" in message


# ------------------------------------------- case 4: start and goal checked before a search
def test_a_start_near_an_obstacle_is_refused_before_any_search(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    params, _ = _planar_files(tmp_path)
    # At q = 0 the forearm (a cylinder of radius 0.02 m) lies on the x axis from 0.6 to
    # 1.0 m; a ball of radius 0.02 m centred 0.045 m above x = 0.8 m: 0.005 m apart.
    scene = tmp_path / "touch.toml"
    scene.write_text(
        'name = "touch"\n[task]\nstart = [0.0, 0.0]\ngoal = [1.0, 1.0]\n'
        '[[obstacle]]\nname = "ball"\nshape = "sphere"\nradius = 0.02\nxyz = [0.8, 0.0, 0.045]\n'
    )
    out = tmp_path / "run"
    argv = ["plan", *TINY, "--robot", str(PLANAR), "--params", str(params), "--scene", str(scene)]
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1  # one line, no traceback
    assert "start: fore/rod – obstacle ball 0.005 m" in err[0]
    assert "goal" not in err[0].split("at rest:")[1]  # the goal, lifted, is clear
    assert not (out / "run.json").exists()  # nothing run, nothing written
    # the same ball at the goal's forearm is named for the goal
    swapped = "start = [1.0, 1.0]\ngoal = [0.0, 0.0]"
    scene.write_text(scene.read_text().replace("start = [0.0, 0.0]\ngoal = [1.0, 1.0]", swapped))
    assert main([*argv, "--out", str(out)]) == 2
    assert "goal: fore/rod – obstacle ball 0.005 m" in capsys.readouterr().err


# -------------------------------- case 3: package:// robots, locked joints, Cartesian poses
def _problem(argv: list[str]) -> TrajectoryProblem:
    """The problem the planning options ``argv`` describe (the parser of ``plan``)."""
    import argparse

    from adept_traj.cli.arguments import add_problem_arguments, problem_from_arguments

    parser = argparse.ArgumentParser()
    add_problem_arguments(parser)
    from adept_traj.cli.app import negative_values_attached

    return problem_from_arguments(parser.parse_args(negative_values_attached(argv)))


def test_robot_as_a_package_uri_and_a_locked_joint_from_the_command_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    params, scene = _planar_files(tmp_path)
    package = tmp_path / "pkgs" / "planar_pkg" / "urdf"
    package.mkdir(parents=True)
    (package / "planar.urdf").write_text(PLANAR.read_text())
    uri = "package://planar_pkg/urdf/planar.urdf"
    out = tmp_path / "run"
    argv = ["plan", *TINY, "--no-plots", "--robot", uri, "--package-dir", str(tmp_path / "pkgs")]
    argv += ["--params", str(params), "--scene", str(scene), "--locked-joint", "elbow=-0.3"]
    argv += ["--start", "0", "--goal", "1"]
    assert main([*argv, "--out", str(out)]) == 0, capsys.readouterr().err
    stored = json.loads((out / "result.json").read_text())["robot"]
    assert Path(stored["urdf"]) == (package / "planar.urdf").resolve()
    assert stored["joint_names"] == ["shoulder"]
    assert stored["locked_joints"] == {"elbow": -0.3}
    assert main(["verify", str(out)]) == 0  # the recorded robot rebuilds, lock included
    with pytest.raises(Exception, match="--locked-joint must be NAME=VALUE"):
        _problem(["--robot", uri, "--locked-joint", "elbow"])


@pytest.mark.parametrize("elbow", ["lefty", "righty"])
def test_a_cartesian_goal_for_the_scara_with_its_elbow(elbow: str) -> None:
    robot = Robot.adept_one_xl()
    scene = Scene.paper()
    pose = robot.tool_pose(scene.goal)  # Pinocchio's forward kinematics: the reference
    yaw = float(np.arctan2(pose[1, 0], pose[0, 0]))
    text = ",".join(f"{v:.12g}" for v in [*pose[:3, 3], yaw])
    problem = _problem(["--goal-pose", text, "--elbow", elbow, "--workers", "1"])
    try:
        q = problem.goal
        reached = robot.tool_pose(q)
        np.testing.assert_allclose(reached[:3, 3], pose[:3, 3], atol=1e-9)
        assert np.arctan2(reached[1, 0], reached[0, 0]) == pytest.approx(yaw, abs=1e-9)
        # the two elbows: the inner-arm angle θ2 of opposite signs, one of them the scene's
        same = np.allclose(q, scene.goal, atol=1e-9)
        assert same == (np.sign(q[1]) == np.sign(scene.goal[1]))
    finally:
        problem.close()


def test_a_start_given_as_joints_and_as_a_pose_is_refused() -> None:
    from adept_traj.errors import ConfigurationError

    with pytest.raises(ConfigurationError, match="give --start or --start-pose, not both"):
        _problem(["--start", "0,0,0,0", "--start-pose", "0.5,0,0.3,0"])


# ---------------------------------------- case 5: numbers that look like mm or degrees
_MM_SCENE = """name = "mm"
[robot]
xyz = [1450, 390, -250]
rpy = [0.0, 0.0, 180]
[task]
start = [0.1682, 1.3849, 0.08, -0.7555]
goal = [-0.7610, 0.2450, 0.20, 1.0095]
[[obstacle]]
name = "cube1"
shape = "box"
size = [200, 200, 200]
xyz = [900, 700, 150]
rpy = [0, 0, 180]
"""


def test_a_scene_in_millimetres_and_degrees_is_warned_about(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from adept_traj.analysis import robot_reach

    scene = tmp_path / "mm.toml"
    scene.write_text(_MM_SCENE)
    _problem(["--scene", str(scene), "--workers", "1"]).close()
    err = capsys.readouterr().err.splitlines()
    assert all(line.startswith("adept-traj: warning: ") for line in err)
    text = "\n".join(err)
    assert "every obstacle is farther than 10 × the robot's reach" in text
    assert "obstacle 'cube1' is 346.4 m across" in text  # √3 × 200 m
    assert "robot.rpy = [0.0, 0.0, 180] has an angle above 2π" in text
    assert "obstacle[0].rpy = [0, 0, 180] has an angle above 2π" in text
    # the AdeptOne XL's reach: 0.425 + 0.375 m of arms plus the solids' enclosing balls
    reach = robot_reach(Robot.adept_one_xl())
    assert 0.8 < reach < 2.0
    # the same scene in metres and radians: no warning
    metres = _MM_SCENE.replace("[1450, 390, -250]", "[1.45, 0.39, -0.25]")
    metres = metres.replace("180]", "3.141592653589793]").replace(
        "[200, 200, 200]", "[0.2, 0.2, 0.2]"
    )
    scene.write_text(metres.replace("[900, 700, 150]", "[0.9, 0.7, 0.15]"))
    _problem(["--scene", str(scene), "--workers", "1"]).close()
    assert capsys.readouterr().err == ""


# ------------------------------- cases 2, 8: self-collision on by default, without an SRDF
def _ur5_urdf() -> Path:
    from adept_traj.robot import installed_data_dirs

    for d in installed_data_dirs():
        path = d / "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
        if path.is_file():
            return path
    pytest.skip("example-robot-data is not installed")


_UR5_REFERENCE = [-1.0, -1.2, 1.2, -1.5, -1.57, 0.0]  # the start of examples/data/ur5_box.toml
_UR5_FOLDED = [0.0, -1.57, 3.0, -1.57, 0.0, 0.0]  # the forearm folded onto the upper arm


def _coal_reference(urdf: Path, q: list[float]) -> dict[frozenset[str], tuple[bool, float]]:
    """Per pair of links with a collision mesh: (collide, distance [m]) of the raw meshes
    (not their hulls) by coal, placed by Pinocchio's own model of the URDF."""
    import coal
    import pinocchio as pin

    share = urdf.parents[4]
    model = pin.buildModelFromUrdf(str(urdf))
    geom = pin.buildGeomFromUrdf(model, str(urdf), pin.COLLISION, package_dirs=[str(share)])
    data, gdata = model.createData(), pin.GeometryData(geom)
    q_ref = np.asarray(q)  # revolute joints: Pinocchio's q is the angles themselves
    pin.forwardKinematics(model, data, q_ref)
    pin.updateGeometryPlacements(model, data, geom, gdata, q_ref)
    out = {}
    objects = geom.geometryObjects
    for i in range(len(objects)):
        for j in range(i + 1, len(objects)):
            a, b = objects[i], objects[j]
            la, lb = model.frames[a.parentFrame].name, model.frames[b.parentFrame].name
            ta = coal.Transform3s(gdata.oMg[i].rotation, gdata.oMg[i].translation)
            tb = coal.Transform3s(gdata.oMg[j].rotation, gdata.oMg[j].translation)
            hit = coal.collide(a.geometry, ta, b.geometry, tb, coal.CollisionRequest(),
                               coal.CollisionResult())  # fmt: skip
            d = coal.distance(a.geometry, ta, b.geometry, tb, coal.DistanceRequest(),
                              coal.DistanceResult())  # fmt: skip
            out[frozenset((la, lb))] = (bool(hit), float(d))
    return out


def test_self_collision_is_on_without_an_srdf_and_agrees_with_coal_on_the_raw_meshes() -> None:
    from adept_traj.certification import rest_pose_contacts

    urdf = _ur5_urdf()
    robot = Robot.from_urdf(urdf)  # no SRDF, no parameter file
    scene = Scene.from_dict({"name": "far", "obstacle": [FAR_BOX]})
    problem = TrajectoryProblem(robot, scene, _UR5_REFERENCE, _UR5_FOLDED, workers=1)
    try:
        assert problem.settings.self_collision is True
        check = problem.self_check
        checked = {frozenset(p) for p in check.link_pairs}
        assert frozenset(("upper_arm_link", "wrist_1_link")) in checked
        left = {frozenset(p[:2]): p[2] for p in problem.self_pairs.left_out}
        assert set(left.values()) == {"adjacent links"}  # nothing touches at every pose
        assert checked.isdisjoint(left)
        # the reference: coal on the raw meshes, every checked pair apart
        reference = _coal_reference(urdf, _UR5_REFERENCE)
        assert not any(reference[p][0] for p in checked)
        assert min(reference[p][1] for p in checked) > 0.01
        folded = _coal_reference(urdf, _UR5_FOLDED)
        hits = {p for p in checked if folded[p][0]}
        assert frozenset(("upper_arm_link", "wrist_1_link")) in hits
        # our check (convex hulls, never farther than the meshes) flags the same pair
        ours = check.distances(np.array(_UR5_FOLDED), exact=True)
        for k, (a, b) in enumerate(check.pairs.tolist()):
            pair = frozenset((check.links[a], check.links[b]))
            assert ours[k] <= folded[pair][1] + 1e-9  # a hull contains its mesh
        assert ours.min() < 0
        assert check.distances(np.array(_UR5_REFERENCE), exact=True).min() > 0.01
        # checked before any search: the folded goal is named, with its pair and distance
        found = rest_pose_contacts(problem)
        assert found
        assert all(line.startswith("goal: ") for line in found)
        assert any("upper_arm_link" in line and "wrist_1_link" in line for line in found)
    finally:
        problem.close()


def test_a_folded_ur5_start_is_refused_and_the_collision_matrix_is_saved(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    urdf = _ur5_urdf()
    scene = tmp_path / "far.toml"
    scene.write_text(
        'name = "far"\n[[obstacle]]\nname = "box"\nshape = "box"\nsize = [0.1, 0.1, 0.1]\n'
        "xyz = [2.0, 2.0, 2.0]\n"
    )
    folded = ",".join(map(str, _UR5_FOLDED))
    argv = ["plan", *TINY, "--no-plots", "--robot", str(urdf), "--scene", str(scene)]
    argv += ["--goal", ",".join(map(str, _UR5_REFERENCE))]
    assert main([*argv, "--start", folded, "--out", str(tmp_path / "folded")]) == 2
    err = capsys.readouterr().err
    assert "start: upper_arm_link_0 – wrist_1_link_0 (self-collision) -0.04" in err
    # the collision matrix: written by the robot command, and beside a result
    matrix = tmp_path / "ur5.srdf"
    assert main(["robot", "--robot", str(urdf), "--collision-matrix", str(matrix)]) == 0
    from adept_traj.robot.urdf_loading import read_srdf_disabled_pairs

    pairs = {frozenset(p) for p in read_srdf_disabled_pairs(matrix)}
    assert frozenset(("base_link", "shoulder_link")) in pairs
    assert frozenset(("upper_arm_link", "wrist_1_link")) not in pairs
    start = ",".join(map(str, [1.0, -1.2, 1.2, -1.5, -1.57, 0.0]))
    out = tmp_path / "run"
    main([*argv, "--start", start, "--out", str(out)])
    assert (out / "collision_matrix.srdf").read_text() == matrix.read_text()
    stored = json.loads((out / "result.json").read_text())
    assert stored["problem_settings"]["self_collision"] is True
    sc = stored["self_collision"]
    assert ["upper_arm_link", "wrist_1_link"] in sc["checked"]
    assert {"pair": ["base_link", "shoulder_link"], "reason": "adjacent links"} in sc["left_out"]
    text = capsys.readouterr().out
    assert "self-collision: 20 link pairs checked" in text
    # a user SRDF replaces the matrix: its pairs are left out, nothing is saved
    argv2 = [*argv, "--srdf", str(matrix), "--start", start, "--out", str(tmp_path / "srdf")]
    main(argv2)
    assert not (tmp_path / "srdf" / "collision_matrix.srdf").exists()


# ----------------------------------------- case 6: large hulls simplified conservatively
def _sphere_obj(path: Path, n: int = 4100, radius: float = 0.05) -> np.ndarray:
    """An OBJ mesh of ``n`` points on a sphere (their convex hull: a triangle mesh with
    every point a vertex, more than MAX_HULL_POINTS); returns the vertices (n, 3) [m]."""
    from scipy.spatial import ConvexHull

    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + 5.0**0.5) * k * 1.0001  # off the polytope's own lattice
    r = np.sqrt(1.0 - z * z)
    points = radius * np.column_stack([r * np.cos(phi), r * np.sin(phi), z])
    faces = ConvexHull(points).simplices + 1
    lines = [f"v {x:.9f} {y:.9f} {z:.9f}" for x, y, z in points]
    lines += [f"f {a} {b} {c}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")
    return points


def test_the_bounding_polytope_contains_the_points_and_states_its_extra_clearance() -> None:
    import coal
    from scipy.spatial import ConvexHull

    from adept_traj.robot.collision_meshes import MAX_HULL_POINTS, bounding_polytope

    rng = np.random.default_rng(5)
    points = rng.normal(size=(2000, 3)) * [0.08, 0.03, 0.02]  # an ellipsoidal cloud [m]
    vertices = coal.StdVec_Vec3s()
    for p in points:
        vertices.append(p)
    hull = coal.ConvexBase.convexHull(vertices, False, "Qt")
    polytope, extra = bounding_polytope(points, hull, n_directions=300)
    corners = np.asarray(polytope.points(), dtype=float)
    assert len(corners) <= MAX_HULL_POINTS
    facets = ConvexHull(corners).equations  # scipy's own facets: a·x + b ≤ 0 inside
    assert (points @ facets[:, :3].T + facets[:, 3]).max() <= 1e-12
    # extra bounds how far a corner is from the hull: scipy's hull facets of the points
    inner = ConvexHull(points).equations
    out_of_hull = (corners @ inner[:, :3].T + inner[:, 3]).max(axis=1)  # ≤ the distance
    assert out_of_hull.max() <= extra + 1e-12  # (equal where the nearest point is on a facet)
    assert extra < 0.02  # 10.1 mm for this sparse cloud and 300 planes; 0.2 mm for a 5 cm ball


@pytest.mark.slow
def test_a_hull_with_too_many_vertices_is_replaced_by_a_polytope_that_contains_it(
    tmp_path: Path,
) -> None:
    from scipy.spatial import ConvexHull

    from adept_traj.robot.collision_meshes import MAX_HULL_POINTS

    points = _sphere_obj(tmp_path / "ball.obj")
    text = PLANAR.read_text().replace(
        '<geometry><cylinder radius="0.02" length="0.4"/></geometry>',
        f'<geometry><mesh filename="{tmp_path / "ball.obj"}"/></geometry>',
    )
    urdf = tmp_path / "ball_arm.urdf"
    urdf.write_text(text)
    with pytest.warns(UserWarning, match=r"fore/rod' has 4100 vertices .* up to \d\.\d\d mm"):
        robot = Robot.from_urdf(urdf)
    (report,) = robot.mesh_hulls
    assert report.simplified_from == 4100
    assert report.hull_points <= MAX_HULL_POINTS
    solid = robot.collision_model.geometryObjects[1].geometry
    corners = np.asarray(solid.points(), dtype=float)
    # it contains the mesh: every vertex of the mesh inside the polytope (scipy's facets)
    facets = ConvexHull(corners).equations  # a·x + b ≤ 0 inside
    assert (points @ facets[:, :3].T + facets[:, 3]).max() <= 1e-12
    # the extra clearance it costs: at least how far its corners stick out of the ball
    # that holds the hull, and small
    sticks_out = float(np.linalg.norm(corners, axis=1).max() - 0.05)
    assert sticks_out <= report.extra < 2e-3
