"""The playback of a whole cycle: every move's best trade-off, one after the other.

:func:`cycle_playback` builds each move's :class:`~adept_traj.viz.playback.Playback`
(:func:`~adept_traj.viz.playback.build_animation`) and joins them: the robot and the moving
obstacles are animated through all moves in sequence (one frame of rest between two
moves), each move keeps its own tool path (``tool_path/NN-NAME/…``), and the floor and
the camera frame the whole cycle. Moving obstacles are shown as each move was planned:
from the scene's time 0 at the start of every move (a fixed-obstacle cycle, where nothing
moves). :func:`clock_playback` plays a cycle planned on the scene clock
(:mod:`adept_traj.cycle.clock`) on one continuous clock: every frame at its scene time,
the dwells included (the robot at rest, the obstacles moving on), so the obstacles never
jump; a periodic cycle plays its one pass and the final dwell, so that the page's loop is
continuous too; every pass back to back plays the first :data:`PLAYBACK_PASSES` passes.
:func:`cycle_html` writes either as a self-contained page (``playback.html``). meshcat is
imported only when they are called.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.cycle.clock import CycleClock
from adept_traj.files import write_text_atomic
from adept_traj.results import PlanningResult, Replay
from adept_traj.robot import Robot
from adept_traj.scene import Scene

__all__ = ["PLAYBACK_FILE", "PLAYBACK_PASSES", "clock_playback", "cycle_html", "cycle_playback"]

PLAYBACK_FILE = "playback.html"
#: Passes a clock's playback plays at most (the first ones; the page's size grows with
#: every move).
PLAYBACK_PASSES = 10


def cycle_playback(
    results: Sequence[PlanningResult],
    names: Sequence[str],
    *,
    robot: Robot | None = None,
    scene: Scene | None = None,
    fps: float = 30.0,
    members: Sequence[int] | None = None,
) -> Any:
    """The :class:`~adept_traj.viz.playback.Playback` of the moves ``results`` (in order,
    named ``names``) played one after the other at real time and ``fps`` [1/s]; ``robot``
    and ``scene``: those of the runs (default: loaded from each result); ``members``: the
    row of each front to play (default: the best trade-offs)."""
    from adept_traj.viz.playback import SceneObject, build_animation

    rows = [r.best.index for r in results] if members is None else list(members)
    parts = [
        build_animation(
            r, fps=fps, replay=Replay.of(r, r.front.x[k], robot=robot, scene=scene), member=k
        )
        for r, k in zip(results, rows, strict=True)
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
    return _framed(
        objects,
        tools,
        times=np.concatenate(times),
        frame_numbers=np.concatenate(frames),
        q=np.concatenate(q),
        fps=parts[0].fps,
        speed=parts[0].speed,
        certified=all(p.certified for p in parts),
    )


def _framed(objects: list[Any], tools: list[np.ndarray], **fields: Any) -> Any:
    """The cycle's :class:`~adept_traj.viz.playback.Playback`
    (:func:`~adept_traj.viz.playback.framed_playback`): the floor and camera frame every
    tool path and every drawn node's positions."""
    from adept_traj.viz.playback import framed_playback

    seen = np.vstack([*tools, *(o.poses[..., :3, 3].reshape(-1, 3) for o in objects)])
    return framed_playback(
        objects,
        seen,
        tool_path=np.vstack(tools),
        closest_points=None,
        closest_distance=None,
        member=0,
        **fields,
    )


def clock_playback(
    clock: CycleClock,
    results: Sequence[Sequence[PlanningResult]],
    *,
    robot: Robot,
    scene: Scene,
    fps: float = 30.0,
) -> Any:
    """The :class:`~adept_traj.viz.playback.Playback` of a cycle planned on the scene
    clock: its planned passes (``results``: per pass the chosen results, in order) with
    every frame at its scene time [s] (keyframe = scene time × ``fps``), the dwells as
    frames of the robot at rest while the obstacles move; at most the first
    :data:`PLAYBACK_PASSES` passes."""
    from adept_traj.viz.playback import SceneObject, build_animation

    segments: list[tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]] = []
    fixed: dict[str, Any] = {}
    tools = []
    certified = clock.certified
    shown = zip(clock.passes[:PLAYBACK_PASSES], results[:PLAYBACK_PASSES])
    entries = [(m, r) for moves, rs in shown for m, r in zip(moves, rs)]
    for n, (m, r) in enumerate(entries):
        if r.problem_settings.start_time != m.start_time:  # run at another time than planned
            r = replace(r, problem_settings=replace(r.problem_settings, start_time=m.start_time))
        replay = Replay.of(r, r.front.x[m.member], robot=robot, scene=scene)
        part = build_animation(r, fps=fps, replay=replay, member=m.member)
        animated = {o.path: o.poses for o in part.objects if o.animated}
        if m.dwell > 0:
            segments.append(_rest(scene, m.start_time - m.dwell, m.dwell, part, 0, fps))
        segments.append((part.times + m.start_time, part.q, animated))
        tools.append(part.tool_path)
        for obj in part.objects:
            if obj.path.startswith("tool_path/"):
                path = f"tool_path/{n:02d}-p{m.pass_index}-{m.name}/"
                path += obj.path.removeprefix("tool_path/")
                fixed[path] = SceneObject(path, obj.parts, obj.poses)
            elif not obj.path.startswith(("floor", "axes")):
                fixed.setdefault(obj.path, obj)
        if n == len(entries) - 1 and clock.final_dwell > 0:
            segments.append(_rest(scene, m.end_time, clock.final_dwell, part, -1, fps))
    times, q, poses = _join(segments)
    objects = [
        SceneObject(path, obj.parts, poses.get(path, obj.poses)) for path, obj in fixed.items()
    ]
    return _framed(
        objects,
        tools,
        times=times,
        frame_numbers=times * fps,
        q=q,
        fps=fps,
        speed=1.0,
        certified=certified,
    )


def _rest(
    scene: Scene, start: float, duration: float, part: Any, frame: int, fps: float
) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """A dwell: frames 1 / ``fps`` apart over the scene times ``[start, start +
    duration]`` [s], the robot at rest in frame ``frame`` of the move ``part`` (0: the next
    move's first, −1: the last move's last), the moving obstacles at each scene time."""
    times = np.append(np.arange(start, start + duration, 1.0 / fps), start + duration)
    n = len(times)
    world = scene.obstacle_poses(times)  # (n_obs, n, 4, 4)
    moving = {f"obstacles/{ob.name}": world[i] for i, ob in enumerate(scene.obstacles)}
    poses = {}
    for obj in part.objects:
        if not obj.animated:
            continue
        if obj.path in moving:
            poses[obj.path] = moving[obj.path]
        else:  # the robot at rest
            poses[obj.path] = np.repeat(obj.poses[frame][None], n, axis=0)
    return times, np.repeat(part.q[frame][None], n, axis=0), poses


def _join(
    segments: list[tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]],
) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """The segments' frames in time order, each scene time once (a segment's frames at or
    before the previous segment's last time left out)."""
    times, q, poses = [], [], {}
    last = -np.inf
    for t, qs, animated in segments:
        keep = t > last + 1e-12
        times.append(t[keep])
        q.append(qs[keep])
        for path, p in animated.items():
            poses.setdefault(path, []).append(p[keep])
        last = float(t[keep][-1]) if keep.any() else last
    return (
        np.concatenate(times),
        np.concatenate(q),
        {k: np.concatenate(v) for k, v in poses.items()},
    )


def cycle_html(
    results: Sequence[PlanningResult],
    names: Sequence[str],
    path: str | os.PathLike[str],
    *,
    robot: Robot | None = None,
    scene: Scene | None = None,
    title: str = "adept_traj cycle",
    clock: CycleClock | None = None,
    passes: Sequence[Sequence[PlanningResult]] | None = None,
    members: Sequence[int] | None = None,
) -> Path:
    """Write the self-contained page (no server, no network) playing
    :func:`cycle_playback` in a loop (with ``clock`` and the chosen results of its
    ``passes``: :func:`clock_playback`, ``robot`` and ``scene`` required); return its
    path."""
    from adept_traj.viz.meshcat_scene import render_html

    if clock is not None and robot is not None and scene is not None and passes is not None:
        playback = clock_playback(clock, passes, robot=robot, scene=scene)
    else:
        playback = cycle_playback(results, names, robot=robot, scene=scene, members=members)
    status = "all certified" if playback.certified else "NOT ALL CERTIFIED"
    label = (
        f"cycle of {len(results)} moves, each its chosen member · "
        f"T = {playback.duration:.3f} s in all · {status}"
    )
    text = render_html(playback, title=f"{title}, {playback.duration:.3f} s", label=label)
    return write_text_atomic(Path(path), text)
