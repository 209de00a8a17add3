"""Drawing a :class:`~adept_traj.viz.playback.Playback` into meshcat: into any
visualizer (:func:`draw`), or into one self-contained HTML page that plays it
(:func:`render_html`, :func:`static_html`: meshcat's viewer inlined, no server, no network
access; the animation plays on opening and loops).

The page adds to meshcat's viewer (its own menu of animation controls stays): a label
naming what is shown (``#member-label``: the front member, its travel time T and whether
it is certified), a legend of the colours (``#legend``, :func:`legend`), and a bar with a
play/pause button (``#play-pause``), a scrubber (``#scrub``, physical time [s]) and a time
read-out (``#time-readout``: the physical time t of the frame shown and T [s]; its
``data-time`` attribute holds t). These drive meshcat's own ``viewer.animator``
(``play``, ``pause``, ``seek``); the page sets ``window.playbackReady`` once drawn.
"""

from __future__ import annotations

import base64
import html
import json
import math
import uuid
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.errors import MeshcatServerError
from adept_traj.files import write_text_atomic
from adept_traj.results import PlanningResult, Replay
from adept_traj.viz.meshcat_geometry import translation
from adept_traj.viz.meshcat_modules import Recorder, meshcat, umsgpack
from adept_traj.viz.playback import (
    CLOSEST_COLOR,
    FIXED_OBSTACLE_COLOR,
    GOAL_COLOR,
    MOVING_OBSTACLE_COLOR,
    PIVOT_COLOR,
    START_COLOR,
    TOOL_PATH_COLOR,
    Playback,
    build_animation,
)

__all__ = [
    "BACKGROUND_RGB",
    "draw",
    "legend",
    "live_html",
    "member_label",
    "member_page",
    "render_html",
    "result_page",
    "static_html",
]

#: Flat background colour of the viewer (r, g, b in [0, 1]).
BACKGROUND_RGB = (0.96, 0.96, 0.97)


def draw(vis: meshcat.Visualizer | Recorder, playback: Playback, *, loop: bool = True) -> None:
    """Send ``playback`` to ``vis`` (a top-level ``meshcat.Visualizer``, or a
    :class:`~adept_traj.viz.meshcat_modules.Recorder` for a page): background, camera, every node,
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


def legend(playback: Playback) -> tuple[tuple[str, str], ...]:
    """The page's legend: ``(CSS colour, text)`` for each kind of node ``playback`` draws,
    in drawing order (robot, fixed and moving obstacles, pivots, tool path, start, goal,
    closest-point segment, floor grid, world axes)."""
    paths = [obj.path for obj in playback.objects]
    moving = {o.path for o in playback.objects if o.animated}

    def has(prefix: str) -> bool:
        return any(p.startswith(prefix) for p in paths)

    obstacles = [p for p in paths if p.startswith("obstacles/")]
    entries = [
        (has("robot/"), "#7f8c8d", "robot (its links in their own colours)"),
        (any(p not in moving for p in obstacles), FIXED_OBSTACLE_COLOR, "fixed obstacle"),
        (any(p in moving for p in obstacles), MOVING_OBSTACLE_COLOR, "moving obstacle (pendulum)"),
        (has("pivots/"), PIVOT_COLOR, "pendulum pivot and axle"),
        (has("tool_path/"), TOOL_PATH_COLOR, "tool path"),
        (has("tool_path/"), START_COLOR, "start (ball)"),
        (has("tool_path/"), GOAL_COLOR, "goal (ball)"),
        (has("closest/"), CLOSEST_COLOR, "closest points, robot to nearest obstacle"),
        (has("floor/grid"), "#b3b6b7", "floor z = 0, grid 0.1 m"),
        (has("floor/axes"), "linear-gradient(90deg, #e00 33%, #0c0 33% 66%, #00f 66%)",
         "world axes x, y, z (0.2 m)"),
    ]  # fmt: skip
    return tuple(
        (f"#{c:06x}" if isinstance(c, int) else c, text) for shown, c, text in entries if shown
    )


def member_label(playback: Playback, *, best: bool | None = None, of: int | None = None) -> str:
    """What the page shows, e.g. ``"member 3 of 40 (the best trade-off) · T = 2.100 s ·
    certified"``; ``best``: whether it is the best trade-off (``None``: not said), ``of``:
    the number of front members (``None``: not said)."""
    which = f"member {playback.member}" + ("" if of is None else f" of {of}")
    if best:
        which += " (the best trade-off)"
    status = "certified" if playback.certified else "NOT CERTIFIED"
    return f"{which} · T = {playback.duration:.3f} s · {status}"


_PAGE_STYLE = """body { margin: 0; font: 13px/1.35 system-ui, sans-serif; color: #1c2833; }
#meshcat-pane { width: 100vw; height: 100vh; overflow: hidden; }
#adept-info { position: absolute; top: 8px; left: 8px; max-width: 330px; padding: 6px 9px;
  background: rgba(255, 255, 255, 0.86); border-radius: 4px; }
#member-label { font-weight: 600; margin-bottom: 4px; }
#member-label.uncertified { color: #b03a2e; }
#legend { list-style: none; margin: 0; padding: 0; }
#legend li { display: flex; align-items: center; gap: 6px; }
#legend .swatch { width: 14px; height: 9px; border-radius: 2px; flex: none; }
#adept-controls { position: absolute; left: 8px; right: 8px; bottom: 8px; display: flex;
  align-items: center; gap: 10px; padding: 5px 9px; background: rgba(255, 255, 255, 0.86);
  border-radius: 4px; }
#play-pause { width: 64px; }
#scrub { flex: 1; }
#time-readout { font-variant-numeric: tabular-nums; white-space: nowrap; }"""

# Drives meshcat's viewer.animator (play, pause, seek; actions' times are playback times
# [s]); physical time = playback time · speed, at most T.
_PAGE_SCRIPT = """(function () {
  var A = viewer.animator, P = adeptTrajPlayback;
  var button = document.getElementById("play-pause"), scrub = document.getElementById("scrub");
  var readout = document.getElementById("time-readout"), dragging = false;
  function playbackTime() {
    return A.actions.reduce(function (m, a) { return Math.max(m, a.time); }, 0);
  }
  function physical() { return Math.min(playbackTime() * P.speed, P.duration); }
  function show() {
    var t = physical();
    readout.textContent = "t = " + t.toFixed(3) + " s / T = " + P.duration.toFixed(3) + " s";
    readout.setAttribute("data-time", String(t));
    button.textContent = A.playing ? "Pause" : "Play";
    if (!dragging) { scrub.value = String(t); }
  }
  button.addEventListener("click", function () {
    if (A.playing) { A.pause(); } else { A.play(); }
    show();
  });
  scrub.addEventListener("input", function () {
    dragging = true;
    if (A.playing) { A.pause(); }
    var t = Number(scrub.value) / P.speed;
    A.seek(t);
    A.display_progress(t);
    show();
  });
  scrub.addEventListener("change", function () { dragging = false; show(); });
  (function tick() { show(); requestAnimationFrame(tick); })();
  window.playbackReady = true;
})();"""


def render_html(
    playback: Playback,
    *,
    loop: bool = True,
    title: str = "adept_traj",
    label: str | None = None,
) -> str:
    """A self-contained HTML page (meshcat's viewer inlined, no network) playing
    ``playback`` on opening: every drawing command of :func:`draw`, as base64 MessagePack,
    replayed in order (the animation last), with the page's label (``label``; default
    :func:`member_label`), legend (:func:`legend`) and play/pause, scrubber and time
    read-out (see the module's description)."""
    window = _RecordingWindow()
    draw(Recorder(window), playback, loop=loop)
    commands = ",\n".join(f'"{base64.b64encode(c).decode("ascii")}"' for c in window.commands)
    viewer = (
        f"<script>\n{_viewer_js()}\n</script>\n"
        "<script>\n"
        'var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));\n'
        f"var adeptTrajCommands = [\n{commands}\n];\n"
        "adeptTrajCommands.forEach(function (b64) {\n"
        "  var s = atob(b64), bytes = new Uint8Array(s.length);\n"
        "  for (var i = 0; i < s.length; i++) { bytes[i] = s.charCodeAt(i); }\n"
        "  viewer.handle_command_bytearray(bytes);\n"
        "});\n"
    )
    return _page(playback, title=title, label=label, viewer=viewer)


def live_html(playback: Playback, *, title: str = "adept_traj", label: str | None = None) -> str:
    """The page of the live viewer (:func:`~adept_traj.viz.server.show`): the label, legend
    and controls of :func:`render_html` around meshcat's viewer, which loads its script
    (``main.min.js``) from the meshcat server serving the page and receives the scene and
    the animation over that server's WebSocket (``viewer.connect()``), as meshcat's own
    page does."""
    viewer = (
        '<script src="main.min.js"></script>\n'
        "<script>\n"
        'var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));\n'
        "viewer.connect();\n"
    )
    return _page(playback, title=title, label=label, viewer=viewer)


def _page(playback: Playback, *, title: str, label: str | None, viewer: str) -> str:
    """The page around a meshcat viewer: ``viewer`` is the HTML that makes ``viewer`` and
    fills it, ending inside an open ``<script>`` element that the page's controls close."""
    label = member_label(playback) if label is None else label
    items = "\n".join(
        f'<li><span class="swatch" style="background: {colour}"></span>{html.escape(text)}</li>'
        for colour, text in legend(playback)
    )
    info = json.dumps({"duration": playback.duration, "speed": playback.speed})
    status = "" if playback.certified else ' class="uncertified"'
    return (
        '<!DOCTYPE html>\n<html>\n<head>\n<meta charset="utf-8">\n'
        f"<title>{html.escape(title)}</title>\n"
        f"<style>\n{_PAGE_STYLE}\n</style>\n</head>\n<body>\n"
        '<div id="meshcat-pane"></div>\n'
        f'<div id="adept-info">\n<div id="member-label"{status}>{html.escape(label)}</div>\n'
        f'<ul id="legend">\n{items}\n</ul>\n</div>\n'
        '<div id="adept-controls">\n<button id="play-pause" type="button">Pause</button>\n'
        f'<input id="scrub" type="range" min="0" max="{playback.duration!r}" step="0.001" '
        'value="0" aria-label="time [s]">\n<span id="time-readout" data-time="0">'
        f"t = 0.000 s / T = {playback.duration:.3f} s</span>\n</div>\n"
        f"{viewer}"
        f"var adeptTrajPlayback = {info};\n"
        f"{_PAGE_SCRIPT}\n"
        "</script>\n</body>\n</html>\n"
    )


def static_html(result: PlanningResult, path: str | Path, **options: Any) -> Path:
    """Write :func:`result_page`'s page of ``result`` to ``path`` (its folder created if
    needed), atomically (a temporary file renamed); ``options`` are
    :func:`result_page`'s keywords. Returns ``path`` as a :class:`pathlib.Path`."""
    return write_text_atomic(Path(path), result_page(result, **options))


def result_page(
    result: PlanningResult,
    *,
    speed: float = 1.0,
    fps: float = 30.0,
    loop: bool = True,
    show_closest: bool = False,
    replay: Replay | None = None,
    member: int | None = None,
) -> str:
    """A self-contained HTML page playing a member of ``result``'s front (default: the best
    trade-off), labelled with the member, its T and whether it is certified.

    The page inlines meshcat's viewer and the scene (no server, no network access); the
    animation starts on opening and loops (``loop=False``: plays once). About 0.9 MB.

    Parameters
    ----------
    result: the planning result.
    speed, fps, show_closest, replay, member: see
        :func:`~adept_traj.viz.playback.build_animation`.
    loop: loop the animation forever.

    Returns
    -------
    str
        The page (``playback.html``, written by :func:`static_html`).
    """
    playback = build_animation(
        result, speed=speed, fps=fps, show_closest=show_closest, replay=replay, member=member
    )
    return member_page(result, playback, loop=loop)


def member_page(
    result: PlanningResult, playback: Playback, *, loop: bool = True, live: bool = False
) -> str:
    """The page of a member of ``result`` drawn by ``playback``: :func:`render_html`
    (``playback.html``) or, ``live``, :func:`live_html` (the live viewer's), both titled
    and labelled alike, e.g. ``"nsga2 · member 3 of 40 (the best trade-off) · T = 2.100 s ·
    certified"``."""
    best = playback.member == result.best.index
    label = f"{result.algorithm} · " + member_label(playback, best=best, of=len(result.front))
    title = f"adept_traj — {result.algorithm}, member {playback.member}, "
    title += f"T = {playback.duration:.3f} s"
    if live:
        return live_html(playback, title=title, label=label)
    return render_html(playback, loop=loop, title=title, label=label)
