"""Meshcat playback of a planning result: the robot moving along its best trajectory among
the obstacles, in the browser.

Two ways to watch a :class:`~adept_traj.results.PlanningResult`:

* :func:`show` starts a local meshcat server (bound to 127.0.0.1 only), draws the scene and
  the animation, and returns the :class:`meshcat.Visualizer`; open ``vis.url()`` in a browser,
  call ``vis.close()`` to stop the server.
* :func:`static_html` writes one self-contained HTML file (meshcat's viewer inlined, no
  network access, no server) that plays the animation on opening and loops.

What is drawn, all in the **world** frame of the scene [m]: the robot's link solids in the
colours of its visual model (poses ``scene.robot_base @`` the base-frame poses), the fixed
obstacles (red), the moving obstacles (purple: the pendulum's rod and bob) at the physical
time of each frame, the tool path of the best trajectory (a green line with a sphere at the
start and the goal), the floor z = 0 with a 0.1 m grid and the world axes and, optionally,
the closest-point segment (yellow) between the robot's collision solids and the nearest
obstacle at every frame (exact coal distances).

Timing: frame ``k`` is shown at playback time ``k / fps`` [s] and shows the physical time
``t_k = k · speed / fps`` [s] (the last frame exactly at ``T``): ``speed = 1`` is real time,
``speed = 0.5`` half speed. :func:`build_animation` computes all of it without any server;
:func:`draw` sends it to a visualizer.
"""

from __future__ import annotations

import atexit
import base64
import html
import math
import queue
import subprocess
import sys
import threading
import warnings
import webbrowser
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import coal
import numpy as np
import zmq

with warnings.catch_warnings():  # meshcat 0.3.2 imports pyzmq's deprecated zmq.eventloop.ioloop
    warnings.filterwarnings("ignore", "zmq.eventloop.ioloop is deprecated", DeprecationWarning)
    import meshcat
    import meshcat.geometry as mg
    import umsgpack
    from meshcat.animation import Animation, AnimationFrameVisualizer
    from meshcat.path import Path as MeshcatPath
    from meshcat.visualizer import ViewerWindow

from adept_traj.collision import distance_request
from adept_traj.errors import InvalidInputError, MeshcatServerError
from adept_traj.results.record import PlanningResult
from adept_traj.scene.scene import Obstacle
from adept_traj.scene.shapes import Box, Capsule, Cylinder, Shape, Sphere
from adept_traj.validation import readonly_copy

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

#: Flat background colour of the viewer (r, g, b in [0, 1]).
BACKGROUND_RGB = (0.96, 0.96, 0.97)
#: Most frames an animation may have (``fps · T / speed``).
MAX_FRAMES = 20_000
FIXED_OBSTACLE_COLOR = 0xC0392B
MOVING_OBSTACLE_COLOR = 0x7D3C98
TOOL_PATH_COLOR = 0x1E8449
START_COLOR = 0x1E8449
GOAL_COLOR = 0x0B5345
CLOSEST_COLOR = 0xF1C40F
#: Points of the drawn tool path at most (the dense trajectory is thinned evenly).
MAX_PATH_POINTS = 4000
#: Seconds to wait for the meshcat server to start.
SERVER_TIMEOUT_S = 30.0
#: Root path of a meshcat visualizer (``meshcat.Visualizer().path``).
DEFAULT_ROOT = ("meshcat",)

_MARKER_RADIUS = 0.012  # tool path start/goal spheres [m]
_SEGMENT_RADIUS = 0.005  # closest-point segment [m]
_POINT_RADIUS = 0.01  # closest-point end spheres [m]
_FOV_DEG = 75.0  # meshcat's default camera: vertical field of view
_VIEW_DIRECTION = np.array([-0.7, -1.2, 0.9])
_GRID_STEP = 0.1  # floor grid spacing [m]
_FLOOR_MARGIN = 0.3  # floor beyond the drawn scene [m]
FLOOR_COLOR = 0xE5E7E9
GRID_COLOR = 0xB3B6B7  # camera offset direction from the target


# ============================================================================ data
@dataclass(frozen=True, eq=False)
class Part:
    """One drawable of a :class:`SceneObject`.

    Attributes
    ----------
    obj: the meshcat object (``meshcat.geometry.Mesh`` or ``Line``).
    local: (4, 4) its placement in the object's frame (e.g. the 90° turn that puts a meshcat
        cylinder's y axis on coal's z axis).
    """

    obj: mg.Object
    local: np.ndarray


@dataclass(frozen=True, eq=False)
class SceneObject:
    """A node of the drawn scene.

    Attributes
    ----------
    path: meshcat path below the visualizer's root, e.g. ``"robot/link4/gripper"``.
    parts: what is drawn in the node's frame.
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
    objects: the scene nodes (robot solids, obstacles, tool path, closest segment).
    times: (n_frames,) physical time of each frame [s], from 0 to ``duration``.
    frame_numbers: (n_frames,) animation keyframe of each frame, ``times / speed · fps``
        (integers except possibly the last).
    q: (n_frames, nq) joint positions at the frames [rad | m].
    fps: frames per second of playback [1/s].
    speed: playback rate (1 = real time).
    duration: travel time T of the best trajectory [s].
    tool_path: (n_points, 3) world tool positions along the dense trajectory [m].
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
def build_animation(
    result: PlanningResult, *, speed: float = 1.0, fps: float = 30.0, show_closest: bool = False
) -> Playback:
    """Compute the scene and the animation of ``result``'s best trajectory.

    Parameters
    ----------
    result: the planning result (its robot files must exist: the problem is rebuilt).
    speed: playback rate, > 0 (1 = real time, 0.5 = half speed).
    fps: frames per second of playback, > 0 [1/s]; the animation has
        ``ceil(fps · T / speed) + 1`` frames (at most :data:`MAX_FRAMES`).
    show_closest: also compute the closest-point segment between the robot's collision
        solids and the nearest obstacle at each frame (exact coal distances).

    Returns
    -------
    Playback

    Raises
    ------
    InvalidInputError: ``result`` is not a PlanningResult, ``speed`` or ``fps`` is not a
        positive finite number, too many frames, or a robot solid meshcat cannot draw.
    """
    if not isinstance(result, PlanningResult):
        raise InvalidInputError(f"result must be a PlanningResult; got {type(result).__name__}")
    speed = _positive(speed, "speed", "(playback rate, 1 = real time)")
    fps = _positive(fps, "fps", "[frames/s]")
    if not isinstance(show_closest, (bool, np.bool_)):
        raise InvalidInputError(f"show_closest must be True or False; got {show_closest!r}")

    problem = result.problem()
    robot, scene = problem.robot, problem.scene
    x = np.asarray(result.best_x, dtype=float)
    duration = float(problem.trajectory.decode(x)[0])

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
    q = problem.trajectory.sample(x, times / duration, orders=(0,)).q
    base = scene.robot_base

    objects: list[SceneObject] = []
    # --- robot: the visual solids, in the visual model's colours (else the collision solids)
    visual = robot.visual_model if robot.visual_model.ngeoms else robot.collision_model
    solid_poses = base @ robot.geometry_poses(q, visual)  # (n, n_geom, 4, 4)
    for k, g in enumerate(visual.geometryObjects):
        rgba = np.asarray(g.meshColor, dtype=float)
        material = mg.MeshLambertMaterial(color=_hex(rgba[:3]), opacity=float(rgba[3]))
        parts = _solid_parts(g, material)
        objects.append(SceneObject(f"robot/{g.name}", parts, solid_poses[:, k]))

    # --- obstacles, at the physical time of each frame
    obstacle_poses = scene.obstacle_poses(times)  # (n_obs, n, 4, 4)
    for i, ob in enumerate(scene.obstacles):
        color = MOVING_OBSTACLE_COLOR if ob.is_moving else FIXED_OBSTACLE_COLOR
        material = mg.MeshLambertMaterial(color=color, opacity=1.0 if ob.is_moving else 0.85)
        poses = obstacle_poses[i] if ob.is_moving else obstacle_poses[i, 0]
        objects.append(SceneObject(f"obstacles/{ob.name}", _shape_parts(ob.shape, material), poses))

    # --- tool path of the dense (certified) trajectory
    dense_q = np.asarray(result.best_trajectory.q, dtype=float)
    if dense_q.shape[0] > MAX_PATH_POINTS:
        keep = np.unique(np.linspace(0, dense_q.shape[0] - 1, MAX_PATH_POINTS).round().astype(int))
        dense_q = dense_q[keep]
    tool = (base @ robot.tool_pose(dense_q))[:, :3, 3]
    line = mg.Line(
        mg.PointsGeometry(np.ascontiguousarray(tool.T, dtype=np.float32)),
        mg.LineBasicMaterial(color=TOOL_PATH_COLOR, linewidth=2.0),
    )
    objects.append(SceneObject("tool_path/line", (Part(line, np.eye(4)),), np.eye(4)))
    for name, point, color in (("start", tool[0], START_COLOR), ("goal", tool[-1], GOAL_COLOR)):
        marker = mg.Mesh(mg.Sphere(_MARKER_RADIUS), mg.MeshLambertMaterial(color=color))
        objects.append(
            SceneObject(f"tool_path/{name}", (Part(marker, np.eye(4)),), _translation(point))
        )

    # --- closest-point segment
    closest_points = closest_distance = None
    if show_closest and scene.obstacles:
        solids = base @ robot.geometry_poses(q)  # collision model, world
        closest_points, closest_distance = _closest_points(
            [g.geometry for g in robot.collision_model.geometryObjects],
            solids,
            scene.obstacles,
            obstacle_poses,
        )
        objects.extend(_closest_objects(closest_points))

    seen = [tool, solid_poses[..., :3, 3].reshape(-1, 3)]
    seen += [obstacle_poses[i, :, :3, 3] for i in range(len(scene.obstacles))]
    seen_points = np.vstack(seen)
    objects.extend(_floor(seen_points))
    target, position = _camera(seen_points)
    return Playback(
        objects=tuple(objects),
        times=readonly_copy(times),
        frame_numbers=readonly_copy(frames),
        q=readonly_copy(np.array(q)),
        fps=fps,
        speed=speed,
        duration=duration,
        tool_path=readonly_copy(tool),
        closest_points=None if closest_points is None else readonly_copy(closest_points),
        closest_distance=None if closest_distance is None else readonly_copy(closest_distance),
        camera_target=readonly_copy(target),
        camera_position=readonly_copy(position),
    )


def _positive(value: Any, name: str, unit: str) -> float:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)):
        raise InvalidInputError(f"{name} must be a positive number {unit}; got {value!r}")
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise InvalidInputError(f"{name} must be a positive finite number {unit}; got {v!r}")
    return v


def _hex(rgb: np.ndarray) -> int:
    r, g, b = (round(255 * min(max(float(c), 0.0), 1.0)) for c in rgb)
    return (r << 16) | (g << 8) | b


def _translation(p: np.ndarray) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = p
    return m


#: Turns a meshcat (three.js) cylinder, axis along local y, onto coal's z axis.
_Y_TO_Z = np.array([[1.0, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]])


def _cylinder(radius: float, length: float, material: mg.Material) -> Part:
    return Part(mg.Mesh(mg.Cylinder(length, radius), material), _Y_TO_Z.copy())


def _capsule(radius: float, length: float, material: mg.Material) -> tuple[Part, ...]:
    caps = tuple(
        Part(mg.Mesh(mg.Sphere(radius), material), _translation([0.0, 0.0, z]))
        for z in (-0.5 * length, 0.5 * length)
    )
    return (_cylinder(radius, length, material), *caps)


def _shape_parts(shape: Shape, material: mg.Material) -> tuple[Part, ...]:
    """Meshcat parts of an adept_traj obstacle shape (centred, axis along local z)."""
    if isinstance(shape, Box):
        return (Part(mg.Mesh(mg.Box([float(s) for s in shape.size]), material), np.eye(4)),)
    if isinstance(shape, Sphere):
        return (Part(mg.Mesh(mg.Sphere(shape.radius), material), np.eye(4)),)
    if isinstance(shape, Cylinder):
        return (_cylinder(shape.radius, shape.length, material),)
    if isinstance(shape, Capsule):
        return _capsule(shape.radius, shape.length, material)
    raise InvalidInputError(f"cannot draw obstacle shape {type(shape).__name__}")


def _solid_parts(gobj: Any, material: mg.Material) -> tuple[Part, ...]:
    """Meshcat parts of a robot solid (a ``pinocchio.GeometryObject``: a coal geometry in the
    solid's frame, or a mesh file)."""
    geometry, name = gobj.geometry, gobj.name
    if isinstance(geometry, coal.Box):
        lengths = [2.0 * float(h) for h in geometry.halfSide]
        return (Part(mg.Mesh(mg.Box(lengths), material), np.eye(4)),)
    if isinstance(geometry, coal.Sphere):
        return (Part(mg.Mesh(mg.Sphere(float(geometry.radius)), material), np.eye(4)),)
    if isinstance(geometry, coal.Cylinder):
        return (_cylinder(float(geometry.radius), 2.0 * float(geometry.halfLength), material),)
    if isinstance(geometry, coal.Capsule):
        return _capsule(float(geometry.radius), 2.0 * float(geometry.halfLength), material)
    if isinstance(geometry, coal.Cone):  # base at z = -h/2, apex at +h/2 (three.js: +y)
        height, radius = 2.0 * float(geometry.halfLength), float(geometry.radius)
        cone = mg.Cylinder(height, radiusTop=0.0, radiusBottom=radius)
        return (Part(mg.Mesh(cone, material), _Y_TO_Z.copy()),)
    if isinstance(geometry, coal.Ellipsoid):
        return (Part(mg.Mesh(mg.Ellipsoid(list(geometry.radii)), material), np.eye(4)),)
    mesh_path = str(getattr(gobj, "meshPath", "") or "")
    path = Path(mesh_path) if mesh_path else None
    if path is not None and path.is_file():
        loaders = {
            ".stl": mg.StlMeshGeometry,
            ".obj": mg.ObjMeshGeometry,
            ".dae": mg.DaeMeshGeometry,
        }
        loader = loaders.get(path.suffix.lower())
        if loader is not None:
            scale = np.diag([*np.asarray(gobj.meshScale, dtype=float), 1.0])
            return (Part(mg.Mesh(loader.from_file(str(path)), material), scale),)
    raise InvalidInputError(
        f"robot solid {name!r}: cannot draw a {type(geometry).__name__} "
        "(supported: box, sphere, cylinder, capsule, cone, ellipsoid, .stl/.obj/.dae mesh)"
    )


def _closest_points(
    robot_geoms: list[Any],
    solid_poses: np.ndarray,
    obstacles: Sequence[Obstacle],
    obstacle_poses: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Per frame, the nearest (solid, obstacle) pair's witness points (n, 2, 3) in the world
    and their signed distance (n,) [m]."""
    n = solid_poses.shape[0]
    obstacle_geoms = [ob.shape.to_coal() for ob in obstacles]
    request, res = distance_request(), coal.DistanceResult()  # the checker's settings
    tf_a, tf_b = coal.Transform3s(), coal.Transform3s()
    points = np.empty((n, 2, 3))
    distance = np.full(n, np.inf)
    for k in range(n):
        for s, g in enumerate(robot_geoms):
            tf_a.setRotation(solid_poses[k, s, :3, :3])
            tf_a.setTranslation(solid_poses[k, s, :3, 3])
            for o, h in enumerate(obstacle_geoms):
                tf_b.setRotation(obstacle_poses[o, k, :3, :3])
                tf_b.setTranslation(obstacle_poses[o, k, :3, 3])
                res.clear()
                d = coal.distance(g, tf_a, h, tf_b, request, res)
                if d < distance[k]:
                    distance[k] = d
                    points[k, 0] = res.getNearestPoint1()
                    points[k, 1] = res.getNearestPoint2()
    return points, distance


def _rotation_y_to(u: np.ndarray) -> np.ndarray:
    """(3, 3) rotation taking the y axis onto the unit vector ``u``."""
    y = np.array([0.0, 1.0, 0.0])
    c = float(np.dot(y, u))
    if c < -1.0 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])  # half turn about x
    v = np.cross(y, u)
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx / (1.0 + c)


def _closest_objects(points: np.ndarray) -> list[SceneObject]:
    n = points.shape[0]
    seg_poses = np.tile(np.eye(4), (n, 1, 1))
    scales = np.ones((n, 3))
    for k in range(n):
        a, b = points[k]
        d = b - a
        length = float(np.linalg.norm(d))
        seg_poses[k, :3, 3] = 0.5 * (a + b)
        if length > 1e-9:
            seg_poses[k, :3, :3] = _rotation_y_to(d / length)
        scales[k, 1] = max(length, 1e-6)
    material = mg.MeshLambertMaterial(color=CLOSEST_COLOR)
    rod = Part(mg.Mesh(mg.Cylinder(1.0, _SEGMENT_RADIUS), material), np.eye(4))  # along y
    ends = []
    for i, name in enumerate(("robot_point", "obstacle_point")):
        poses = np.tile(np.eye(4), (n, 1, 1))
        poses[:, :3, 3] = points[:, i]
        ball = Part(mg.Mesh(mg.Sphere(_POINT_RADIUS), material), np.eye(4))
        ends.append(SceneObject(f"closest/{name}", (ball,), poses))
    return [SceneObject("closest/segment", (rod,), seg_poses, scales), *ends]


def _floor(points: np.ndarray) -> list[SceneObject]:
    """The floor z = 0 under ``points`` (n, 3): a light slab with a 0.1 m grid, and the world
    axes (x red, y green, z blue, 0.2 m) at the origin."""
    lo = np.floor((points[:, :2].min(axis=0) - _FLOOR_MARGIN) / _GRID_STEP) * _GRID_STEP
    hi = np.ceil((points[:, :2].max(axis=0) + _FLOOR_MARGIN) / _GRID_STEP) * _GRID_STEP
    size = hi - lo
    slab = mg.Mesh(mg.Box([*size, 0.004]), mg.MeshLambertMaterial(color=FLOOR_COLOR))
    centre = _translation([*(0.5 * (lo + hi)), -0.0021])
    segments = []
    for axis in (0, 1):
        n = round(size[axis] / _GRID_STEP)
        for v in lo[axis] + _GRID_STEP * np.arange(n + 1):
            a, b = np.zeros(3), np.zeros(3)
            a[axis] = b[axis] = v
            a[1 - axis], b[1 - axis] = lo[1 - axis], hi[1 - axis]
            segments += [a, b]
    grid = mg.LineSegments(
        mg.PointsGeometry(np.ascontiguousarray(np.array(segments).T, dtype=np.float32)),
        mg.LineBasicMaterial(color=GRID_COLOR),
    )
    return [
        SceneObject("floor/slab", (Part(slab, np.eye(4)),), centre),
        SceneObject("floor/grid", (Part(grid, np.eye(4)),), np.eye(4)),
        SceneObject("floor/axes", (Part(mg.triad(0.2), np.eye(4)),), np.eye(4)),
    ]


def _camera(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A camera target (the centre of the box around ``points`` (n, 3)) and a position from
    which all of it is in view [m]."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    target = 0.5 * (lo + hi)
    radius = max(0.5 * float(np.linalg.norm(hi - lo)), 0.3) + 0.15
    distance = 1.05 * radius / math.tan(math.radians(0.5 * _FOV_DEG))
    direction = _VIEW_DIRECTION / np.linalg.norm(_VIEW_DIRECTION)
    return target, target + distance * direction


# ============================================================================ drawing
def draw(vis: meshcat.Visualizer, playback: Playback, *, loop: bool = True) -> None:
    """Send ``playback`` to ``vis`` (a top-level visualizer): background, camera, every node,
    then the animation (playing; looping forever when ``loop``, else played once).

    Meshcat's orbit camera always turns about the viewer's origin, so the visualizer's root
    node is shifted by ``-playback.camera_target``: every node below it keeps its world pose.
    Meshcat's own grid and axes (20 m wide, at the viewer's origin) are hidden; the playback
    draws its own floor and world axes.
    """
    vis.set_transform(_translation(-playback.camera_target))
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


# ============================================================================ live viewer
# The meshcat 0.3.2 server binds its web server on every interface (tornado's listen() with
# no address) although it prints a 127.0.0.1 URL; this launcher binds it to 127.0.0.1.
_SERVER_SCRIPT = """
import functools, sys
from meshcat.servers import zmqserver as z
_make_app = z.ZMQWebSocketBridge.make_app
def make_app(self):
    app = _make_app(self)
    app.listen = functools.partial(app.listen, address=self.host)
    return app
z.ZMQWebSocketBridge.make_app = make_app
sys.argv = ["meshcat-server"]
z.main()
"""


class _LocalWindow(ViewerWindow):
    """A meshcat server of our own on 127.0.0.1 (ZeroMQ and web), silent, closable."""

    def __init__(self, timeout: float = SERVER_TIMEOUT_S) -> None:  # no super(): it prints
        self._closed = False
        self.server_proc = subprocess.Popen(
            [sys.executable, "-u", "-c", _SERVER_SCRIPT],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        atexit.register(self.close)
        lines: queue.Queue[str | None] = queue.Queue()

        def pump() -> None:  # reads the server's stdout to the end: the pipe never fills
            assert self.server_proc.stdout is not None
            for raw in self.server_proc.stdout:
                lines.put(raw.decode("utf-8", "replace").strip())
            lines.put(None)

        threading.Thread(target=pump, name="meshcat-server-stdout", daemon=True).start()
        found: dict[str, str] = {}
        try:
            while len(found) < 2:
                line = lines.get(timeout=timeout)
                if line is None:
                    raise MeshcatServerError(
                        f"the meshcat server exited with code {self.server_proc.wait()}"
                    )
                key, _, value = line.partition("=")
                if key in ("zmq_url", "web_url"):
                    found[key] = value
        except queue.Empty:
            self.close()
            raise MeshcatServerError(
                f"the meshcat server did not start within {timeout:g} s"
            ) from None
        except BaseException:
            self.close()
            raise
        self.zmq_url, self.web_url = found["zmq_url"], found["web_url"]
        self.connect_zmq()

    def connect_zmq(self) -> None:
        self.zmq_socket = self.context.socket(zmq.REQ)
        self.zmq_socket.setsockopt(zmq.LINGER, 0)
        self.zmq_socket.setsockopt(zmq.RCVTIMEO, int(1000 * SERVER_TIMEOUT_S))
        self.zmq_socket.connect(self.zmq_url)

    def send(self, command: Any) -> None:
        try:
            super().send(command)
        except zmq.Again:
            raise MeshcatServerError("the meshcat server does not answer") from None

    def close(self) -> None:
        """Stop the server (idempotent)."""
        if self._closed:
            return
        self._closed = True
        atexit.unregister(self.close)
        socket = getattr(self, "zmq_socket", None)
        if socket is not None:
            socket.close(linger=0)
        if self.server_proc.poll() is None:
            self.server_proc.kill()
        self.server_proc.wait(timeout=10)

    @property
    def closed(self) -> bool:
        """True once :meth:`close` has run."""
        return self._closed


def show(
    result: PlanningResult,
    *,
    speed: float = 1.0,
    fps: float = 30.0,
    loop: bool = True,
    show_closest: bool = False,
    open_browser: bool = False,
) -> meshcat.Visualizer:
    """Start a local meshcat server and play ``result``'s best trajectory in it.

    The server (a subprocess) listens on 127.0.0.1 only: its ZeroMQ socket and its web
    server. Nothing is printed; ``vis.url()`` is the page to open, ``vis.close()`` stops the
    server (it is also stopped when Python exits).

    Parameters
    ----------
    result: the planning result.
    speed, fps, show_closest: see :func:`build_animation`.
    loop: loop the animation forever (else play it once).
    open_browser: also open the page in the default web browser.

    Returns
    -------
    meshcat.Visualizer
        The visualizer, drawn and playing.

    Raises
    ------
    InvalidInputError: see :func:`build_animation` (raised before any server starts).
    MeshcatServerError: the server did not start or does not answer.
    """
    playback = build_animation(result, speed=speed, fps=fps, show_closest=show_closest)
    window = _LocalWindow()
    vis = meshcat.Visualizer(window=window)
    try:
        draw(vis, playback, loop=loop)
        if open_browser:
            webbrowser.open(vis.url(), new=2)
    except BaseException:
        window.close()
        raise
    return vis


# ============================================================================ static page
class _RecordingWindow:
    """Stands in for a meshcat window: keeps every command as the viewer's msgpack bytes."""

    def __init__(self) -> None:
        self.commands: list[bytes] = []

    def send(self, command: Any) -> None:
        self.commands.append(umsgpack.packb(command.lower()))

    def close(self) -> None:
        pass


def _viewer_js() -> str:
    path = Path(meshcat.__file__).resolve().parent / "viewer" / "dist" / "main.min.js"
    if not path.is_file():
        raise MeshcatServerError(f"meshcat's viewer script is missing: {path}")
    return path.read_text(encoding="utf-8")


def render_html(playback: Playback, *, loop: bool = True, title: str = "adept_traj") -> str:
    """A self-contained HTML page (meshcat's viewer inlined, no network) playing
    ``playback`` on opening."""
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
) -> Path:
    """Write a self-contained HTML page playing ``result``'s best trajectory.

    The page inlines meshcat's viewer and the scene (no server, no network access); the
    animation starts on opening and loops (``loop=False``: plays once). About 0.9 MB.

    Parameters
    ----------
    result: the planning result.
    path: the file to write (its folder is created if needed).
    speed, fps, show_closest: see :func:`build_animation`.
    loop: loop the animation forever.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    playback = build_animation(result, speed=speed, fps=fps, show_closest=show_closest)
    out = Path(path)
    title = f"adept_traj — {result.algorithm}, T = {playback.duration:.3f} s"
    page = render_html(playback, loop=loop, title=title)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(page, encoding="utf-8")
    return out
