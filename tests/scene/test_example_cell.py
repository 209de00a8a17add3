"""The shipped example cell (docs/example-cell.md): its meshes are what examples/make_cell.py
writes, closed, read in millimetres; a short run plans it to a move certified in continuous
time that `verify` re-derives; the playback draws the meshes and moves the machines."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

import adept_traj as at
from adept_traj.cli.app import main as cli_main
from adept_traj.scene import LinearMotion, Mesh, RotationMotion

ROOT = Path(__file__).resolve().parents[2]
CELL = ROOT / "adept_traj" / "data" / "scenes" / "cell"


def test_shipped_meshes_are_the_scripts_and_closed(tmp_path, monkeypatch):
    spec = importlib.util.spec_from_file_location("make_cell", ROOT / "examples" / "make_cell.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    monkeypatch.setattr(module, "OUT", tmp_path)
    module.main()
    shipped = sorted(p.name for p in CELL.iterdir())
    assert shipped == sorted(p.name for p in tmp_path.iterdir())
    for name in shipped:
        assert (tmp_path / name).read_bytes() == (CELL / name).read_bytes(), name
    scene = at.Scene.shipped("cell")
    meshes = [ob for ob in scene.obstacles if isinstance(ob.shape, Mesh)]
    assert len(meshes) == 4
    assert all(ob.shape.closed for ob in meshes)
    fixture = scene.obstacle("fixture")  # a 0.4 × 0.2 table 0.30 m high, STL in mm
    lo, hi = fixture.shape.local_box
    np.testing.assert_allclose(hi - lo, [0.4, 0.2, 0.3], atol=1e-6)
    assert isinstance(scene.obstacle("part2").motion, LinearMotion)
    assert isinstance(scene.obstacle("jig").motion, RotationMotion)


@pytest.fixture(scope="module")
def cell_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("cell") / "run"
    code = cli_main(
        [
            "plan",
            "--scene",
            "cell",
            "--pop",
            "16",
            "--gens",
            "4",
            "--seed",
            "1",
            "--out",
            str(out),
            "--no-plots",
        ]
    )
    return code, out


@pytest.mark.slow
def test_cell_plans_to_a_certified_move_that_verify_rederives(cell_run):
    code, out = cell_run
    assert code == 0
    result = at.PlanningResult.load(out)
    assert result.certificate.certified
    assert result.certificate.guarantee == "continuous"
    assert cli_main(["verify", str(out)]) == 0
    assert (out / "playback.html").stat().st_size > 10_000


@pytest.mark.slow
def test_playback_draws_meshes_and_moves_the_machines(cell_run):
    from adept_traj.viz.playback import build_animation

    _, out = cell_run
    result = at.PlanningResult.load(out)
    playback = build_animation(result)
    objects = {o.path: o for o in playback.objects}
    fixture = objects["obstacles/fixture"]
    assert not fixture.animated
    drawn = fixture.parts[0].obj.geometry
    mesh = at.Scene.shipped("cell").obstacle("fixture").shape
    np.testing.assert_allclose(np.asarray(drawn.vertices), mesh.vertices, atol=1e-7)
    np.testing.assert_array_equal(np.asarray(drawn.faces), mesh.triangles)
    part = objects["obstacles/part1"]
    assert part.animated
    t = playback.times
    # by hand: x = 0.34 + (0.25 t mod 1.2), y and z fixed
    want = 0.34 + np.mod(0.25 * t, 1.2)
    np.testing.assert_allclose(part.poses[:, 0, 3], want, atol=1e-12)
    jig = objects["obstacles/jig"]
    angle = math.atan2(jig.poses[-1, 1, 0], jig.poses[-1, 0, 0])
    assert angle == pytest.approx(math.remainder(0.6 * t[-1], 2 * math.pi), abs=1e-9)


def _robot_a_joints(t):
    """Robot A's joints (n, 4) at scene times ``t`` (n,): the shipped table interpolated
    linearly by numpy, held at its ends."""
    table = np.loadtxt(CELL / "robot_a.csv", delimiter=",", skiprows=1)
    return np.column_stack([np.interp(t, table[:, 0], table[:, j]) for j in range(1, 5)])


def _world_solid_poses(robot, base, q):
    """World poses (n, k, 4, 4) of the robot's collision solids by Pinocchio directly."""
    import pinocchio as pin

    model, gm = robot.model, robot.collision_model
    data, gdata = model.createData(), gm.createData()
    out = np.empty((len(q), len(gm.geometryObjects), 4, 4))
    for n, qn in enumerate(q):
        pin.updateGeometryPlacements(model, data, gm, gdata, qn)
        for k in range(len(gm.geometryObjects)):
            out[n, k] = base @ gdata.oMg[k].homogeneous
    return out


@pytest.mark.slow
def test_planned_move_clears_the_second_robot_at_dense_instants(cell_run):
    """The certified move re-checked against robot A by coal called directly on every pair
    of solids (robot B's and A's, Pinocchio poses, A's table interpolated by numpy) at
    2 kHz: never closer than the certificate's margin, and A comes within 0.3 m."""
    import coal

    _, out = cell_run
    result = at.PlanningResult.load(out)
    robot, scene = at.Robot.adept_one_xl(), at.Scene.shipped("cell")
    problem = at.TrajectoryProblem(robot, scene, scene.start, scene.goal)
    total = float(result.best_objectives[0])
    t = np.linspace(0.0, total, int(2000 * total) + 1)
    q_b = problem.trajectory.sample(result.best_x, t / total, orders=(0,)).q
    base_a = at.transforms.transform_from_xyz_rpy((0.2, 1.45, -0.25))
    poses_b = _world_solid_poses(robot, scene.robot_base, q_b)
    poses_a = _world_solid_poses(robot, base_a, _robot_a_joints(t))
    geoms = [g.geometry for g in robot.collision_model.geometryObjects]
    request, result_c = coal.DistanceRequest(), coal.DistanceResult()
    closest = np.inf
    for n in range(len(t)):
        for i, gi in enumerate(geoms):
            tf_b = coal.Transform3s(poses_b[n, i, :3, :3], poses_b[n, i, :3, 3])
            for j, gj in enumerate(geoms):
                tf_a = coal.Transform3s(poses_a[n, j, :3, :3], poses_a[n, j, :3, 3])
                result_c.clear()
                closest = min(closest, coal.distance(gi, tf_b, gj, tf_a, request, result_c))
    assert result.certificate.certified
    assert closest >= result.certificate.margin
    assert closest < 0.3


@pytest.mark.slow
def test_playback_moves_the_second_robot(cell_run):
    """Robot A's solids in the playback at each frame: its table interpolated by numpy,
    Pinocchio poses (not the library's motion law)."""
    from adept_traj.viz.playback import build_animation

    _, out = cell_run
    playback = build_animation(at.PlanningResult.load(out))
    t = playback.times
    want = _world_solid_poses(
        at.Robot.adept_one_xl(),
        at.transforms.transform_from_xyz_rpy((0.2, 1.45, -0.25)),
        _robot_a_joints(t),
    )
    objects = {o.path: o for o in playback.objects}
    gripper = next(o for p, o in objects.items() if p.startswith("obstacles/robotA.link4"))
    assert gripper.animated
    moved = np.linalg.norm(gripper.poses[-1, :3, 3] - gripper.poses[0, :3, 3])
    assert moved > 0.3
    names = [g.name for g in at.Robot.adept_one_xl().collision_model.geometryObjects]
    for k, name in enumerate(names):
        drawn = objects[f"obstacles/robotA.{name}"]
        np.testing.assert_allclose(drawn.poses[:, :3, 3], want[:, k, :3, 3], atol=1e-9)
