"""The meshcat playback under its former module name, kept for existing callers (the CLI):
every name is re-exported from :mod:`~adept_traj.viz.playback`,
:mod:`~adept_traj.viz.meshcat_scene` and :mod:`~adept_traj.viz.server`, where new code
should import it from.
"""

from __future__ import annotations

from adept_traj.viz.meshcat_scene import BACKGROUND_RGB, draw, render_html, static_html
from adept_traj.viz.playback import (
    MAX_FRAMES,
    Part,
    Playback,
    SceneObject,
    build_animation,
)
from adept_traj.viz.server import MeshcatServerError, show

__all__ = [
    "BACKGROUND_RGB",
    "MAX_FRAMES",
    "MeshcatServerError",
    "Part",
    "Playback",
    "SceneObject",
    "build_animation",
    "draw",
    "render_html",
    "show",
    "static_html",
]
