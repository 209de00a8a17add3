"""Every serial arm of example-robot-data from the command line (issue 26): loaded from
its URDF alone, and with the package's SRDF, it plans a short move around a box at a small
budget, draws the figures and verifies, without a traceback (exit 0 or 1 for plan and
verify: certified or not; never 2, bad input, nor 3, a mismatch).

Start and goal: two poses of a fixed seed within the limits, apart from each other by at
most 1 rad per joint, clear of self-collision and of the box by the margin (the box
placed beside the straight line between the two tool positions); what each run certifies
is the command's business, not this suite's.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from adept_traj.certification import rest_pose_contacts
from adept_traj.cli import main
from adept_traj.problem import TrajectoryProblem
from adept_traj.robot import Robot, installed_data_dirs
from adept_traj.scene import Scene

_FOUND = [d / "example-robot-data" / "robots" for d in installed_data_dirs()]
ROBOTS = next((d for d in _FOUND if d.is_dir()), None)
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed"),
]

#: The serial arms of example-robot-data (URDF, SRDF or None, relative to robots/).
ARMS = {
    "ur3": ("ur_description/urdf/ur3_robot.urdf", None),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", "ur_description/srdf/ur5.srdf"),
    "ur10": ("ur_description/urdf/ur10_robot.urdf", None),
    "panda": ("panda_description/urdf/panda.urdf", "panda_description/srdf/panda.srdf"),
    "kinova": ("kinova_description/robots/kinova.urdf", "kinova_description/srdf/kinova.srdf"),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", "xarm_description/srdf/xarm7.srdf"),
    "z1": ("z1_description/urdf/z1.urdf", "z1_description/srdf/z1.srdf"),
    "so100": ("so_arm_description/urdf/so100.urdf", None),
    "so101": ("so_arm_description/urdf/so101.urdf", None),
}
_CASES = [(name, False) for name in ARMS] + [(n, True) for n, (_, s) in ARMS.items() if s]


def _task(robot: Robot, srdf: bool) -> tuple[np.ndarray, np.ndarray, dict]:
    """Start, goal (nq,) and a box obstacle (a scene file's table) for ``robot`` (module
    doc)."""
    rng = np.random.default_rng(7)
    lo = np.clip(robot.limits.lower, -np.pi, np.pi)
    hi = np.clip(robot.limits.upper, -np.pi, np.pi)
    empty = Scene.from_dict({"name": "empty"})
    for _ in range(200):
        start = rng.uniform(lo, hi)
        goal = np.clip(start + rng.uniform(-1.0, 1.0, robot.nq), lo, hi)
        problem = TrajectoryProblem(robot, empty, start, goal, workers=1, n_knots=6)
        clear = not rest_pose_contacts(problem)
        problem.close()
        if not clear:
            continue
        a, b = robot.tool_pose(start)[:3, 3], robot.tool_pose(goal)[:3, 3]
        middle, side = 0.5 * (a + b), np.cross(b - a, [0.0, 0.0, 1.0])
        side = side / max(np.linalg.norm(side), 1e-9)
        for shift in (0.15, 0.3, -0.15, -0.3):
            box = {"name": "box", "shape": "box", "size": [0.08, 0.08, 0.08],
                   "xyz": [float(v) for v in middle + shift * side]}  # fmt: skip
            scene = Scene.from_dict({"name": "box", "obstacle": [box]})
            problem = TrajectoryProblem(robot, scene, start, goal, workers=1, n_knots=6)
            clear = not rest_pose_contacts(problem)
            problem.close()
            if clear:
                return start, goal, box
    pytest.fail(f"no clear start and goal found for {robot.name}")


@pytest.mark.parametrize(("name", "srdf"), _CASES, ids=[f"{n}-{'srdf' if s else 'urdf'}"
                                                        for n, s in _CASES])  # fmt: skip
def test_an_arm_of_example_robot_data_plans_draws_and_verifies(
    name: str, srdf: bool, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    urdf, srdf_file = ARMS[name]
    options = ["--robot", str(ROBOTS / urdf)]
    if srdf:
        options += ["--srdf", str(ROBOTS / srdf_file)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (a simplified hull says so)
        robot = Robot.from_urdf(ROBOTS / urdf, srdf=ROBOTS / srdf_file if srdf else None)
    start, goal, box = _task(robot, srdf)
    scene = tmp_path / "box.toml"
    scene.write_text(
        f'name = "box"\n[[obstacle]]\nname = "box"\nshape = "box"\nsize = {box["size"]}\n'
        f"xyz = {box['xyz']}\n"
    )
    out = tmp_path / "run"
    argv = ["plan", *options, "--scene", str(scene), "--pop", "8", "--gens", "2", "--quiet"]
    argv += ["--no-html", "--start", ",".join(repr(float(v)) for v in start), "--goal"]
    argv += [",".join(repr(float(v)) for v in goal), "--workers", "1", "--out", str(out)]
    code = main(argv)
    captured = capsys.readouterr()
    assert code in (0, 1), captured.err
    assert "Traceback" not in captured.err
    stored = json.loads((out / "result.json").read_text())
    assert code == (0 if stored["certificate"]["feasible"] else 1)
    assert len(list((out / "figures").glob("*.png"))) == 5
    assert stored["problem_settings"]["self_collision"] is True
    assert stored["self_collision"]["checked"]
    assert (out / "collision_matrix.srdf").exists() != srdf  # made only without an SRDF
    code = main(["verify", str(out)])
    captured = capsys.readouterr()
    assert code == (0 if stored["certificate"]["feasible"] else 1), captured.out
    assert "no mismatch" in captured.out
