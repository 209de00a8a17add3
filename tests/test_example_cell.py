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

ROOT = Path(__file__).resolve().parents[1]
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
