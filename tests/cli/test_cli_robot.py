"""The robot options of ``verify`` and ``show`` on a saved result (the recorded robot's
files moved, meshes elsewhere, a robot that is not the recorded one), the ``[robot]`` table
shared by scene and cycle files, and errors naming the robot's joint count.

The result is planned on copies of the shipped AdeptOne XL files, which are then moved; the
references are the recorded values (joint names, limits, stored torques), not the check.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

import adept_traj.viz.server as server
from adept_traj.cli import main
from adept_traj.cli.result_robot import check_recorded_robot
from adept_traj.cycle import read_cycle_file
from adept_traj.errors import CycleError, RobotMismatchError, RobotModelError, SceneError
from adept_traj.optimise import plan
from adept_traj.problem import TrajectoryProblem
from adept_traj.results import PlanningResult
from adept_traj.robot import Robot, RobotSource, resolve_package_file, shipped_file
from adept_traj.scene import Scene, read_robot_files


def _ur5_urdf() -> Path | None:
    """The UR5 URDF of example-robot-data, found as a ``package://`` file; ``None``."""
    try:
        return resolve_package_file(f"package://example-robot-data/robots/{UR5_PATH}")
    except RobotModelError:
        return None


UR5_PATH = "ur_description/urdf/ur5_robot.urdf"
UR5 = _ur5_urdf()
ROBOTS = UR5.parents[2] if UR5 is not None else None
needs_robots = pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "data"


@pytest.fixture(scope="module")
def moved(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A result planned on copies of the AdeptOne XL files in ``a/``, then moved to ``b/``."""
    root = tmp_path_factory.mktemp("moved")
    (root / "a").mkdir()
    for name in ("adept_one_xl.urdf", "adept_one_xl.toml"):
        shutil.copy(shipped_file(name), root / "a" / name)
    robot = Robot.from_urdf(root / "a" / "adept_one_xl.urdf", root / "a" / "adept_one_xl.toml")
    paper = Scene.paper()
    problem = TrajectoryProblem(robot, paper, paper.start, paper.goal, workers=1)
    plan(problem, "nsga2", seed=1, pop_size=8, n_gen=2, max_certify=1).save(root / "run")
    problem.close()
    (root / "a").rename(root / "b")
    return {
        "run": root / "run",
        "urdf": root / "b" / "adept_one_xl.urdf",
        "params": root / "b" / "adept_one_xl.toml",
    }


def test_verify_uses_the_robot_given_when_the_recorded_files_moved(
    moved: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    run = str(moved["run"])
    assert main(["verify", run]) == 2  # the recorded URDF is gone
    assert "adept_one_xl.urdf" in capsys.readouterr().err
    argv = ["verify", run, "--robot", str(moved["urdf"]), "--params", str(moved["params"])]
    assert main(argv) in (0, 1)  # 1: this tiny run's best is not certified
    assert "no mismatch" in capsys.readouterr().out


def test_verify_refuses_another_robot_naming_both(
    moved: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    planar = EXAMPLES / "planar_2link.urdf"
    assert main(["verify", str(moved["run"]), "--robot", str(planar)]) == 2
    err = capsys.readouterr().err
    assert "planar_2link.urdf does not load as the result's robot 'adept_one_xl'" in err
    assert "no frame 'tool0'" in err  # the recorded tool frame
    argv = ["verify", str(moved["run"]), "--robot", str(planar), "--tool-frame", "hand"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "robot 'planar_2link'" in err
    assert "is not the result's robot 'adept_one_xl'" in err
    assert "its 2 joints ['shoulder', 'elbow'] differ from the recorded 4" in err


def test_a_robot_without_the_recorded_parameter_file_is_refused(
    moved: dict[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    """The parameter file gives the acceleration and jerk limits the URDF lacks."""
    assert main(["verify", str(moved["run"]), "--robot", str(moved["urdf"])]) == 2
    err = capsys.readouterr().err
    assert "acceleration limits [inf, inf, inf, inf] differ from the recorded" in err
    assert "--params" in err


def test_a_robot_with_other_masses_is_refused(moved: dict[str, Path], tmp_path: Path) -> None:
    text = moved["urdf"].read_text()
    assert text.count('<mass value="20.0"/>') == 1
    heavier = tmp_path / "heavier.urdf"
    heavier.write_text(text.replace('<mass value="20.0"/>', '<mass value="20.5"/>'))
    result = PlanningResult.load(moved["run"])
    same = Robot.from_urdf(moved["urdf"], moved["params"])
    check_recorded_robot(result, same)  # the recorded robot passes
    with pytest.raises(RobotMismatchError, match=r"inverse dynamics differs.*joint '"):
        check_recorded_robot(result, Robot.from_urdf(heavier, moved["params"]))


def test_show_plays_the_robot_given_and_refuses_another_before_the_server(
    moved: dict[str, Path], monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    played = []

    def fake_show(result: PlanningResult, **kwargs: object) -> None:
        played.append(kwargs["replay"])
        raise KeyboardInterrupt  # as Ctrl-C: show exits 0

    monkeypatch.setattr(server, "show", fake_show)
    run, urdf, params = str(moved["run"]), str(moved["urdf"]), str(moved["params"])
    assert main(["show", run, "--robot", urdf, "--params", params]) == 0
    (replay,) = played
    assert replay.robot.urdf_path == moved["urdf"]
    planar = str(EXAMPLES / "planar_2link.urdf")
    assert main(["show", run, "--robot", planar]) == 2
    assert "does not load as the result's robot 'adept_one_xl'" in capsys.readouterr().err
    assert len(played) == 1  # refused before the server


def _ur5_in_own_package(folder: Path) -> Path:
    """``folder/ur5.urdf``: the UR5 with meshes in ``package://my_ur/``, a package found
    only in ``folder/pkgs`` (not installed, not on ROS_PACKAGE_PATH)."""
    (folder / "pkgs").mkdir()
    (folder / "pkgs" / "my_ur").symlink_to(ROBOTS / "ur_description")
    text = UR5.read_text()
    urdf = folder / "ur5.urdf"
    urdf.write_text(
        text.replace("package://example-robot-data/robots/ur_description/", "package://my_ur/")
    )
    return urdf


@needs_robots
@pytest.mark.slow
def test_verify_and_show_find_moved_meshes_with_package_dir_alone(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """A UR5 whose meshes come from a package only ``package_dirs`` names; the folder moves
    after planning, and ``--package-dir`` alone finds it again."""
    urdf = _ur5_in_own_package(tmp_path)
    robot = Robot.from_urdf(urdf, EXAMPLES / "ur5.toml", package_dirs=[tmp_path / "pkgs"])
    scene = Scene.from_file(EXAMPLES / "ur5_box.toml")
    problem = TrajectoryProblem(robot, scene, scene.start, scene.goal, n_knots=6, workers=1)
    plan(problem, "nsga2", seed=1, pop_size=8, n_gen=2, max_certify=1).save(tmp_path / "run")
    problem.close()
    (tmp_path / "pkgs").rename(tmp_path / "elsewhere")
    run = str(tmp_path / "run")
    assert main(["verify", run]) == 2
    assert "my_ur" in capsys.readouterr().err  # the mesh is not found
    assert main(["verify", run, "--package-dir", str(tmp_path / "elsewhere")]) in (0, 1)
    assert "no mismatch" in capsys.readouterr().out
    played = []
    monkeypatch.setattr(server, "show", lambda result, **kw: played.append(kw) or exit_now())
    assert main(["show", run, "--package-dir", str(tmp_path / "elsewhere")]) == 0
    assert played[0]["replay"].robot.package_dirs[0] == (tmp_path / "elsewhere").resolve()


def exit_now() -> None:
    raise KeyboardInterrupt


# ------------------------------------------------------------------ [robot] tables
def _cycle_text(robot: str) -> str:
    return f"""name = "ur5-cycle"
scene = "ur5_box.toml"
{robot}
[[location]]
name = "left"
joints = [-1.0, -1.2, 1.2, -1.5, -1.57, 0.0]

[[location]]
name = "right"
joints = [1.0, -1.2, 1.2, -1.5, -1.57, 0.0]

[[move]]
from = "left"
to = "right"
"""


@needs_robots
def test_a_ur5_cycle_file_names_its_tool_frame_and_package_folders(tmp_path: Path) -> None:
    shutil.copy(EXAMPLES / "ur5_box.toml", tmp_path)
    shutil.copy(EXAMPLES / "ur5.toml", tmp_path)
    _ur5_in_own_package(tmp_path)
    table = (
        '[robot]\nurdf = "ur5.urdf"\nparams = "ur5.toml"\ntool_frame = "wrist_2_link"\n'
        'package_dirs = ["pkgs"]\n'
    )
    (tmp_path / "cycle.toml").write_text(_cycle_text(table))
    cycle = read_cycle_file(tmp_path / "cycle.toml")
    assert cycle.robot == RobotSource(
        tmp_path / "ur5.urdf",
        tmp_path / "ur5.toml",
        tool_frame="wrist_2_link",
        package_dirs=(tmp_path / "pkgs",),
    )
    robot = cycle.robot.load()
    assert (robot.name, robot.nq, robot.tool_frame) == ("ur5", 6, "wrist_2_link")
    assert robot.package_dirs[0] == (tmp_path / "pkgs").resolve()
    np.testing.assert_array_equal(cycle.locations["right"].joints, [1.0, -1.2, 1.2, -1.5, -1.57, 0])


def test_a_cycle_file_without_a_plan_table_takes_the_defaults(tmp_path: Path) -> None:
    """(It was refused: "field 'plan': missing; must be a table".)"""
    text = _cycle_text("").replace('scene = "ur5_box.toml"', 'scene = "paper"')
    text = text.replace("[-1.0, -1.2, 1.2, -1.5, -1.57, 0.0]", "[0.1682, 1.3849, 0.08, -0.7555]")
    text = text.replace("[1.0, -1.2, 1.2, -1.5, -1.57, 0.0]", "[0.5, 1.0, 0.08, 0.0]")
    (tmp_path / "cycle.toml").write_text(text)
    cycle = read_cycle_file(tmp_path / "cycle.toml")
    (move,) = cycle.moves
    assert (move.algorithm, move.seed, move.pop_size, move.n_gen) == ("nsga2", 1, None, None)
    assert cycle.rate_hz == 1000.0


def test_a_bad_robot_key_is_named_with_the_valid_ones(tmp_path: Path) -> None:
    (tmp_path / "cycle.toml").write_text(_cycle_text('[robot]\nurfd = "x.urdf"\n'))
    with pytest.raises(CycleError) as caught:
        read_cycle_file(tmp_path / "cycle.toml")
    message = str(caught.value)
    assert "field 'robot.urfd': unknown field; allowed fields: 'urdf', 'params'" in message
    assert "'tool_frame', 'package_dirs', 'srdf', 'locked_joints'" in message
    scene = tmp_path / "scene.toml"
    scene.write_text('[robot]\nxyz = [0, 0, 0]\nurfd = "x.urdf"\n')
    with pytest.raises(SceneError, match=r"'robot.urfd': unknown field; allowed fields: 'xyz'"):
        read_robot_files(scene)


def test_the_robot_table_needs_a_urdf_for_its_other_keys(tmp_path: Path) -> None:
    (tmp_path / "cycle.toml").write_text(_cycle_text('[robot]\ntool_frame = "tool0"\n'))
    with pytest.raises(CycleError, match=r"field 'robot': tool_frame given without a URDF"):
        read_cycle_file(tmp_path / "cycle.toml")


def test_a_scene_file_robot_table_reads_srdf_and_locked_joints(tmp_path: Path) -> None:
    shutil.copy(EXAMPLES / "planar_2link.urdf", tmp_path)
    (tmp_path / "robot.srdf").write_text('<robot name="planar_2link"></robot>\n')
    scene = tmp_path / "scene.toml"
    scene.write_text(
        '[robot]\nurdf = "planar_2link.urdf"\nsrdf = "robot.srdf"\n'
        "locked_joints = { elbow = 0.25 }\n"
    )
    source = read_robot_files(scene)
    assert source.srdf == tmp_path / "robot.srdf"
    assert source.locked_joints == (("elbow", 0.25),)
    robot = source.load()
    assert robot.joint_names == ("shoulder",)
    assert robot.locked_joints == {"elbow": 0.25}
    scene.write_text('[robot]\nurdf = "planar_2link.urdf"\nsrdf = "missing.srdf"\n')
    with pytest.raises(SceneError, match=r"field 'robot.srdf': no such file: .*missing.srdf"):
        read_robot_files(scene)


def test_a_cycle_location_of_the_wrong_length_names_the_robot_joints(tmp_path: Path) -> None:
    text = _cycle_text("").replace('scene = "ur5_box.toml"', 'scene = "paper"')
    (tmp_path / "cycle.toml").write_text(text)
    with pytest.raises(CycleError) as caught:
        read_cycle_file(tmp_path / "cycle.toml")
    assert "must be a list of 4 finite numbers [rad | m], one per joint of robot " in str(
        caught.value
    )
    assert "'adept_one_xl' (joint1, joint2, joint3, joint4); got a list of 6" in str(caught.value)


def test_compare_seeds_plans_on_the_robot_of_the_options(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """(The seed study planned on the AdeptOne XL whatever the options named.)"""
    import adept_traj.cli.compare as compare_command

    seen = []

    def fake_study(*args: object, **kwargs: object) -> None:
        seen.append(kwargs.get("robot"))
        raise KeyboardInterrupt

    monkeypatch.setattr(compare_command, "run_seed_study", fake_study)
    for name in ("planar_2link.urdf", "planar_2link.toml"):
        shutil.copy(EXAMPLES / name, tmp_path)
    scene = tmp_path / "scene.toml"
    scene.write_text(
        '[robot]\nurdf = "planar_2link.urdf"\nparams = "planar_2link.toml"\n'
        "[task]\nstart = [0.0, 0.0]\ngoal = [1.0, 1.0]\n"
    )
    argv = ["compare", "--seeds", "1", "--scene", str(scene), "--quiet", "--out", str(tmp_path)]
    assert main([*argv, "--tool-frame", "fore"]) == 130
    urdf, params = tmp_path / "planar_2link.urdf", tmp_path / "planar_2link.toml"
    assert seen == [RobotSource(urdf, params, tool_frame="fore")]


@pytest.mark.parametrize("command", ["verify", "show"])
def test_the_tool_frame_help_of_a_saved_result_names_the_recorded_default(
    command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit):
        main([command, "--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "tool frame name (default: the recorded one)" in text
    assert "the parameter file's" not in text


def test_the_ur5_example_scene_names_its_srdf_as_a_package_uri_and_turns_self_collision_on() -> (
    None
):
    source = read_robot_files(EXAMPLES / "ur5_box.toml")
    assert str(source.srdf).startswith("package://example-robot-data/")
    robot = source.load()
    expected = ROBOTS / "ur_description" / "srdf" / "ur5.srdf"
    assert robot.srdf_path.resolve() == expected.resolve()
    assert {"base_link", "shoulder_link"} in [set(pair) for pair in robot.disabled_pairs]
    scene = Scene.from_file(EXAMPLES / "ur5_box.toml")
    problem = TrajectoryProblem(robot, scene, scene.start, scene.goal, n_knots=6)
    assert problem.self_check is not None
    assert problem.self_check.n_pairs > 0
    problem.close()


def test_a_parameter_file_disables_link_pairs_and_turns_self_collision_on(tmp_path: Path) -> None:
    params = tmp_path / "ur5.toml"
    params.write_text(
        'disable_collisions = [["forearm_link", "wrist_3_link"]]\n'
        + (EXAMPLES / "ur5.toml").read_text()
    )
    robot = Robot.from_urdf(UR5, params)
    assert robot.disabled_pairs == (("forearm_link", "wrist_3_link"),)
    scene = Scene.from_file(EXAMPLES / "ur5_box.toml")
    problem = TrajectoryProblem(robot, scene, scene.start, scene.goal, n_knots=6)
    check = problem.self_check
    assert check is not None
    links = {frozenset(pair) for pair in check.disabled}
    assert frozenset(("forearm_link", "wrist_3_link")) in links
    checked = {frozenset(check.links[i] for i in pair) for pair in check.pairs.tolist()}
    assert frozenset(("forearm_link", "wrist_3_link")) not in checked
    assert frozenset(("upper_arm_link", "wrist_3_link")) in checked
    problem.close()
    params.write_text('disable_collisions = [["forearm_link", "no_such_link"]]\n')
    with pytest.raises(
        RobotModelError, match=r"disable_collisions names link\(s\) \['no_such_link'\]"
    ):
        Robot.from_urdf(UR5, params)
    params.write_text('disable_collisions = [["forearm_link", "base_link", "tool0"]]\n')
    with pytest.raises(RobotModelError, match="must hold \\[link1, link2\\] pairs of link names"):
        Robot.from_urdf(UR5, params)
