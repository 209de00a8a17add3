"""Mesh obstacles (adept_traj.scene.meshes, collision.mesh_distance): files read, coal's
distances called directly, a robot solid inside a closed mesh flagged, open meshes, bad
input. The inside references are written here: a winding number by L'Huilier's spherical
excess (not the library's arctan formula) and the closed-form inside of a star prism."""

from __future__ import annotations

import math
import struct
import warnings

import coal
import numpy as np
import pytest

import adept_traj as at
from adept_traj.collision import CollisionChecker
from adept_traj.collision.mesh_distance import distance_functor
from adept_traj.errors import MeshFileError, OpenMeshWarning, SceneError
from adept_traj.scene import Box, FixedPose, Mesh, Obstacle, Scene

RNG_SEED = 28


def star_prism(points: int = 5, r_out: float = 0.3, r_in: float = 0.12, height: float = 0.4):
    """A closed, outward-oriented, concave mesh: a star polygon extruded along z (z from 0
    to ``height``), caps fanned from their centres. Returns (vertices, triangles)."""
    n = 2 * points
    ang = np.arange(n) * math.pi / points
    rad = np.where(np.arange(n) % 2 == 0, r_out, r_in)
    ring = np.c_[rad * np.cos(ang), rad * np.sin(ang)]
    v = np.vstack([np.c_[ring, np.zeros(n)], np.c_[ring, np.full(n, height)]])
    v = np.vstack([v, [0.0, 0.0, 0.0], [0.0, 0.0, height]])
    cb, ct = 2 * n, 2 * n + 1
    tris = []
    for i in range(n):
        j = (i + 1) % n
        tris += [(cb, j, i), (ct, n + i, n + j), (i, j, n + j), (i, n + j, n + i)]
    return v, np.array(tris)


def star_inside(p: np.ndarray, points=5, r_out=0.3, r_in=0.12, height=0.4) -> np.ndarray:
    """Closed-form inside of :func:`star_prism`: 0 < z < h and the (x, y) point inside
    the star polygon (inside the triangle (centre, ring i, ring i+1) of its sector)."""
    n = 2 * points
    ang = np.arctan2(p[:, 1], p[:, 0]) % (2 * math.pi)
    i = np.floor(ang / (math.pi / points)).astype(int) % n
    j = (i + 1) % n
    a = np.where(i % 2 == 0, r_out, r_in)
    b = np.where(j % 2 == 0, r_out, r_in)
    pa = np.c_[a * np.cos(i * math.pi / points), a * np.sin(i * math.pi / points)]
    pb = np.c_[b * np.cos(j * math.pi / points), b * np.sin(j * math.pi / points)]
    e = pb - pa
    cross = e[:, 0] * (p[:, 1] - pa[:, 1]) - e[:, 1] * (p[:, 0] - pa[:, 0])
    return (cross > 0) & (p[:, 2] > 0) & (p[:, 2] < height)


def lhuilier_winding(v: np.ndarray, tris: np.ndarray, p: np.ndarray) -> float:
    """Winding number of point p by L'Huilier's theorem (solid angle = 4 atan sqrt(...)),
    the sign from the triple product: a plain per-triangle loop."""
    total = 0.0
    for t in tris:
        a, b, c = (v[k] - p for k in t)
        ua, ub, uc = (x / np.linalg.norm(x) for x in (a, b, c))
        sa = math.acos(np.clip(ub @ uc, -1, 1))
        sb = math.acos(np.clip(uc @ ua, -1, 1))
        sc = math.acos(np.clip(ua @ ub, -1, 1))
        s = 0.5 * (sa + sb + sc)
        prod = math.tan(s / 2) * math.tan((s - sa) / 2) * math.tan((s - sb) / 2)
        prod *= math.tan((s - sc) / 2)
        omega = 4.0 * math.atan(math.sqrt(max(prod, 0.0)))
        total += math.copysign(omega, float(a @ np.cross(b, c)))
    return total / (4.0 * math.pi)


def write_binary_stl(path, v, tris, scale=1.0):
    """A binary STL (triangle soup, float32) of the mesh, coordinates × ``scale``."""
    with open(path, "wb") as f:
        f.write(b"adept_traj test".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", 0.0, 0.0, 0.0))
            for k in t:
                f.write(struct.pack("<3f", *(v[k] * scale)))
            f.write(b"\0\0")


def write_obj(path, v, tris):
    with open(path, "w", encoding="ascii") as f:
        f.writelines(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in v)
        f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in tris)


def write_dae(path, v, tris):
    pos = " ".join(repr(float(x)) for x in v.ravel())
    idx = " ".join(str(int(i)) for i in tris.ravel())
    path.write_text(
        '<?xml version="1.0" encoding="utf-8"?>\n'
        '<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">'
        '<asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>'
        '<library_geometries><geometry id="g"><mesh>'
        f'<source id="p"><float_array id="pa" count="{v.size}">{pos}</float_array>'
        f'<technique_common><accessor source="#pa" count="{len(v)}" stride="3">'
        '<param name="X" type="float"/><param name="Y" type="float"/>'
        '<param name="Z" type="float"/></accessor></technique_common></source>'
        '<vertices id="vx"><input semantic="POSITION" source="#p"/></vertices>'
        f'<triangles count="{len(tris)}"><input semantic="VERTEX" source="#vx" offset="0"/>'
        f"<p>{idx}</p></triangles></mesh></geometry></library_geometries>"
        '<library_visual_scenes><visual_scene id="s"><node id="n">'
        '<instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>'
        '<scene><instance_visual_scene url="#s"/></scene></COLLADA>',
        encoding="utf-8",
    )


@pytest.fixture(scope="module")
def star():
    return star_prism()


@pytest.mark.parametrize("fmt", ["stl", "obj", "dae"])
def test_files_read_scaled_and_closed(tmp_path, star, fmt):
    v, tris = star
    path = tmp_path / f"star.{fmt}"
    if fmt == "stl":
        write_binary_stl(path, v, tris, scale=1000.0)  # CAD in mm
        mesh = Mesh.from_file(path, 0.001)
    elif fmt == "obj":
        write_obj(path, v, tris)
        mesh = Mesh.from_file(path)
    else:
        write_dae(path, v, tris)
        mesh = Mesh.from_file(path)
    assert mesh.closed
    assert mesh.n_triangles == len(tris)
    # every written triangle is there, as a set of corner coordinates (to float32 rounding)
    got = np.sort(np.round(mesh.vertices[mesh.triangles], 6).reshape(len(tris), -1), axis=0)
    want = np.sort(
        np.round(v[tris].astype(np.float32).astype(float), 6).reshape(len(tris), -1), axis=0
    )
    np.testing.assert_allclose(got, want, atol=2e-6)
    assert mesh.source == str(path.resolve())


def test_inside_test_against_independent_references(star):
    v, tris = star
    mesh = Mesh(v, tris)
    rng = np.random.default_rng(RNG_SEED)
    p = rng.uniform([-0.35, -0.35, -0.05], [0.35, 0.35, 0.45], size=(400, 3))
    expected = star_inside(p)
    assert 40 < expected.sum() < 360  # both kinds are tested
    np.testing.assert_array_equal(mesh.contains(p), expected)
    for k in range(0, 400, 40):  # the loop reference on a subset
        assert abs(lhuilier_winding(v, tris, p[k]) - float(expected[k])) < 1e-9
        assert abs(mesh.winding_number(p[k : k + 1])[0] - float(expected[k])) < 1e-9


def _solids():
    return [coal.Box(0.04, 0.06, 0.05), coal.Cylinder(0.02, 0.08), coal.Capsule(0.015, 0.05)]


def test_distances_are_coal_outside_and_negative_inside(star):
    """Every solid pose: the functor equals coal.distance on the BVH called directly where
    the solid is outside the mesh (reference: the closed-form star inside of its centre and
    coal's own collision), and is -coal.distance where the solid is wholly inside."""
    v, tris = star
    mesh = Mesh(v, tris)
    bvh = mesh.to_coal()
    pose_m = at.transforms.transform_from_xyz_rpy((0.3, -0.2, 0.1), (0.2, -0.1, 0.7))
    tf_m = coal.Transform3s(pose_m[:3, :3], pose_m[:3, 3])
    rng = np.random.default_rng(RNG_SEED)
    seen = {"inside": 0, "outside": 0, "touch": 0}
    for solid in _solids():
        functor = distance_functor(solid, mesh.to_coal(), mesh)
        for _ in range(150):
            local = rng.uniform([-0.3, -0.3, -0.1], [0.3, 0.3, 0.5])
            rot = at.transforms.rotation_from_rpy(rng.uniform(-math.pi, math.pi, 3))
            world = pose_m[:3, :3] @ local + pose_m[:3, 3]
            tf_s = coal.Transform3s(rot, world)
            req, res = coal.DistanceRequest(), coal.DistanceResult()
            direct = coal.distance(solid, tf_s, bvh, tf_m, req, res)
            res2 = coal.DistanceResult()
            got = functor(tf_s, tf_m, coal.DistanceRequest(), res2)
            if direct <= 0.0:
                seen["touch"] += 1
                assert got == direct
            elif star_inside(local[None])[0]:
                seen["inside"] += 1
                assert got == -direct
            else:
                seen["outside"] += 1
                assert got == direct
    assert min(seen.values()) > 10, seen


def test_robot_solid_inside_a_closed_mesh_is_colliding(star):
    """The AdeptOne XL's tool solids inside a big closed star prism: the checker (broad
    phase, branch and bound, exact) reports negative distances; a box of the same bounding
    box agrees on the sign of every pair."""
    robot = at.Robot.adept_one_xl()
    q = np.array([[[0.0, 0.5, 0.05, 0.0]]])
    tool = robot.tool_pose(q[0])[0, :3, 3]
    v, tris = star_prism(r_out=0.8, r_in=0.6, height=0.6)
    mesh = Mesh(v, tris)
    scene = Scene((Obstacle("star", mesh, FixedPose.from_xyz_rpy(tool - [0, 0, 0.3])),))
    checker = CollisionChecker(robot, scene)
    exact = checker.distances(q, np.zeros((1, 1)), exact=True).distance[0, 0, :, 0]
    broad = checker.distances(q, np.zeros((1, 1))).distance[0, 0, :, 0]
    mind = checker.min_distances(q, np.zeros((1, 1))).distance[0, 0]
    # which solids are inside: coal's own nearest-point check, independent of the library
    inside = []
    frames = robot.kinematics.joint_frames(q.reshape(-1, 4))
    for k, _g in enumerate(robot.collision_model.geometryObjects):
        pose = checker.broad_phase.solid_poses(frames, np.array([0]), k)[0]
        local = np.linalg.inv(scene.obstacles[0].pose(0.0)) @ pose[:, 3]
        inside.append(bool(star_inside(local[None, :3], r_out=0.8, r_in=0.6, height=0.6)[0]))
    assert any(inside)
    assert all(exact[k] < 0 for k in range(len(inside)) if inside[k])
    assert mind < 0
    assert mind == pytest.approx(exact.min(), abs=1e-9)
    assert (broad <= exact + 1e-9).all()


def test_broad_phase_bounds_are_lower_bounds_for_meshes(star):
    robot = at.Robot.adept_one_xl()
    v, tris = star_prism(r_out=0.4, r_in=0.2, height=0.5)
    scene = Scene(
        (Obstacle("star", Mesh(v, tris), FixedPose.from_xyz_rpy((0.8, 0.1, 0.3), (0, 0, 0.3))),)
    )
    checker = CollisionChecker(robot, scene, influence=1.0)
    rng = np.random.default_rng(RNG_SEED)
    lo, hi = robot.limits.lower, robot.limits.upper
    q = rng.uniform(np.maximum(lo, -2.5), np.minimum(hi, 2.5), size=(1, 300, 4))
    t = np.zeros((1, 300))
    exact = checker.distances(q, t, exact=True).distance
    bounds = checker.broad_phase.bounds(
        robot.kinematics.joint_frames(q[0]), checker.obstacle_poses(t)
    )
    assert (bounds.lower.reshape(exact.shape) <= exact + 1e-9).all()
    assert (exact < 0).any()
    assert (exact > 0).any()


def test_open_mesh_warns_and_has_no_inside(star):
    v, tris = star
    with pytest.warns(OpenMeshWarning, match="not closed"):
        sheet = Mesh(v, tris[1:])
    assert not sheet.closed
    assert not sheet.contains([[0.0, 0.0, 0.2]]).any()
    inverted = tris[:, ::-1]  # consistently reversed: still closed
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert Mesh(v, inverted).closed


def test_bad_mesh_files(tmp_path):
    with pytest.raises(MeshFileError, match=r"nope\.stl.*does not exist"):
        Mesh.from_file(tmp_path / "nope.stl")
    bad = tmp_path / "bad.stl"
    bad.write_bytes(b"garbage")
    with pytest.raises(MeshFileError, match=r"bad\.stl.*cannot be read"):
        Mesh.from_file(bad)
    with pytest.raises(MeshFileError, match="suffix"):
        Mesh.from_file(tmp_path / "part.step")
    with pytest.raises(at.InvalidInputError, match="scale"):
        Mesh.from_file(bad, -1.0)


def test_scene_file_mesh_round_trip_and_errors(tmp_path, star):
    v, tris = star
    (tmp_path / "cad").mkdir()
    write_binary_stl(tmp_path / "cad" / "star.stl", v, tris, scale=1000.0)
    text = (
        '[[obstacle]]\nname = "fixture"\nshape = "mesh"\nfile = "cad/star.stl"\n'
        "scale = 0.001\nxyz = [0.8, 0.1, 0.0]\nrpy = [0.0, 0.0, 0.5]\n"
    )
    (tmp_path / "cell.toml").write_text(text, encoding="utf-8")
    scene = Scene.from_file(tmp_path / "cell.toml")
    mesh = scene.obstacles[0].shape
    assert isinstance(mesh, Mesh)
    assert mesh.closed
    np.testing.assert_allclose(mesh.bounding_radius, math.hypot(0.3, 0.4), rtol=1e-6)
    again = Scene.from_dict(scene.to_dict())
    assert again == scene
    (tmp_path / "missing.toml").write_text(text.replace("star.stl", "gone.stl"), "utf-8")
    with pytest.raises(MeshFileError, match=r"missing\.toml.*file.*gone\.stl"):
        Scene.from_file(tmp_path / "missing.toml")
    (tmp_path / "cad" / "broken.obj").write_text("f 1 2 3\n", encoding="ascii")
    (tmp_path / "broken.toml").write_text(text.replace("star.stl", "broken.obj"), "utf-8")
    with pytest.raises(MeshFileError, match=r"broken\.obj"):
        Scene.from_file(tmp_path / "broken.toml")
    with pytest.raises(SceneError, match="scale"):
        Scene.from_dict({"obstacle": [{"name": "m", "shape": "mesh", "file": "x.stl", "scale": 0}]})


def test_mesh_and_box_agree_on_a_box_mesh():
    """A mesh of a box's 12 triangles gives the box's distances outside it (coal on the
    primitive) and the same sign inside: over random robot configurations."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * 0.15
    hull = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
            (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]  # fmt: skip
    mesh = Mesh(corners, np.array(hull))
    assert mesh.closed
    robot = at.Robot.adept_one_xl()
    pose = FixedPose.from_xyz_rpy((0.75, -0.2, 0.5))
    a = CollisionChecker(robot, Scene((Obstacle("m", mesh, pose),)))
    b = CollisionChecker(robot, Scene((Obstacle("b", Box([0.3, 0.3, 0.3]), pose),)))
    rng = np.random.default_rng(RNG_SEED)
    q = rng.uniform([-0.6, 0.0, 0.0, -1.0], [0.6, 1.2, 0.195, 1.0], size=(1, 200, 4))
    t = np.zeros((1, 200))
    dm = a.distances(q, t, exact=True).distance
    db = b.distances(q, t, exact=True).distance
    outside = db > 1e-6
    np.testing.assert_allclose(dm[outside], db[outside], atol=1e-6)
    assert (dm[db < -1e-6] < 0).all()
    assert (db < -1e-6).any()


def test_meshcat_and_wireframe_of_a_mesh(star):
    from adept_traj.viz import meshcat_geometry  # its meshcat import filters a warning
    from adept_traj.viz.meshcat_geometry import shape_parts
    from adept_traj.viz.plots.wireframes import shape_wireframe

    v, tris = star
    mesh = Mesh(v, tris)
    (part,) = shape_parts(mesh, meshcat_geometry.mg.MeshLambertMaterial())
    np.testing.assert_allclose(np.asarray(part.obj.geometry.vertices), v, atol=1e-7)  # float32
    np.testing.assert_array_equal(np.asarray(part.obj.geometry.faces), tris)
    lines = np.concatenate(shape_wireframe(mesh, np.eye(4)))  # its bounding box's edges
    np.testing.assert_allclose(lines.min(axis=0), v.min(axis=0))
    np.testing.assert_allclose(lines.max(axis=0), v.max(axis=0))
