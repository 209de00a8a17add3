"""Meshcat playback: the animation's frames and poses, the self-contained HTML page rendered
for real in headless Chromium (two instants), and the live viewer bound to 127.0.0.1."""

from __future__ import annotations

import base64
import html
import math
import os
import re
import shutil
import subprocess
import sys
import urllib.request
from pathlib import Path

import coal
import numpy as np
import pytest
import umsgpack

from adept_traj.errors import InvalidInputError
from adept_traj.problem import BSplineTrajectory, TrajectoryProblem
from adept_traj.results import PlanningResult, Replay, RobotInfo
from adept_traj.scene import FixedPose, Obstacle, Scene, Sphere
from adept_traj.testing.paper_moves import lift_then_lower, single_result
from adept_traj.viz import meshcat_scene, playback, server
from adept_traj.viz.playback import MeshcatPath

CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--host-resolver-rules=MAP * ~NOTFOUND",  # no network: the page must not need it
    "--window-size=800,600",
]
BUDGETS_MS = (300, 1500)  # two instants of the animation (T = 2.1 s, real time)


@pytest.fixture(scope="module")
def result(problem: TrajectoryProblem) -> PlanningResult:
    return single_result(problem, lift_then_lower(problem))


@pytest.fixture(scope="module")
def page(result: PlanningResult, tmp_path_factory: pytest.TempPathFactory) -> Path:
    return meshcat_scene.static_html(
        result, tmp_path_factory.mktemp("viz") / "run" / "playback.html"
    )


# ============================================================================ no server
def test_viz_package_is_lazy() -> None:
    code = (
        "import sys, adept_traj, adept_traj.viz as v\n"
        "assert 'meshcat' not in sys.modules and 'matplotlib' not in sys.modules\n"
        "assert v.__all__ == ['meshcat_scene', 'playback', 'plots', 'server']\n"
        "v.plots, v.playback\n"
        "assert 'meshcat' in sys.modules and 'matplotlib' not in sys.modules\n"
        "try:\n    v.nothing\nexcept AttributeError:\n    pass\nelse:\n    raise SystemExit(1)\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr


def test_frames_and_poses(result: PlanningResult, problem: TrajectoryProblem) -> None:
    pb = playback.build_animation(result, show_closest=True)
    T = float(result.best_x[0])
    assert pytest.approx(2.1) == T
    assert pb.duration == pytest.approx(T)
    assert pb.n_frames == math.ceil(30 * T) + 1
    assert pb.times[0] == 0.0
    assert pb.times[-1] == T
    np.testing.assert_allclose(pb.frame_numbers, pb.times * 30, atol=1e-9)
    np.testing.assert_allclose(pb.q[0], problem.start, atol=1e-12)
    np.testing.assert_allclose(pb.q[-1], problem.goal, atol=1e-12)

    objects = {o.path: o for o in pb.objects}
    robot, scene = problem.robot, problem.scene
    # every visual solid of the robot, in the WORLD frame, in the visual model's colours
    names = [g.name for g in robot.visual_model.geometryObjects]
    assert {f"robot/{n}" for n in names} <= set(objects)
    k = names.index("link4/gripper")
    world = scene.robot_base @ robot.geometry_poses(pb.q, robot.visual_model)[:, k]
    np.testing.assert_allclose(objects["robot/link4/gripper"].poses, world, atol=1e-12)
    mesh = objects["robot/link4/gripper"].parts[0].obj
    assert mesh.material.color == 0xD9731A  # rgba 0.85 0.45 0.1 of the URDF
    np.testing.assert_allclose(mesh.geometry.lengths, [0.12, 0.06, 0.05])
    quill = objects["robot/link4/quill"].parts[0]  # meshcat cylinder: y axis turned onto z
    np.testing.assert_allclose(quill.local[:3, :3] @ [0, 1, 0], [0, 0, 1], atol=1e-15)
    # fixed obstacles static, the pendulum animated at the physical time of each frame
    assert not objects["obstacles/cube1"].animated
    np.testing.assert_allclose(objects["obstacles/cube1"].poses[:3, 3], [0.9, 0.7, 0.15])
    bob = objects["obstacles/pendulum.bob"]
    assert bob.animated
    np.testing.assert_allclose(bob.poses, scene.obstacle("pendulum.bob").pose(pb.times))
    # tool path from start to goal, world frame
    tool = scene.robot_base @ robot.tool_pose(np.vstack([problem.start, problem.goal]))
    np.testing.assert_allclose(pb.tool_path[[0, -1]], tool[:, :3, 3], atol=1e-12)
    # closest points: coal's distances pair by pair, the segment joins the two witness points
    exact, _ = coal_nearest(problem, pb.q, pb.times)
    np.testing.assert_allclose(pb.closest_distance, exact, atol=1e-9)
    gap = np.linalg.norm(pb.closest_points[:, 1] - pb.closest_points[:, 0], axis=-1)
    np.testing.assert_allclose(gap, np.abs(pb.closest_distance), atol=1e-9)
    seg = objects["closest/segment"]
    ends = seg.poses[:, :3, :3] @ (seg.scales * [0, 0.5, 0])[..., None]
    np.testing.assert_allclose(seg.poses[:, :3, 3] + ends[..., 0], pb.closest_points[:, 1])
    # the animation: one clip per moving node, keyframes in frames at the playback fps
    anim = pb.animation()
    clip = anim.clips[MeshcatPath(("meshcat", "robot", "link4", "gripper"))]
    assert clip.fps == 30.0
    assert clip.tracks["position"].frames[-1] == pytest.approx(30 * T)
    assert MeshcatPath(("meshcat", "obstacles", "cube1")) not in anim.clips


def coal_nearest(problem: TrajectoryProblem, q: np.ndarray, times: np.ndarray):
    """Reference: per frame, coal's distance and witness points of the nearest (collision
    solid, obstacle) pair over every pair, world frame."""
    robot, scene = problem.robot, problem.scene
    solids = scene.robot_base @ robot.geometry_poses(q)
    obstacles = scene.obstacle_poses(times)
    request, res = coal.DistanceRequest(), coal.DistanceResult()
    request.gjk_tolerance = 1e-9  # coal's default 1e-6 leaves up to ~1 µm (docs: 'exact')
    distance, points = np.full(len(q), np.inf), np.zeros((len(q), 2, 3))
    for k in range(len(q)):
        for s, g in enumerate(robot.collision_model.geometryObjects):
            for o, ob in enumerate(scene.obstacles):
                a, b = solids[k, s], obstacles[o, k]
                res.clear()
                d = coal.distance(
                    g.geometry,
                    coal.Transform3s(a[:3, :3], a[:3, 3]),
                    ob.shape.to_coal(),
                    coal.Transform3s(b[:3, :3], b[:3, 3]),
                    request,
                    res,
                )
                if d < distance[k]:
                    distance[k] = d
                    points[k] = res.getNearestPoint1(), res.getNearestPoint2()
    return distance, points


def test_closest_points_match_coal(result: PlanningResult, problem: TrajectoryProblem) -> None:
    pb = playback.build_animation(result, fps=10, show_closest=True)
    distance, points = coal_nearest(problem, pb.q, pb.times)
    np.testing.assert_allclose(pb.closest_distance, distance, atol=1e-9)
    np.testing.assert_allclose(pb.closest_points, points, atol=1e-6)


def test_closest_penetration_depth_of_a_sphere_in_a_cylinder(
    problem: TrajectoryProblem,
) -> None:
    """A small ball inside the quill (a cylinder) near its upper cap at the start: the drawn
    depth is the exact one, |z| − h, not coal 3.0.3's radial depth."""
    robot = problem.robot
    names = [g.name for g in robot.collision_model.geometryObjects]
    quill = robot.collision_model.geometryObjects[names.index("link4/quill")].geometry
    radius, half, ball = float(quill.radius), float(quill.halfLength), 0.004
    local = np.array([0.3 * radius, 0.0, half - 0.3 * radius])  # inside, 7.5 mm under the cap
    pose = (
        problem.scene.robot_base @ robot.geometry_poses(problem.start)[names.index("link4/quill")]
    )
    centre = np.eye(4)
    centre[:3, 3] = pose[:3, :3] @ local + pose[:3, 3]
    scene = Scene(
        obstacles=(Obstacle("ball", Sphere(ball), FixedPose(centre)),),
        robot_base=problem.scene.robot_base,
    )
    inside = TrajectoryProblem(robot, scene, problem.start, problem.goal)
    try:
        res = single_result(inside, lift_then_lower(inside), rate_hz=100.0)
    finally:
        inside.close()
    pb = playback.build_animation(res, fps=5, show_closest=True)
    depth = max(math.hypot(local[0], local[1]) - radius, abs(local[2]) - half) - ball
    assert depth == pytest.approx(-0.0115)
    assert pb.closest_distance[0] == pytest.approx(depth, abs=1e-9)
    gap = np.linalg.norm(pb.closest_points[0, 1] - pb.closest_points[0, 0])
    assert gap == pytest.approx(-depth, abs=1e-9)


def test_nothing_is_rebuilt_with_a_replay(
    result: PlanningResult, problem: TrajectoryProblem, monkeypatch: pytest.MonkeyPatch
) -> None:
    """No TrajectoryProblem is rebuilt (no collision tables); the robot files are loaded once
    per call without a replay and never with one."""
    loads = []
    load = RobotInfo.load
    monkeypatch.setattr(RobotInfo, "load", lambda info: loads.append(1) or load(info))

    def no_problem(*_args: object, **_kwargs: object) -> None:
        raise AssertionError("result.problem() called")

    monkeypatch.setattr(PlanningResult, "problem", no_problem)
    playback.build_animation(result, show_closest=True)
    assert len(loads) == 1
    replay = Replay.of(result, robot=problem.robot, scene=problem.scene)
    pb = playback.build_animation(result, show_closest=True, replay=replay)
    assert len(loads) == 1
    np.testing.assert_allclose(pb.q[[0, -1]], [problem.start, problem.goal], atol=1e-12)


def test_replay_of_another_solution(result: PlanningResult, problem: TrajectoryProblem) -> None:
    x = np.array(result.best_x, dtype=float)
    x[0] *= 1.5  # a slower move
    other = Replay.of(result, x, robot=problem.robot, scene=problem.scene)
    with pytest.raises(InvalidInputError, match="best_x"):
        playback.build_animation(result, replay=other)
    with pytest.raises(InvalidInputError, match="replay must be of type Replay"):
        playback.build_animation(result, replay=problem)
    # the same x from another start: another move (the viewer used to check x alone)
    moved = BSplineTrajectory(
        result.start + 0.05, result.goal, n_knots=int(result.problem_settings.n_knots)
    )
    elsewhere = Replay(problem.robot, problem.scene, moved, result.best_x)
    with pytest.raises(InvalidInputError, match="start, goal"):
        playback.build_animation(result, replay=elsewhere)


def test_speed_and_fps(result: PlanningResult) -> None:
    slow = playback.build_animation(result, speed=0.5, fps=10)
    T = slow.duration
    assert slow.n_frames == math.ceil(10 * T / 0.5) + 1
    assert slow.playback_duration == pytest.approx(2 * T)
    np.testing.assert_allclose(np.diff(slow.times)[:-1], 0.05)
    assert slow.closest_points is None
    assert not any(o.path.startswith("closest/") for o in slow.objects)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"speed": 0}, "speed"),
        ({"speed": -1.0}, "speed"),
        ({"speed": float("nan")}, "speed"),
        ({"speed": float("inf")}, "speed"),
        ({"speed": "1"}, "speed"),
        ({"fps": 0}, "fps"),
        ({"fps": True}, "fps"),
        ({"fps": 1e7}, "MAX_FRAMES"),
        ({"show_closest": "yes"}, "show_closest"),
    ],
)
def test_bad_input(result: PlanningResult, kwargs: dict, match: str, tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match=match):
        playback.build_animation(result, **kwargs)
    with pytest.raises(InvalidInputError, match=match):
        meshcat_scene.static_html(result, tmp_path / "p.html", **kwargs)
    with pytest.raises(InvalidInputError, match=match):  # before any server starts
        server.show(result, **kwargs)
    assert not (tmp_path / "p.html").exists()


def test_not_a_result(tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match="PlanningResult"):
        meshcat_scene.static_html("out", tmp_path / "p.html")


# ============================================================================ static page
def page_commands(text: str) -> list[dict]:
    block = re.search(r"var adeptTrajCommands = \[(.*?)\];", text, re.S)
    assert block is not None
    return [umsgpack.unpackb(base64.b64decode(s)) for s in re.findall(r'"([^"]+)"', block[1])]


def test_static_html_is_self_contained(page: Path, result: PlanningResult) -> None:
    text = page.read_text(encoding="utf-8")
    assert 0.5e6 < len(text) < 3e6
    assert "MeshCat.Viewer" in text  # the viewer is inlined
    # nothing to fetch: no external script, stylesheet, image, fetch() or import()
    assert not re.search(r"<(?:script|link|img|iframe)\b[^>]*\b(?:src|href)\s*=", text, re.I)
    assert not re.search(r"""(?:fetch|import)\s*\(\s*["'`](?:https?:)?//""", text)
    urls = set(re.findall(r"https?://[^\s\"'<>)]+", text))
    assert all(u.startswith("http://www.w3.org/") for u in urls), urls  # XML namespaces only
    # the scene and the animation are in the page, playing and looping
    commands = page_commands(text)
    drawn = {c["path"] for c in commands if c["type"] == "set_object"}
    assert "/meshcat/robot/link4/gripper/part0" in drawn
    assert "/meshcat/obstacles/pendulum.bob/part0" in drawn
    assert "/meshcat/tool_path/line/part0" in drawn
    (anim,) = [c for c in commands if c["type"] == "set_animation"]
    assert commands[-1] is anim
    assert anim["options"] == {"play": True, "repetitions": math.inf}
    clips = {a["path"]: a["clip"] for a in anim["animations"]}
    assert "/meshcat/obstacles/pendulum.rod" in clips
    assert "/meshcat/obstacles/cube1" not in clips
    keys = clips["/meshcat/robot/link2/outer_arm"]["tracks"][0]["keys"]
    assert len(keys) == math.ceil(30 * float(result.best_x[0])) + 1
    assert keys[-1]["time"] == pytest.approx(30 * float(result.best_x[0]))


def test_same_result_same_page_bytes(page: Path, result: PlanningResult, tmp_path: Path) -> None:
    """meshcat's ids are time-based (uuid1); the page's come from the drawn paths."""
    again = meshcat_scene.static_html(result, tmp_path / "again.html")
    assert again.read_bytes() == page.read_bytes()
    drawn = [
        c for c in page_commands(page.read_text(encoding="utf-8")) if c["type"] == "set_object"
    ]
    ids = [c["object"]["object"]["uuid"] for c in drawn]
    ids += [g["uuid"] for c in drawn for g in c["object"]["geometries"]]
    ids += [m["uuid"] for c in drawn for m in c["object"]["materials"]]
    assert len(ids) == len(set(ids)) == 3 * len(drawn)  # every object, geometry, material
    for c in drawn:  # each object refers to its own geometry and material
        (geometry,), (material,) = c["object"]["geometries"], c["object"]["materials"]
        assert c["object"]["object"]["geometry"] == geometry["uuid"]
        assert c["object"]["object"]["material"] == material["uuid"]


def chromium() -> str:
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        pytest.skip("headless Chromium is not installed (Debian: apt-get install -y chromium)")
    return exe


def screenshot(exe: str, page: Path, png: Path, budget_ms: int, profile: Path) -> np.ndarray:
    import matplotlib.image

    args = [
        exe,
        *CHROMIUM_FLAGS,
        f"--user-data-dir={profile}",
        f"--virtual-time-budget={budget_ms}",
        f"--screenshot={png}",
        page.resolve().as_uri(),
    ]
    try:
        run = subprocess.run(args, capture_output=True, text=True, timeout=60)
    except subprocess.TimeoutExpired:
        pytest.fail(f"headless Chromium did not finish within 60 s: {' '.join(args)}")
    assert png.is_file(), f"no screenshot (exit {run.returncode}): {run.stderr[-2000:]}"
    return matplotlib.image.imread(png)[..., :3]


@pytest.mark.slow  # default-tier time (≤ 3 min): the slow tier runs it in CI (.ci/run)
def test_page_renders_in_headless_chromium(page: Path, tmp_path: Path) -> None:
    exe = chromium()
    shots = [
        screenshot(exe, page, tmp_path / f"t{ms}.png", ms, tmp_path / f"profile{ms}")
        for ms in BUDGETS_MS
    ]
    for img in shots:
        assert img.shape == (600, 800, 3)
        r, g, b = img[..., 0], img[..., 1], img[..., 2]
        drawn = np.abs(img - np.array(meshcat_scene.BACKGROUND_RGB)).max(axis=-1) > 0.03
        assert drawn.mean() > 0.15  # floor, obstacles and robot cover much of the view
        # the robot, in its own colours: blue elbow housing, orange gripper
        assert ((b > r + 0.25) & (b > g + 0.1)).sum() > 300
        assert ((r > 0.7) & (g > 0.3) & (g < 0.6) & (b < 0.25)).sum() > 30
        assert ((r > g + 0.3) & (r > b + 0.3)).sum() > 3000  # the red cubes
        assert ((r > g + 0.15) & (b > g + 0.15)).sum() > 300  # the purple pendulum
    moved = np.abs(shots[0] - shots[1]).max(axis=-1) > 0.1
    assert moved.sum() > 5000  # the robot and the pendulum moved between the two instants


# ============================================================================ live viewer
def listening_addresses(pid: int) -> list[tuple[str, str, int]]:
    """(family, local address hex, port) of every listening TCP socket of process pid."""
    inodes = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        try:
            target = os.readlink(fd)
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    found = []
    for family in ("tcp", "tcp6"):
        rows = Path(f"/proc/net/{family}").read_text().splitlines()[1:]
        for row in rows:
            cols = row.split()
            if cols[3] == "0A" and cols[9] in inodes:  # state LISTEN
                address, port = cols[1].split(":")
                found.append((family, address, int(port, 16)))
    return found


def test_show_serves_on_localhost(
    result: PlanningResult, capsys: pytest.CaptureFixture[str]
) -> None:
    vis = server.show(result, speed=2.0, show_closest=True)
    window = vis.window
    try:
        assert capsys.readouterr().out == ""  # prints nothing (meshcat itself would)
        url = vis.url()
        assert re.fullmatch(r"http://127\.0\.0\.1:\d+/static/", url)
        assert re.fullmatch(r"tcp://127\.0\.0\.1:\d+", window.zmq_url)
        with urllib.request.urlopen(url, timeout=10) as reply:
            assert reply.status == 200
            page = reply.read().decode("utf-8")
        # the live page: the member's label, the legend and the controls of playback.html
        # (driven in a real browser: tests/viz/test_playback_page.py)
        label = re.search(r'<div id="member-label">(.*?)</div>', page)
        assert label is not None
        T = float(result.best_x[0])
        assert html.unescape(label[1]) == (
            f"{result.algorithm} · member 0 of 1 (the best trade-off) · T = {T:.3f} s · certified"
        )
        for element in ('id="legend"', 'id="play-pause"', 'id="scrub"', 'id="time-readout"'):
            assert element in page, element
        assert "closest points, robot to nearest obstacle" in page  # show_closest's entry
        assert '<script src="main.min.js"></script>' in page  # meshcat's viewer, from the server
        assert "viewer.connect();" in page
        with urllib.request.urlopen(url + "main.min.js", timeout=10) as reply:
            assert reply.status == 200
        with urllib.request.urlopen(url + "index.html", timeout=10) as reply:
            assert b"<title>MeshCat</title>" in reply.read()  # meshcat's own page stays
    finally:
        vis.close()
    assert window.closed
    assert window.server_proc.poll() is not None
    vis.close()  # idempotent


@pytest.mark.skipif(not Path("/proc/net/tcp").is_file(), reason="needs Linux /proc/net/tcp")
def test_show_listens_on_the_loopback_address_only(result: PlanningResult) -> None:
    """The server's only listening sockets (read from /proc) are its two ports on
    127.0.0.1, IPv4."""
    vis = server.show(result)
    window = vis.window
    try:
        url = vis.url()
        sockets = listening_addresses(window.server_proc.pid)
        ports = {int(url.rsplit(":", 1)[1].split("/")[0]), int(window.zmq_url.rsplit(":")[-1])}
        assert {p for _, _, p in sockets} == ports
        assert all(f == "tcp" and a == "0100007F" for f, a, _ in sockets), sockets
    finally:
        vis.close()
    assert window.closed
    assert window.server_proc.poll() is not None
    vis.close()  # idempotent
