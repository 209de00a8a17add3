"""The playback page (``playback.html``): the pendulum's pivot, the label naming the member
shown (its T, certified or not), the legend, ``adept-traj show`` serving it and the
explorer on 127.0.0.1 (fetched from the printed addresses), and — in a real browser
(headless Chromium + Selenium, slow tier) — the play/pause button, the scrubber and the
time read-out, checked against the drawn robot's pose at the read-out's time computed from
the replay."""

from __future__ import annotations

import html
import io
import re
import time
import urllib.request
from pathlib import Path

import numpy as np
import pytest

from adept_traj.cli import main
from adept_traj.cli import show as show_command
from adept_traj.problem import TrajectoryProblem
from adept_traj.results import PlanningResult, Replay, certified_members
from adept_traj.testing.paper_moves import lift_then_lower, single_result
from adept_traj.viz import meshcat_scene, playback
from tests.conftest import chromium_driver, fetch, refused, wait_for

_TINY = ["plan", "--pop", "8", "--gens", "2", "--no-html", "--no-plots", "--quiet", "--no-polish"]


@pytest.fixture(scope="module")
def result(problem: TrajectoryProblem) -> PlanningResult:
    return single_result(problem, lift_then_lower(problem))


def label_and_legend(text: str) -> tuple[str, list[str]]:
    label = re.search(r'<div id="member-label"[^>]*>(.*?)</div>', text, re.S)
    items = re.findall(r"<li><span[^>]*></span>(.*?)</li>", text)
    assert label is not None
    return html.unescape(label[1]), [html.unescape(i) for i in items]


# ============================================================================ no browser
def test_the_pendulum_is_drawn_with_its_pivot(
    result: PlanningResult, problem: TrajectoryProblem
) -> None:
    pb = playback.build_animation(result, fps=10)
    objects = {o.path: o for o in pb.objects}
    pivot = objects["pivots/pendulum"]
    assert not pivot.animated
    _ball, axle = pivot.parts
    centre = pivot.poses[:3, 3]
    # the pivot is the point the bob's centre keeps at the rod's length, and the axle is
    # normal to the plane the bob swings in (from the bob's drawn poses only)
    bob = objects["obstacles/pendulum.bob"].poses[:, :3, 3]
    rod = problem.scene.obstacle("pendulum.rod").shape
    np.testing.assert_allclose(np.linalg.norm(bob - centre, axis=-1), rod.length, atol=1e-12)
    direction = (pivot.poses[:3, :3] @ axle.local[:3, :3])[:, 1]  # meshcat cylinder: y
    assert abs(np.linalg.norm(direction) - 1.0) < 1e-12
    np.testing.assert_allclose((bob - centre) @ direction, 0.0, atol=1e-12)
    assert np.ptp(bob, axis=0).max() > 0.1  # it swings
    assert (bob[:, 2] < centre[2]).all()  # hanging below its pivot
    # the pivot is drawn in the page (ball and axle)
    drawn = {
        c["path"]
        for c in playback_commands(meshcat_scene.render_html(pb))
        if c["type"] == "set_object"
    }
    assert {"/meshcat/pivots/pendulum/part0", "/meshcat/pivots/pendulum/part1"} <= drawn


def test_the_explorer_marks_the_pendulum_s_pivot(
    result: PlanningResult, problem: TrajectoryProblem
) -> None:
    import base64

    from adept_traj.viz.explorer import explorer_data

    data = explorer_data(result, robot=problem.robot, scene=problem.scene)
    ((pivot,),) = [[p for p in data["pivots"] if p["name"] == "pendulum"]]
    (bob,) = [ob for ob in data["obstacles"] if ob["name"] == "pendulum.bob"]
    poses = np.frombuffer(base64.b64decode(bob["poses"]), "<f4").reshape(bob["n_poses"], 3, 4)
    length = problem.scene.obstacle("pendulum.rod").shape.length
    gap = np.linalg.norm(poses[:, :, 3] - np.array(pivot["point"]), axis=-1)
    np.testing.assert_allclose(gap, length, atol=1e-5)  # float32 poses
    assert len(data["pivots"]) == 1


def playback_commands(text: str) -> list[dict]:
    import base64

    import umsgpack

    block = re.search(r"var adeptTrajCommands = \[(.*?)\];", text, re.S)
    assert block is not None
    return [umsgpack.unpackb(base64.b64decode(s)) for s in re.findall(r'"([^"]+)"', block[1])]


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> PlanningResult:
    """A tiny paper run (seed 1): a front of two members."""
    out = tmp_path_factory.mktemp("page") / "run"
    assert main([*_TINY, "--out", str(out)]) == 0
    r = PlanningResult.load(out)
    assert len(r.front) == 2
    return r


def test_the_page_names_the_member_and_has_a_legend(run: PlanningResult, tmp_path: Path) -> None:
    certified = certified_members(run)
    for member in range(2):
        page = meshcat_scene.static_html(run, tmp_path / f"m{member}.html", fps=5, member=member)
        label, items = label_and_legend(page.read_text(encoding="utf-8"))
        T = float(run.front.x[member, 0])
        best = " (the best trade-off)" if member == run.best.index else ""
        status = "certified" if certified[member] else "NOT CERTIFIED"
        assert label == f"{run.algorithm} · member {member} of 2{best} · T = {T:.3f} s · {status}"
        assert items == [
            "robot (its links in their own colours)",
            "fixed obstacle",
            "moving obstacle (pendulum)",
            "pendulum pivot and axle",
            "tool path",
            "start (ball)",
            "goal (ball)",
            "floor z = 0, grid 0.1 m",
            "world axes x, y, z (0.2 m)",
        ]
    # the default page is the best trade-off's; the closest segment adds its entry
    text = meshcat_scene.result_page(run, fps=5, show_closest=True)
    label, items = label_and_legend(text)
    assert f"member {run.best.index} of 2 (the best trade-off)" in label
    assert "closest points, robot to nearest obstacle" in items
    # the scrubber spans the member's travel time
    scrub = re.search(r'<input id="scrub"[^>]*max="([^"]+)"', text)
    assert scrub is not None
    assert float(scrub[1]) == float(run.best_x[0])


class _FakeViewer:
    """Stands in for the live meshcat viewer (tested in test_viz_meshcat)."""

    closed = False

    def url(self) -> str:
        return "http://127.0.0.1:7000/static/"

    def close(self) -> None:
        self.closed = True


def test_show_serves_the_explorer_and_the_member_s_page(
    result: PlanningResult,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    from adept_traj.viz import server

    out = result.save(tmp_path / "run")
    assert not (out / "explorer.html").exists()  # show writes it
    result = PlanningResult.load(out)
    member = result.best.index
    viewer = _FakeViewer()
    monkeypatch.setattr(server, "show", lambda result, **kw: viewer)
    served: dict[str, tuple[int, bytes]] = {}
    urls: list[str] = []

    def fetch_then_stop(_seconds: float) -> None:  # the command's wait loop: fetch, then Ctrl-C
        urls.extend(re.findall(r"http://127\.0\.0\.1:\d+/\S+\.html", capsys.readouterr().out))
        for url in urls:
            served[url.rsplit("/", 1)[1]] = fetch(url)[:2]
        raise KeyboardInterrupt

    monkeypatch.setattr(show_command.time, "sleep", fetch_then_stop)
    assert main(["show", str(out), "--member", str(member)]) == 0
    assert set(served) == {"explorer.html", "playback.html"}
    assert served["explorer.html"] == (200, (out / "explorer.html").read_bytes())
    status, page = served["playback.html"]
    assert status == 200
    label = re.search(rb'<div id="member-label"[^>]*>(.*?)</div>', page)
    assert label is not None
    T = float(result.front.x[member, 0])
    expected = f"member {member} of 1 (the best trade-off) · T = {T:.3f} s · certified"
    assert label[1].decode("utf-8").endswith(expected)
    assert viewer.closed
    port = int(re.search(r":(\d+)/", next(iter(urls)))[1])
    assert refused(port)  # the page server was closed with the command


# ============================================================================ real browser
#: The page must need no network: every host name resolves to nothing (but the loopback
#: address, where the live viewer is served).
NO_NETWORK = "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1"


@pytest.fixture(scope="module")
def browser(tmp_path_factory: pytest.TempPathFactory):
    profile = tmp_path_factory.mktemp("profile")
    with chromium_driver(profile, "--window-size=1000,700", NO_NETWORK) as driver:
        yield driver


def shot(driver) -> np.ndarray:
    from matplotlib.image import imread

    data = driver.find_element("css selector", "#meshcat-pane canvas").screenshot_as_png
    return imread(io.BytesIO(data), format="png")[..., :3]


#: The drawn pose's translation of the gripper in the frame of the viewer's ``meshcat``
#: node's parent: the world shifted by ``-camera_target`` (added back by the caller).
_GRIPPER = """const root = viewer.scene_tree.find(["meshcat"]).object;
const o = viewer.scene_tree.find(["meshcat", "robot", "link4", "gripper"]).object;
o.updateMatrixWorld(true);
const m = root.parent.matrixWorld.clone().invert().multiply(o.matrixWorld).elements;
return [m[12], m[13], m[14]];"""


@pytest.mark.slow  # a browser and a 2.1 s animation
def test_play_pause_scrub_and_read_out_in_a_real_browser(
    result: PlanningResult, problem: TrajectoryProblem, browser, tmp_path: Path
) -> None:
    page = meshcat_scene.static_html(result, tmp_path / "playback.html")
    browser.get(page.resolve().as_uri())
    check_label_legend_and_controls(browser, result, problem)


@pytest.mark.slow  # a browser, a meshcat server and a 2.1 s animation
def test_the_live_viewer_has_the_label_legend_and_controls_in_a_real_browser(
    result: PlanningResult, problem: TrajectoryProblem, browser
) -> None:
    """``adept-traj show``'s live meshcat page (the scene and the animation sent over the
    meshcat server's WebSocket) has the label, legend and controls of playback.html, and
    they drive the live view; meshcat's own menu and page stay."""
    from adept_traj.viz import server

    vis = server.show(result)
    try:
        browser.get(vis.url())
        check_label_legend_and_controls(browser, result, problem)
        menus = browser.execute_script(
            "return Array.from(document.querySelectorAll('.dg .title')).map(e => e.textContent)"
        )
        assert "Animations" in menus  # meshcat's own animation controls too
        with urllib.request.urlopen(vis.url() + "index.html", timeout=10) as reply:
            assert b"<title>MeshCat</title>" in reply.read()  # meshcat's plain page
    finally:
        vis.close()


def check_label_legend_and_controls(browser, result: PlanningResult, problem) -> None:
    """The page open in ``browser`` shows ``result``'s best trade-off with its label and
    legend, plays on opening, pauses, scrubs to 80 % of T (read out and drawn there: the
    gripper where the replay puts it) and plays on from there."""
    from selenium.webdriver.common.action_chains import ActionChains

    pb = playback.build_animation(result)
    T = pb.duration
    wait_for(lambda: browser.execute_script("return window.playbackReady === true"))
    assert browser.find_element("id", "member-label").text == (
        f"NSGA-II · member 0 of 1 (the best trade-off) · T = {T:.3f} s · certified"
    )
    legend = browser.find_elements("css selector", "#legend li")
    assert len(legend) == 9
    assert legend[3].text == "pendulum pivot and axle"
    readout = browser.find_element("id", "time-readout")
    button = browser.find_element("id", "play-pause")

    def now() -> float:
        return float(readout.get_attribute("data-time"))

    # playing on opening: the read-out runs
    first = now()
    wait_for(lambda: now() != first, 10.0)
    assert button.text == "Pause"
    # paused: the read-out and the view stand still
    button.click()
    assert button.text == "Play"
    stopped = now()
    before = shot(browser)
    time.sleep(0.5)
    assert now() == stopped
    # scrub: a click at 80 % of the bar shows t ≈ 0.8 T, read out and drawn there
    scrub = browser.find_element("id", "scrub")
    width = scrub.size["width"]
    ActionChains(browser).move_to_element_with_offset(scrub, int(0.3 * width), 0).click().perform()
    wait_for(lambda: abs(now() - stopped) > 1e-6, 30.0)  # a loaded machine: 10 s too short
    t = now()
    assert abs(t - 0.8 * T) < 0.05 * T, (t, T)
    assert readout.text == f"t = {t:.3f} s / T = {T:.3f} s"
    assert button.text == "Play"  # scrubbing leaves it paused
    time.sleep(0.5)
    after = shot(browser)
    assert before.shape == after.shape
    assert (np.abs(before - after).max(axis=-1) > 0.1).mean() > 0.001  # the robot moved
    # the gripper is drawn where the replay puts it at the read-out's time t
    replay = Replay.of(result)
    q = replay.sample(np.array([t]), orders=(0,)).q
    names = [g.name for g in problem.robot.visual_model.geometryObjects]
    k = names.index("link4/gripper")
    world = problem.scene.robot_base @ problem.robot.geometry_poses(q, problem.robot.visual_model)
    drawn = np.array(browser.execute_script(_GRIPPER)) + pb.camera_target
    np.testing.assert_allclose(drawn, world[0, k, :3, 3], atol=5e-3)  # 30 fps keyframes
    # play again: the time runs on from t
    button.click()
    wait_for(lambda: now() != t, 10.0)
    assert button.text == "Pause"
