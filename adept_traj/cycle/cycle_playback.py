"""The playback of a whole cycle: every move's best trade-off, one after the other.

:func:`cycle_playback` builds each move's :class:`~adept_traj.viz.playback.Playback`
(:func:`~adept_traj.viz.playback.build_animation`) and joins them: the robot and the moving
obstacles are animated through all moves in sequence (one frame of rest between two
moves), each move keeps its own tool path (``tool_path/NN-NAME/…``), and the floor and
the camera frame the whole cycle. Moving obstacles are shown as each move was planned:
from the scene's time 0 at the start of every move. :func:`cycle_html` writes it as a
self-contained page (``playback.html``). meshcat is imported only when they are called.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.files import write_text_atomic
from adept_traj.results import PlanningResult, Replay
from adept_traj.robot import Robot
from adept_traj.scene import Scene

__all__ = ["PLAYBACK_FILE", "cycle_html", "cycle_playback"]

PLAYBACK_FILE = "playback.html"


def cycle_playback(
    results: Sequence[PlanningResult],
    names: Sequence[str],
    *,
    robot: Robot | None = None,
    scene: Scene | None = None,
    fps: float = 30.0,
) -> Any:
    """The :class:`~adept_traj.viz.playback.Playback` of the moves ``results`` (in order,
    named ``names``) played one after the other at real time and ``fps`` [1/s]; ``robot``
    and ``scene``: those of the runs (default: loaded from each result)."""
    from adept_traj.viz.framing import camera, floor
    from adept_traj.viz.playback import Playback, SceneObject, build_animation

    parts = [
        build_animation(r, fps=fps, replay=Replay.of(r, robot=robot, scene=scene)) for r in results
    ]
    animated: dict[str, list[np.ndarray]] = {}
    fixed: dict[str, Any] = {}
    frames, times, q, tools = [], [], [], []
    frame0 = time0 = 0.0
    for k, (p, name) in enumerate(zip(parts, names, strict=True)):
        frames.append(p.frame_numbers + frame0)
        times.append(p.times + time0)
        q.append(p.q)
        tools.append(p.tool_path)
        for obj in p.objects:
            if obj.path.startswith("tool_path/"):
                path = f"tool_path/{k:02d}-{name}/{obj.path.removeprefix('tool_path/')}"
                fixed[path] = SceneObject(path, obj.parts, obj.poses)
            elif obj.animated:
                animated.setdefault(obj.path, []).append(obj.poses)
                fixed.setdefault(obj.path, obj)  # parts of the first move
            elif not obj.path.startswith(("floor", "axes")):
                fixed.setdefault(obj.path, obj)
        frame0 = float(frames[-1][-1]) + 1.0
        time0 = float(times[-1][-1]) + p.speed / p.fps
    objects = []
    for path, obj in fixed.items():
        poses = np.concatenate(animated[path]) if path in animated else obj.poses
        objects.append(SceneObject(path, obj.parts, poses))
    seen = np.vstack([*tools, *(o.poses[..., :3, 3].reshape(-1, 3) for o in objects)])
    objects.extend(SceneObject(path, obj_parts, pose) for path, obj_parts, pose in floor(seen))
    target, position = camera(seen)
    return Playback(
        objects=tuple(objects),
        times=np.concatenate(times),
        frame_numbers=np.concatenate(frames),
        q=np.concatenate(q),
        fps=parts[0].fps,
        speed=parts[0].speed,
        duration=float(times[-1][-1]),
        tool_path=np.vstack(tools),
        closest_points=None,
        closest_distance=None,
        camera_target=target,
        camera_position=position,
        member=0,
        certified=all(p.certified for p in parts),
    )


def cycle_html(
    results: Sequence[PlanningResult],
    names: Sequence[str],
    path: str | os.PathLike[str],
    *,
    robot: Robot | None = None,
    scene: Scene | None = None,
    title: str = "adept_traj cycle",
) -> Path:
    """Write the self-contained page (no server, no network) playing
    :func:`cycle_playback` in a loop; return its path."""
    from adept_traj.viz.meshcat_scene import render_html

    playback = cycle_playback(results, names, robot=robot, scene=scene)
    status = "all certified" if playback.certified else "NOT ALL CERTIFIED"
    label = (
        f"cycle of {len(results)} moves, each its best trade-off · "
        f"T = {playback.duration:.3f} s in all · {status}"
    )
    text = render_html(playback, title=f"{title}, {playback.duration:.3f} s", label=label)
    return write_text_atomic(Path(path), text)
