"""Point-cloud obstacles (adept_traj.scene.point_clouds): files of every format written here
and read back, distances against the points themselves (closed-form point–box distances:
the octree's distance is at most the points' and at least that minus a cell diagonal),
coal called directly, the memory limit checked from the header before any data is read,
scene files and the certificate's statement of the resolution."""

from __future__ import annotations

import math

import coal
import numpy as np
import pytest

import adept_traj as at
from adept_traj.collision import CollisionChecker
from adept_traj.errors import MeshFileError, ResourceLimitError
from adept_traj.scene import FixedPose, Obstacle, PointCloud, Scene, scene_notes


@pytest.fixture(scope="module")
def points():
    rng = np.random.default_rng(2829)
    return rng.uniform([-0.2, -0.2, 0.0], [0.2, 0.2, 0.05], (3000, 3))


def write_ply(path, p, binary):
    head = f"ply\nformat {'binary_little_endian' if binary else 'ascii'} 1.0\n"
    head += f"element vertex {len(p)}\nproperty float x\nproperty float y\nproperty float z\n"
    head += "property uchar red\nend_header\n"
    with open(path, "wb") as f:
        f.write(head.encode("ascii"))
        if binary:
            rec = np.zeros(len(p), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("r", "u1")])
            rec["x"], rec["y"], rec["z"] = p.T
            f.write(rec.tobytes())
        else:
            f.write("".join(f"{x:.9g} {y:.9g} {z:.9g} 7\n" for x, y, z in p).encode("ascii"))


def write_pcd(path, p, binary):
    head = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
        f"WIDTH {len(p)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(p)}\n"
        f"DATA {'binary' if binary else 'ascii'}\n"
    )
    with open(path, "wb") as f:
        f.write(head.encode("ascii"))
        if binary:
            f.write(p.astype("<f4").tobytes())
        else:
            f.write("".join(f"{x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in p).encode("ascii"))


@pytest.mark.parametrize("fmt", ["npy", "xyz", "ply", "ply-binary", "pcd", "pcd-binary"])
def test_every_format_reads_the_points(tmp_path, points, fmt):
    path = tmp_path / f"scan.{fmt.split('-')[0]}"
    binary = fmt.endswith("binary")
    if fmt == "npy":
        np.save(path, points)
    elif fmt == "xyz":
        path.write_text("".join(f"{x!r} {y!r} {z!r}\n" for x, y, z in points.tolist()), "ascii")
    elif fmt.startswith("ply"):
        write_ply(path, points, binary)
    else:
        write_pcd(path, points, binary)
    cloud = PointCloud.from_file(path, 0.01)
    tol = 0.0 if fmt in ("npy", "xyz") else 1e-7  # float32 files
    np.testing.assert_allclose(cloud.points, points, atol=tol)
    assert cloud.n_points == len(points)


def _box_point_distance(pose, half, p):
    """Closed-form distance of points p (n, 3) to a box (pose (4, 4), half sides (3,))."""
    local = (p - pose[:3, 3]) @ pose[:3, :3]
    outside = np.maximum(np.abs(local) - half, 0.0)
    inside = np.minimum(np.max(np.abs(local) - half, axis=1), 0.0)
    return np.linalg.norm(outside, axis=1) + inside


def test_distances_bracket_the_points(points):
    """For box solids at random poses: the checker's distance is coal's (called directly on
    makeOctree) and lies in [d_points − r√3, d_points] when positive (d_points: the
    smallest closed-form distance to the points); a box holding a point gets ≤ 0."""
    r = 0.01
    cloud = PointCloud(points, r)
    octree = coal.makeOctree(np.array(points), r)
    rng = np.random.default_rng(7)
    half = np.array([0.02, 0.03, 0.04])
    solid = coal.Box(*(2 * half))
    checked = 0
    for _ in range(150):
        pose = at.transforms.transform_from_xyz_rpy(
            rng.uniform([-0.25, -0.25, -0.05], [0.25, 0.25, 0.15]), rng.uniform(-3, 3, 3)
        )
        res = coal.DistanceResult()
        d = coal.distance(
            solid, coal.Transform3s(pose[:3, :3], pose[:3, 3]), octree, coal.Transform3s(),
            coal.DistanceRequest(), res,
        )  # fmt: skip
        d_points = _box_point_distance(pose, half, points).min()
        if d_points <= 0.0:
            assert d <= 1e-9
        else:
            assert d <= d_points + 1e-9
            assert d >= d_points - r * math.sqrt(3) - 1e-9
            checked += 1
    assert checked > 30
    # the same through the checker, a robot at many configurations, cloud near its path
    robot, paper = at.Robot.adept_one_xl(), Scene.paper()
    where = FixedPose.from_xyz_rpy((0.9, 0.5, 0.45))
    scene = Scene((Obstacle("scan", cloud, where),), robot_base=paper.robot_base)
    checker = CollisionChecker(robot, scene, influence=1.0)
    q = rng.uniform([-0.5, 0.0, 0.0, -1.0], [0.5, 1.4, 0.195, 1.0], (1, 120, 4))
    t = np.zeros((1, 120))
    exact = checker.distances(q, t, exact=True).distance
    broad = checker.distances(q, t).distance
    assert (broad <= exact + 1e-9).all()
    frames = robot.kinematics.joint_frames(q[0])
    to_cloud = np.linalg.inv(scene.base_from_world @ where.transform)
    for n, k in zip(*np.nonzero(exact[0, :, :, 0] < 0.3)):
        pose = to_cloud @ checker.broad_phase.solid_poses(frames, np.array([n]), int(k))[0]
        geom = robot.collision_model.geometryObjects[int(k)].geometry
        tf = coal.Transform3s(pose[:3, :3], pose[:3, 3])
        request = coal.DistanceRequest()
        request.gjk_tolerance = 1e-9  # as the package's calls
        direct = coal.distance(geom, tf, octree, coal.Transform3s(), request, coal.DistanceResult())
        if direct < 0.0:  # a penetration: one leaf's depth (coal's first, the checker's
            assert exact[0, n, k, 0] < 0.0  # least-bound leaf: cloud_distance)
        else:
            assert exact[0, n, k, 0] == pytest.approx(direct, abs=1e-9)


def test_too_large_cloud_refused_before_reading(tmp_path, points):
    np.save(tmp_path / "scan.npy", points)
    with pytest.raises(ResourceLimitError, match=r"scan\.npy.*3000 points"):
        PointCloud.from_file(tmp_path / "scan.npy", 0.01, budget=100_000)
    huge = tmp_path / "huge.ply"  # a header promising 10¹² points, no data
    huge.write_bytes(b"ply\nformat ascii 1.0\nelement vertex 1000000000000\nproperty float x\n"
                     b"property float y\nproperty float z\nend_header\n")  # fmt: skip
    with pytest.raises(ResourceLimitError, match=r"huge\.ply.*1000000000000 points"):
        PointCloud.from_file(huge, 0.01)


def test_bad_cloud_files(tmp_path):
    with pytest.raises(MeshFileError, match=r"none\.pcd.*does not exist"):
        PointCloud.from_file(tmp_path / "none.pcd", 0.01)
    bad = tmp_path / "bad.ply"
    bad.write_bytes(b"ply\nformat ascii 1.0\nelement face 3\nend_header\n")
    with pytest.raises(MeshFileError, match=r"bad\.ply.*cannot be read.*vertex element"):
        PointCloud.from_file(bad, 0.01)
    short = tmp_path / "short.pcd"
    short.write_bytes(b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 10\nDATA binary\n\0\0")
    with pytest.raises(MeshFileError, match=r"short\.pcd.*cannot be read"):
        PointCloud.from_file(short, 0.01)
    with pytest.raises(at.InvalidInputError, match="resolution"):
        PointCloud(np.zeros((1, 3)), 0.0)


def test_scene_file_cloud_and_the_stated_resolution(tmp_path, points):
    np.save(tmp_path / "scan.npy", points)
    text = (
        '[[obstacle]]\nname = "scan"\nshape = "cloud"\nfile = "scan.npy"\n'
        "resolution = 0.01\nxyz = [0.9, 0.5, 0.45]\n"
    )
    (tmp_path / "cell.toml").write_text(text, encoding="utf-8")
    scene = Scene.from_file(tmp_path / "cell.toml")
    assert isinstance(scene.obstacles[0].shape, PointCloud)
    assert Scene.from_dict(scene.to_dict()) == scene
    (note,) = scene_notes(scene)
    assert "'scan' (3000 points)" in note
    assert "0.01 m octree" in note
    (tmp_path / "bad.toml").write_text(text.replace("scan.npy", "gone.npy"), "utf-8")
    with pytest.raises(MeshFileError, match=r"bad\.toml.*gone\.npy"):
        Scene.from_file(tmp_path / "bad.toml")


def test_meshcat_draws_a_subsample_of_a_large_cloud():
    from adept_traj.viz import meshcat_geometry  # its meshcat import filters a warning
    from adept_traj.viz.meshcat_geometry import MAX_DRAWN_POINTS, shape_parts

    rng = np.random.default_rng(3)
    cloud = PointCloud(rng.uniform(size=(250_001, 3)), 0.01)
    (part,) = shape_parts(cloud, meshcat_geometry.mg.MeshLambertMaterial())
    drawn = np.asarray(part.obj.geometry.position)
    assert drawn.shape == (3, 83_334)
    assert drawn.shape[1] <= MAX_DRAWN_POINTS
    np.testing.assert_allclose(drawn.T, cloud.points[::3], atol=1e-7)  # float32


def test_cube_field_counted_and_refused_before_any_field(tmp_path, monkeypatch):
    """A few points spread over 20 m: the points alone fit a 120 MiB budget, the checker's
    cube-distance field (8·10⁶ cells) does not — refused once read, naming the file, the
    field's cells and the limit, before any distance field is made."""
    from adept_traj.scene import point_clouds

    rng = np.random.default_rng(7)
    spread = rng.uniform(0.0, 20.0, (3000, 3))
    np.save(tmp_path / "hall.npy", spread)

    def no_field(*args):
        raise AssertionError("a distance field was made before the memory check")

    monkeypatch.setattr(point_clouds, "_coarse_field", no_field)
    with pytest.raises(
        ResourceLimitError,
        match=r"hall\.npy.*3000 points.*120.0 MiB.*cube-distance field, \d+ cells",
    ):
        PointCloud.from_file(tmp_path / "hall.npy", 0.01, budget=120 * 2**20)
    monkeypatch.setattr(at.memory, "memory_budget", lambda: 120 * 2**20)  # an array too
    with pytest.raises(ResourceLimitError, match=r"an array \(3000 points\).*cube-distance"):
        PointCloud(spread, 0.01)


def test_cloud_estimate_bounds_the_measured_peak():
    """tracemalloc's peak while a cloud, its leaf arrays, their hierarchy and its
    cube-distance field are made (numpy and scipy; coal's octree is C++, counted
    separately in the estimate) stays below :func:`cloud_bytes` of its points and field
    cells."""
    import tracemalloc

    from adept_traj.collision.cloud_distance import CloudCells
    from adept_traj.collision.cloud_tree import CloudTree
    from adept_traj.scene.point_clouds import cloud_bytes, cube_field_step

    rng = np.random.default_rng(8)
    a = rng.uniform(0.0, 2.0 * np.pi, 60_000)
    p = np.column_stack([0.6 * np.cos(a), 0.6 * np.sin(a), rng.uniform(0.0, 0.5, len(a))])
    octree = coal.makeOctree(p, 0.01)
    tracemalloc.start()
    try:
        cloud = PointCloud(p, 0.01)
        cells = CloudCells(octree)
        field = cells.field[2]
        tree = CloudTree(cells)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    _, n_cells = cube_field_step(p.min(axis=0) - 0.01, p.max(axis=0) + 0.01, 0.01)
    assert field.size <= n_cells
    assert cloud.n_points == len(p)
    assert len(tree.leaf_half) == len(cells.half)
    assert field.size > 500_000  # the field is the large part here
    assert peak <= cloud_bytes(len(p), n_cells), (peak, cloud_bytes(len(p), n_cells))
