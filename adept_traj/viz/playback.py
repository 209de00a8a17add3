"""The playback of a planning result: what is drawn, where, at which frame — independent
of any visualizer.

:func:`build_animation` turns a result's best trajectory, or another member of its front
(``member=N``), (through its
:class:`~adept_traj.results.Replay`: robot, scene and B-spline, loaded once) into a
:class:`Playback`: the frames, the joint positions, and every drawn node with its world
poses [m]. :mod:`~adept_traj.viz.meshcat_scene` draws a playback into a meshcat visualizer
or an HTML page; :mod:`~adept_traj.viz.server` serves it live.

What is drawn, all in the **world** frame of the scene [m]: the robot's link solids in the
colours of its visual model (poses ``scene.robot_base @`` the base-frame poses), the fixed
obstacles (red), the moving obstacles (purple: the pendulum's rod and bob) at the physical
time of each frame, each pendulum's pivot (a fixed dark ball at the pivot with a short
axle along the swing plane's normal, the axis it turns about), the tool path of the move
(a green line with a sphere at the start and the goal), the floor z = 0 with a 0.1 m grid
and the world axes and, optionally, the closest-point segment (yellow) between the robot's
collision solids and the nearest obstacle at every frame (:mod:`~adept_traj.viz.closest_points`).

Timing: frame ``k`` is shown at playback time ``k / fps`` [s] and shows the physical time

.. math:: t_k = \\min(k \\cdot \\text{speed} / \\text{fps},\\ T)

[s], the last frame exactly at ``T``: ``speed = 1`` is real time, ``speed = 0.5`` half speed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.certification import dense_samples
from adept_traj.errors import InvalidInputError
from adept_traj.results import (
    PlanningResult,
    Replay,
    certified_members,
    member_index,
    member_replay,
)
from adept_traj.validation import as_scalar, check_type, readonly_copy
from adept_traj.viz.closest_points import closest_points
from adept_traj.viz.framing import camera, floor
from adept_traj.viz.inputs import as_result
from adept_traj.viz.meshcat_geometry import (
    Part,
    hex_colour,
    pendulum_pivots,
    rotations_y_to,
    shape_parts,
    solid_parts,
    translation,
)
from adept_traj.viz.meshcat_modules import (
    Animation,
    AnimationFrameVisualizer,
    MeshcatPath,
    mg,
)

__all__ = [
    "DEFAULT_ROOT",
    "MAX_FRAMES",
    "MAX_PATH_POINTS",
    "PIVOT_COLOR",
    "Part",
    "Playback",
    "SceneObject",
    "build_animation",
    "frame_times",
    "framed_playback",
]

#: Most frames an animation may have (``fps · T / speed``).
MAX_FRAMES = 20_000
#: Points of the drawn tool path at most (the dense trajectory is thinned evenly).
MAX_PATH_POINTS = 4000
#: Root path of a meshcat visualizer (``meshcat.Visualizer().path``).
DEFAULT_ROOT = ("meshcat",)
FIXED_OBSTACLE_COLOR = 0xC0392B
MOVING_OBSTACLE_COLOR = 0x7D3C98
TOOL_PATH_COLOR = 0x1E8449
START_COLOR = 0x1E8449
GOAL_COLOR = 0x0B5345
CLOSEST_COLOR = 0xF1C40F
PIVOT_COLOR = 0x212F3C

_MARKER_RADIUS = 0.012  # tool path start/goal spheres [m]
_SEGMENT_RADIUS = 0.005  # closest-point segment [m]
_POINT_RADIUS = 0.01  # closest-point end spheres [m]


# ============================================================================ data
@dataclass(frozen=True, eq=False)
class SceneObject:
    """A node of the drawn scene.

    Attributes
    ----------
    path: meshcat path below the visualizer's root, e.g. ``"robot/link4/gripper"``.
    parts: what is drawn in the node's frame (:class:`Part`).
    poses: world poses of the node's frame: (n_frames, 4, 4) when animated, (4, 4) when
        fixed [m].
    scales: (n_frames, 3) per-frame scale of the node (only the closest-point segment), or
        ``None``.
    """

    path: str
    parts: tuple[Part, ...]
    poses: np.ndarray
    scales: np.ndarray | None = None

    @property
    def animated(self) -> bool:
        """True when the node moves (one pose per frame)."""
        return self.poses.ndim == 3

    @property
    def initial_pose(self) -> np.ndarray:
        """(4, 4) pose at the first frame, scale included."""
        pose = self.poses[0] if self.animated else self.poses
        if self.scales is not None:
            pose = pose @ np.diag([*self.scales[0], 1.0])
        return pose


@dataclass(frozen=True, eq=False)
class Playback:
    """Everything drawn and animated, independent of any visualizer.

    Attributes
    ----------
    objects: the scene nodes (robot solids, obstacles, tool path, closest segment, floor).
    times: (n_frames,) physical time of each frame [s], from 0 to ``duration``.
    frame_numbers: (n_frames,) animation keyframe of each frame, ``times / speed · fps``
        (integers except possibly the last).
    q: (n_frames, nq) joint positions at the frames [rad | m].
    fps: frames per second of playback [1/s].
    speed: playback rate (1 = real time).
    duration: travel time T of the move [s].
    member: the row of ``result.front`` shown (``result.best.index``: the best trade-off).
    certified: whether that member is certified
        (:func:`~adept_traj.results.certified_members`).
    tool_path: (n_points, 3) world tool positions along the dense trajectory [m].
    (The arrays are kept as read-only copies.)
    closest_points: (n_frames, 2, 3) world points on the robot and on the nearest obstacle
        at each frame [m], or ``None`` (not requested, or no obstacle).
    closest_distance: (n_frames,) their signed distance [m] (negative: penetration), or
        ``None``.
    camera_target, camera_position: (3,) world points the camera looks at and from [m].
    """

    objects: tuple[SceneObject, ...]
    times: np.ndarray
    frame_numbers: np.ndarray
    q: np.ndarray
    fps: float
    speed: float
    duration: float
    tool_path: np.ndarray
    closest_points: np.ndarray | None
    closest_distance: np.ndarray | None
    camera_target: np.ndarray
    camera_position: np.ndarray
    member: int = 0
    certified: bool = False

    def __post_init__(self) -> None:
        for name in ("times", "frame_numbers", "q", "tool_path", "camera_target",
                     "camera_position", "closest_points", "closest_distance"):  # fmt: skip
            value = getattr(self, name)
            object.__setattr__(self, name, None if value is None else readonly_copy(value))
        object.__setattr__(self, "objects", tuple(self.objects))

    @property
    def n_frames(self) -> int:
        """Number of frames."""
        return int(self.times.size)

    @property
    def playback_duration(self) -> float:
        """Length of one loop of the animation in the browser, ``duration / speed`` [s]."""
        return self.duration / self.speed

    def animation(self, root: Sequence[str] = DEFAULT_ROOT) -> Animation:
        """The meshcat animation of the animated nodes, for a visualizer whose path is
        ``root`` (default: a top-level ``meshcat.Visualizer``)."""
        anim = Animation(default_framerate=self.fps)
        base = MeshcatPath(tuple(root))
        for obj in self.objects:
            if not obj.animated:
                continue
            node = AnimationFrameVisualizer(anim, base, 0)[obj.path]
            for k, frame in enumerate(self.frame_numbers):
                at = AnimationFrameVisualizer(anim, node.path, float(frame))
                at.set_transform(obj.poses[k])
                if obj.scales is not None:
                    at.set_property("scale", "vector3", [float(v) for v in obj.scales[k]])
        return anim


# ============================================================================ building
def frame_times(duration: float, speed: float, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """Keyframes (n,) and physical times (n,) [s] of the frames of a move of ``duration``
    T [s] played at ``speed`` and ``fps`` [1/s]: keyframes 0, 1, … and a last one exactly
    at ``T / speed · fps`` (``ceil(fps · T / speed) + 1`` frames).

    Raises
    ------
    InvalidInputError
        More than :data:`MAX_FRAMES` frames.
    """
    last = duration / speed * fps  # keyframe of t = T
    n_whole = math.floor(last + 1e-9)
    if n_whole + 2 > MAX_FRAMES:
        raise InvalidInputError(
            f"fps · T / speed = {last:.0f} frames exceeds MAX_FRAMES = {MAX_FRAMES}; "
            "lower fps or raise speed"
        )
    frames = np.arange(n_whole + 1, dtype=float)
    if last - n_whole > 1e-9 or n_whole == 0:  # the last frame exactly at t = T
        frames = np.append(frames, last)
    times = np.minimum(frames * speed / fps, duration)
    times[-1] = duration
    return frames, times


def build_animation(
    result: PlanningResult,
    *,
    speed: float = 1.0,
    fps: float = 30.0,
    show_closest: bool = False,
    replay: Replay | None = None,
    member: int | None = None,
) -> Playback:
    """Compute the scene and the animation of a member of ``result``'s front (default: the
    best trade-off).

    Parameters
    ----------
    result: the planning result.
    speed: playback rate, > 0 (1 = real time, 0.5 = half speed).
    fps: frames per second of playback, > 0 [1/s]; the animation has
        ``ceil(fps · T / speed) + 1`` frames (at most :data:`MAX_FRAMES`).
    show_closest: also compute the closest-point segment between the robot's collision
        solids and the nearest obstacle at each frame.
    replay: the member's :class:`~adept_traj.results.Replay` if the caller has one (it must
        replay ``result.front.x[member]``); default
        ``Replay.of(result, result.front.x[member])``, which loads the robot files named in
        the result (they must exist) and parses its stored scene.
    member: the row of ``result.front`` to show, in [0, ``len(result.front)`` − 1];
        ``None`` (default): the best trade-off, ``result.best.index``. Any member is shown,
        certified or not: :attr:`Playback.certified` says which.

    Returns
    -------
    Playback

    Raises
    ------
    InvalidInputError: ``result`` is not a PlanningResult, ``member`` not a row of its
        front, ``replay`` not one of that member, ``speed`` or ``fps`` is not a positive
        finite number, too many frames, or a robot solid meshcat cannot draw.
    """
    result = as_result(result)
    speed = as_scalar(speed, "speed", "(playback rate, 1 = real time)", minimum=0, strict=True)
    fps = as_scalar(fps, "fps", "[frames/s]", minimum=0, strict=True)
    check_type(show_closest, (bool, np.bool_), "show_closest")
    index = member_index(result, member)
    replay = member_replay(result, index, replay)
    robot, scene, duration = replay.robot, replay.scene, replay.duration
    frames, times = frame_times(duration, speed, fps)
    q = replay.sample(times, orders=(0,)).q
    base = scene.robot_base

    objects: list[SceneObject] = []
    # --- robot: the visual solids, in the visual model's colours (else the collision solids)
    visual = robot.visual_model if robot.visual_model.ngeoms else robot.collision_model
    solid_poses = base @ robot.geometry_poses(q, visual)  # (n, n_geom, 4, 4)
    for k, g in enumerate(visual.geometryObjects):
        rgba = np.asarray(g.meshColor, dtype=float)
        material = mg.MeshLambertMaterial(color=hex_colour(rgba[:3]), opacity=float(rgba[3]))
        objects.append(SceneObject(f"robot/{g.name}", solid_parts(g, material), solid_poses[:, k]))

    # --- obstacles, at the scene time of each frame (t0 + t: the move's start time on)
    obstacle_poses = scene.obstacle_poses(replay.scene_time(times))  # (n_obs, n, 4, 4)
    for i, ob in enumerate(scene.obstacles):
        color = MOVING_OBSTACLE_COLOR if ob.is_moving else FIXED_OBSTACLE_COLOR
        material = mg.MeshLambertMaterial(color=color, opacity=1.0 if ob.is_moving else 0.85)
        poses = obstacle_poses[i] if ob.is_moving else obstacle_poses[i, 0]
        objects.append(SceneObject(f"obstacles/{ob.name}", shape_parts(ob.shape, material), poses))
    pivots = [SceneObject(*node) for node in pendulum_pivots(scene, PIVOT_COLOR)]
    objects.extend(pivots)

    # --- tool path of the dense trajectory
    tool = _tool_path(result, replay, index)
    objects.extend(_tool_path_objects(tool))

    # --- closest-point segment
    closest = distance = None
    if show_closest and scene.obstacles:
        closest, distance = closest_points(robot, scene, q, replay.scene_time(times))
        objects.extend(_closest_objects(closest))

    seen = [tool, solid_poses[..., :3, 3].reshape(-1, 3)]
    seen += [obstacle_poses[i, :, :3, 3] for i in range(len(scene.obstacles))]
    seen += [p.poses[None, :3, 3] for p in pivots]
    return framed_playback(
        objects,
        np.vstack(seen),
        times=times,
        frame_numbers=frames,
        q=q,
        fps=fps,
        speed=speed,
        tool_path=tool,
        closest_points=closest,
        closest_distance=distance,
        member=index,
        certified=bool(certified_members(result)[index]),
    )


def framed_playback(objects: Sequence[SceneObject], seen: np.ndarray, **fields: Any) -> Playback:
    """The :class:`Playback` of ``objects`` and of the floor and world axes under the points
    ``seen`` (m, 3) [m], with a camera framing them (:mod:`~adept_traj.viz.framing`) and
    ``duration = times[-1]``; ``fields``: the other fields. The one assembly of a playback:
    of a member (:func:`build_animation`) and of a whole cycle
    (:mod:`adept_traj.cycle.cycle_playback`)."""
    target, position = camera(seen)
    nodes = (*objects, *(SceneObject(path, p, pose) for path, p, pose in floor(seen)))
    duration = float(fields["times"][-1])
    return Playback(nodes, duration=duration, camera_target=target, camera_position=position,
                    **fields)  # fmt: skip


def _tool_path(result: PlanningResult, replay: Replay, index: int) -> np.ndarray:
    """(n, 3) world tool positions [m] at the dense samples of the certificate's rate (at
    most :data:`MAX_PATH_POINTS`, thinned evenly): the stored ones for the best trade-off,
    the replay's for another member."""
    if index != result.best.index:
        n = dense_samples(replay.duration, result.certificate.rate_hz)
        dense_q = replay.sample_uniform(min(n, MAX_PATH_POINTS), orders=(0,)).q
    else:
        dense_q = np.asarray(result.best_trajectory.q, dtype=float)
    if dense_q.shape[0] > MAX_PATH_POINTS:
        keep = np.unique(np.linspace(0, dense_q.shape[0] - 1, MAX_PATH_POINTS).round().astype(int))
        dense_q = dense_q[keep]
    return (replay.scene.robot_base @ replay.robot.tool_pose(dense_q))[:, :3, 3]


def _tool_path_objects(tool: np.ndarray) -> list[SceneObject]:
    line = mg.Line(
        mg.PointsGeometry(np.ascontiguousarray(tool.T, dtype=np.float32)),
        mg.LineBasicMaterial(color=TOOL_PATH_COLOR, linewidth=2.0),
    )
    objects = [SceneObject("tool_path/line", (Part(line, np.eye(4)),), np.eye(4))]
    for name, point, color in (("start", tool[0], START_COLOR), ("goal", tool[-1], GOAL_COLOR)):
        marker = mg.Mesh(mg.Sphere(_MARKER_RADIUS), mg.MeshLambertMaterial(color=color))
        objects.append(
            SceneObject(f"tool_path/{name}", (Part(marker, np.eye(4)),), translation(point))
        )
    return objects


def _closest_objects(points: np.ndarray) -> list[SceneObject]:
    """The closest-point segment (a unit cylinder along y, scaled and turned onto the
    segment at each frame) and its two end spheres, for ``points`` (n, 2, 3) [m]."""
    n = points.shape[0]
    d = points[:, 1] - points[:, 0]
    length = np.linalg.norm(d, axis=-1)
    seg_poses = np.tile(np.eye(4), (n, 1, 1))
    seg_poses[:, :3, 3] = 0.5 * (points[:, 0] + points[:, 1])
    turn = length > 1e-9
    seg_poses[turn, :3, :3] = rotations_y_to(d[turn] / length[turn, None])
    scales = np.ones((n, 3))
    scales[:, 1] = np.maximum(length, 1e-6)
    material = mg.MeshLambertMaterial(color=CLOSEST_COLOR)
    rod = Part(mg.Mesh(mg.Cylinder(1.0, _SEGMENT_RADIUS), material), np.eye(4))  # along y
    ends = []
    for i, name in enumerate(("robot_point", "obstacle_point")):
        poses = np.tile(np.eye(4), (n, 1, 1))
        poses[:, :3, 3] = points[:, i]
        ball = Part(mg.Mesh(mg.Sphere(_POINT_RADIUS), material), np.eye(4))
        ends.append(SceneObject(f"closest/{name}", (ball,), poses))
    return [SceneObject("closest/segment", (rod,), seg_poses, scales), *ends]
