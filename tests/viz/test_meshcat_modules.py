"""meshcat's parts without its viewer (:mod:`adept_traj.viz.meshcat_modules`): a page is
written without importing IPython, pyzmq or Pillow; meshcat stays whole for the caller's
code (``import meshcat``, ``from meshcat import Visualizer``) afterwards; and the
:class:`Recorder` draws the commands meshcat's own ``Visualizer`` sends, byte for byte."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from adept_traj.problem import TrajectoryProblem
from adept_traj.testing.paper_moves import lift_then_lower, single_result

_VIEWER_MODULES = ("IPython", "zmq", "PIL")


def _run(code: str) -> str:
    done = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_a_page_is_written_without_meshcat_s_viewer_and_meshcat_stays_whole(tmp_path) -> None:
    out = _run(
        f"""
        import sys
        import adept_traj as at
        from adept_traj.testing.paper_moves import lift_then_lower, single_result
        from adept_traj.viz import meshcat_scene

        scene = at.Scene.paper()
        problem = at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal)
        result = single_result(problem, lift_then_lower(problem))
        meshcat_scene.static_html(result, {str(tmp_path / "page.html")!r})
        tops = {{m.split(".")[0] for m in sys.modules}}
        print(sorted(tops & {set(_VIEWER_MODULES)!r}))
        import meshcat
        from meshcat import Visualizer
        import meshcat.servers.zmqserver
        assets = meshcat.viewer_assets_path
        print(meshcat.Visualizer is Visualizer, Visualizer.__module__, callable(assets))
        print("IPython" in sys.modules)
        """
    )
    before, whole, viewer = out.splitlines()
    assert before == "[]"
    assert whole == "True meshcat.visualizer True"
    assert viewer == "True"
    assert (tmp_path / "page.html").stat().st_size > 100_000


def test_meshcat_imported_first_is_used_as_it_is() -> None:
    out = _run(
        """
        import meshcat
        from adept_traj.viz import meshcat_modules
        print(meshcat_modules.meshcat is meshcat, meshcat_modules.mg is meshcat.geometry)
        """
    )
    assert out.split() == ["True", "True"]


@pytest.fixture(scope="module")
def playback(problem: TrajectoryProblem):
    from adept_traj.viz.playback import build_animation

    return build_animation(single_result(problem, lift_then_lower(problem)), fps=10)


class _Window:
    def __init__(self) -> None:
        self.sent: list[dict] = []

    def send(self, command) -> None:
        self.sent.append(command.lower())


def test_the_recorder_sends_what_meshcat_s_visualizer_sends(playback) -> None:
    import umsgpack

    from adept_traj.viz.meshcat_modules import Recorder, viewer_modules
    from adept_traj.viz.meshcat_scene import draw

    Visualizer = viewer_modules()[0].Visualizer  # meshcat's own, the reference

    ours, theirs = _Window(), _Window()
    draw(Recorder(ours), playback, loop=False)
    draw(Visualizer(window=theirs), playback, loop=False)
    assert len(ours.sent) == len(theirs.sent) > 10

    def without_ids(value):  # meshcat draws fresh uuid1 ids on every object
        if isinstance(value, dict):
            return {k: without_ids(v) for k, v in value.items() if k != "uuid"}
        if isinstance(value, list):
            return [without_ids(v) for v in value]
        return value

    for a, b in zip(ours.sent, theirs.sent, strict=True):
        assert umsgpack.packb(without_ids(a)) == umsgpack.packb(without_ids(b))


def test_a_recorder_needs_a_window_that_sends() -> None:
    from adept_traj.errors import MeshcatServerError
    from adept_traj.viz.meshcat_modules import Recorder

    with pytest.raises(MeshcatServerError, match="send"):
        Recorder(object())
