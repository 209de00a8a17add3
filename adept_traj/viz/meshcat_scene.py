"""Drawing a :class:`~adept_traj.viz.playback.Playback` into meshcat: into any
visualizer (:func:`draw`), or into one self-contained HTML page that plays it
(:func:`render_html`, :func:`static_html`: meshcat's viewer inlined, no server, no network
access; the animation plays on opening and loops).
"""

from __future__ import annotations

import base64
import html
import math
import uuid
import warnings
from pathlib import Path
from typing import Any

import numpy as np

with warnings.catch_warnings():  # meshcat 0.3.2 imports pyzmq's deprecated zmq.eventloop.ioloop
    warnings.filterwarnings("ignore", "zmq.eventloop.ioloop is deprecated", DeprecationWarning)
    import meshcat
    import umsgpack

from adept_traj.errors import MeshcatServerError
from adept_traj.files import write_text_atomic
from adept_traj.results import PlanningResult, Replay
from adept_traj.viz.meshcat_geometry import translation
from adept_traj.viz.playback import Playback, build_animation

__all__ = ["BACKGROUND_RGB", "draw", "render_html", "static_html"]

#: Flat background colour of the viewer (r, g, b in [0, 1]).
BACKGROUND_RGB = (0.96, 0.96, 0.97)


def draw(vis: meshcat.Visualizer, playback: Playback, *, loop: bool = True) -> None:
    """Send ``playback`` to ``vis`` (a top-level visualizer): background, camera, every node,
    then the animation (playing; looping forever when ``loop``, else played once).

    Meshcat's orbit camera always turns about the viewer's origin, so the visualizer's root
    node is shifted by ``-playback.camera_target``: every node below it keeps its world pose.
    Meshcat's own grid and axes (20 m wide, at the viewer's origin) are hidden; the playback
    draws its own floor and world axes.
    """
    vis.set_transform(translation(-playback.camera_target))
    vis["/Grid"].set_property("visible", False)
    vis["/Axes"].set_property("visible", False)
    vis["/Background"].set_property("top_color", list(BACKGROUND_RGB))
    vis["/Background"].set_property("bottom_color", list(BACKGROUND_RGB))
    dx, dy, dz = playback.camera_position - playback.camera_target
    # the camera sits in the y-up frame "rotated": (x, y, z)_world = (x, -z, y)_rotated
    vis["/Cameras/default/rotated/<object>"].set_property(
        "position", [float(dx), float(dz), float(-dy)]
    )
    for obj in playback.objects:
        node = vis[obj.path]
        for i, part in enumerate(obj.parts):
            child = node[f"part{i}"]
            child.set_object(part.obj)
            child.set_transform(np.asarray(part.local, dtype=float))
        node.set_transform(np.asarray(obj.initial_pose, dtype=float))
    vis.set_animation(
        playback.animation(vis.path.entries),
        play=True,
        repetitions=math.inf if loop else 1,
    )


#: Namespace of the ids given to drawn objects in a page (:func:`uuid.uuid5` of their path).
_PAGE_IDS = uuid.UUID("6f0b1c52-3a5e-4c1b-9d8e-2b7f4e1a9c30")


def _stable_ids(data: dict[str, Any]) -> dict[str, Any]:
    """A lowered meshcat command whose ids are derived from its path instead of meshcat's
    time-based ``uuid1`` (a copy; ``data`` is unchanged): the k-th distinct id met in the
    command (every ``"uuid"`` value: object, geometry, material, texture, ...) becomes
    ``uuid5(_PAGE_IDS, f"{path}#{k}")``, and every reference to it follows. The same drawing
    gives the same bytes, and distinct paths keep distinct ids."""
    found: dict[str, str] = {}

    def collect(node: Any) -> None:
        if isinstance(node, dict):
            for key, value in node.items():
                if key == "uuid" and isinstance(value, str) and value not in found:
                    found[value] = str(uuid.uuid5(_PAGE_IDS, f"{data.get('path')}#{len(found)}"))
                collect(value)
        elif isinstance(node, list):
            for item in node:
                collect(item)

    def rename(node: Any) -> Any:
        if isinstance(node, dict):
            return {key: rename(value) for key, value in node.items()}
        if isinstance(node, list):
            return [rename(item) for item in node]
        if isinstance(node, str):
            return found.get(node, node)
        return node

    collect(data)
    return rename(data) if found else data


class _RecordingWindow:
    """Stands in for a meshcat window: keeps every command as the viewer's msgpack bytes,
    with ids derived from the drawn paths (:func:`_stable_ids`), so that the same playback
    always gives the same bytes."""

    def __init__(self) -> None:
        self.commands: list[bytes] = []

    def send(self, command: Any) -> None:
        self.commands.append(umsgpack.packb(_stable_ids(command.lower())))

    def close(self) -> None:
        pass


def _viewer_js() -> str:
    path = Path(meshcat.__file__).resolve().parent / "viewer" / "dist" / "main.min.js"
    if not path.is_file():
        raise MeshcatServerError(f"meshcat's viewer script is missing: {path}")
    return path.read_text(encoding="utf-8")


def render_html(playback: Playback, *, loop: bool = True, title: str = "adept_traj") -> str:
    """A self-contained HTML page (meshcat's viewer inlined, no network) playing
    ``playback`` on opening: every drawing command of :func:`draw`, as base64 MessagePack,
    replayed in order (the animation last)."""
    window = _RecordingWindow()
    draw(meshcat.Visualizer(window=window), playback, loop=loop)
    commands = ",\n".join(f'"{base64.b64encode(c).decode("ascii")}"' for c in window.commands)
    return (
        '<!DOCTYPE html>\n<html>\n<head>\n<meta charset="utf-8">\n'
        f"<title>{html.escape(title)}</title>\n"
        "<style>body { margin: 0; } #meshcat-pane { width: 100vw; height: 100vh; "
        'overflow: hidden; }</style>\n</head>\n<body>\n<div id="meshcat-pane"></div>\n'
        f"<script>\n{_viewer_js()}\n</script>\n"
        "<script>\n"
        'var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));\n'
        f"var adeptTrajCommands = [\n{commands}\n];\n"
        "adeptTrajCommands.forEach(function (b64) {\n"
        "  var s = atob(b64), bytes = new Uint8Array(s.length);\n"
        "  for (var i = 0; i < s.length; i++) { bytes[i] = s.charCodeAt(i); }\n"
        "  viewer.handle_command_bytearray(bytes);\n"
        "});\n"
        "</script>\n</body>\n</html>\n"
    )


def static_html(
    result: PlanningResult,
    path: str | Path,
    *,
    speed: float = 1.0,
    fps: float = 30.0,
    loop: bool = True,
    show_closest: bool = False,
    replay: Replay | None = None,
) -> Path:
    """Write a self-contained HTML page playing ``result``'s best trajectory.

    The page inlines meshcat's viewer and the scene (no server, no network access); the
    animation starts on opening and loops (``loop=False``: plays once). About 0.9 MB,
    written atomically (a temporary file renamed).

    Parameters
    ----------
    result: the planning result.
    path: the file to write (its folder is created if needed).
    speed, fps, show_closest, replay: see
        :func:`~adept_traj.viz.playback.build_animation`.
    loop: loop the animation forever.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    playback = build_animation(
        result, speed=speed, fps=fps, show_closest=show_closest, replay=replay
    )
    title = f"adept_traj — {result.algorithm}, T = {playback.duration:.3f} s"
    return write_text_atomic(Path(path), render_html(playback, loop=loop, title=title))
