"""Scenes: obstacles with a shape and a motion law, the robot base pose, an optional task.

A :class:`Scene` is a frozen value object. It is built in Python, or read from a TOML scene
file (:meth:`Scene.from_file`, :meth:`Scene.paper`; reading and writing live in
:mod:`adept_traj.scene.scene_file`, format in ``docs/scene-files.md``). Everything is in the
*world* frame, SI units: obstacle poses are world poses, ``robot_base`` is the pose of the
robot's base frame in the world.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from adept_traj.errors import InputShapeError, InvalidInputError, ResourceLimitError, SceneError
from adept_traj.scene.meshes import Mesh
from adept_traj.scene.motion_laws import FixedPose, MotionLaw, PendulumMotion
from adept_traj.scene.point_clouds import PointCloud
from adept_traj.scene.shapes import Cylinder, Shape, Sphere, ValueObject
from adept_traj.transforms import as_rigid_transform, transform_from_xyz_rpy
from adept_traj.validation import as_finite_array, check_type, readonly_copy

__all__ = [
    "BOB_SUFFIX",
    "MAX_OBSTACLES",
    "ROD_SUFFIX",
    "Obstacle",
    "Scene",
    "check_obstacle_count",
    "pendulum_obstacles",
    "scene_notes",
]

#: Most obstacles a scene may hold (a pendulum counts as its two obstacles). Every
#: evaluation computes robot–obstacle distances for every pair (and the dense certificate
#: holds (n_samples, n_solids, n_obstacles) distances: 2 GB at 1 kHz over 5 s with 10 000
#: obstacles and 5 solids); far beyond this a scene file takes minutes to load.
MAX_OBSTACLES = 10_000

#: Name suffix of a pendulum's rod obstacle (``"<pendulum>.rod"``).
ROD_SUFFIX = ".rod"
#: Name suffix of a pendulum's bob obstacle (``"<pendulum>.bob"``).
BOB_SUFFIX = ".bob"


def _identity() -> np.ndarray:
    return np.eye(4)


def _fixed_identity() -> FixedPose:
    return FixedPose(np.eye(4))


@dataclass(frozen=True, eq=False)
class Obstacle(ValueObject):
    """A solid obstacle: a shape placed by a motion law.

    The world pose of the shape's frame at time t is ``motion.pose(t) @ offset``.

    Attributes
    ----------
    name: unique (within a scene), non-empty name.
    shape: the solid, centred on its own frame (see :mod:`adept_traj.scene.shapes`).
    motion: world pose of the moving frame over time; default: fixed at the origin.
    offset: (4, 4) rigid pose of the shape's frame in the motion's frame [m]; default
        identity. Lets several obstacles share one motion law (a pendulum's rod and bob).
    """

    name: str
    shape: Shape
    motion: MotionLaw = field(default_factory=_fixed_identity)
    offset: np.ndarray = field(default_factory=_identity)

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise InvalidInputError(f"name must be a non-empty string; got {self.name!r}")
        check_type(self.shape, Shape, f"obstacle {self.name!r}: shape")
        check_type(self.motion, MotionLaw, f"obstacle {self.name!r}: motion")
        offset = as_rigid_transform(self.offset, "offset")
        object.__setattr__(self, "offset", readonly_copy(offset))

    @property
    def is_moving(self) -> bool:
        """True when the obstacle's pose depends on time."""
        return not self.motion.is_fixed

    def pose(self, t: Any) -> np.ndarray:
        """World pose of the shape's frame.

        Parameters
        ----------
        t: times [s], any shape (...); e.g. (n,).

        Returns
        -------
        (..., 4, 4) homogeneous transforms (a new array).
        """
        return self.motion.pose(t) @ self.offset

    def swept_ball(self) -> tuple[np.ndarray, float]:
        """A fixed ball containing the obstacle at every time (for a broad phase).

        Returns
        -------
        ``(centre, radius)``: (3,) world centre [m] and radius [m]. For a fixed obstacle
        it is the shape's bounding ball; for a moving one, a ball containing that
        bounding ball over the whole motion (see :meth:`MotionLaw.swept_ball`).
        """
        return self.motion.swept_ball(self.offset[:3, 3], self.shape.bounding_radius)


def pendulum_obstacles(
    name: str, motion: PendulumMotion, *, bob_radius: float, rod_radius: float = 0.01
) -> tuple[Obstacle, Obstacle]:
    """The two obstacles of a pendulum, sharing its motion law: its rod and its bob.

    Parameters
    ----------
    name: the pendulum's name; the obstacles are named ``name + ".rod"`` and ``name + ".bob"``.
    motion: the pendulum's motion law.
    bob_radius: radius of the spherical bob [m].
    rod_radius: radius of the cylindrical rod [m] (default 0.01).

    Returns
    -------
    ``(rod, bob)``. The rod is a :class:`Cylinder` of length l from the pivot to the bob
    centre: its centre at the middle of pivot–bob, its z axis along the rod. The bob is a
    :class:`Sphere` centred at :meth:`PendulumMotion.bob_position`.
    """
    check_type(motion, PendulumMotion, "motion")
    if not isinstance(name, str) or not name:
        raise InvalidInputError(f"name must be a non-empty string; got {name!r}")
    length = motion.length
    rod = Obstacle(
        name + ROD_SUFFIX,
        Cylinder(rod_radius, length),
        motion,
        transform_from_xyz_rpy((0.0, 0.0, -0.5 * length)),
    )
    bob = Obstacle(
        name + BOB_SUFFIX,
        Sphere(bob_radius),
        motion,
        transform_from_xyz_rpy((0.0, 0.0, -length)),
    )
    return rod, bob


def scene_notes(scene: Scene) -> tuple[str, ...]:
    """What a distance certificate means for the scene's obstacles that are not exact solids,
    one line each: a point cloud's octree resolution (its guarantee), an open mesh (a thin
    surface, no inside test). Printed with every certificate by ``adept-traj verify``."""
    notes = []
    for ob in scene.obstacles:
        if isinstance(ob.shape, PointCloud):
            notes.append(f"{ob.name!r} ({ob.shape.n_points} points): {ob.shape.guarantee}")
        elif isinstance(ob.shape, Mesh) and not ob.shape.closed:
            notes.append(f"{ob.name!r}: open mesh, a thin surface (a solid inside it is not seen)")
    return tuple(notes)


def check_obstacle_count(n: int, source: str = "scene") -> int:
    """Return ``n`` if a scene may hold ``n`` obstacles, else raise
    :class:`~adept_traj.errors.ResourceLimitError` naming ``source``, ``n`` and
    :data:`MAX_OBSTACLES`. Readers call it on the number of entries before building any
    obstacle."""
    if n > MAX_OBSTACLES:
        raise ResourceLimitError(
            f"{source}: {n} obstacles, more than the limit MAX_OBSTACLES = {MAX_OBSTACLES}"
        )
    return n


def _as_joint_vector(value: Any, name: str) -> np.ndarray:
    arr = as_finite_array(value, name)
    if arr.ndim != 1 or arr.size == 0:
        raise InputShapeError(
            f"{name} must be a non-empty joint vector of shape (nq,) [rad | m]; "
            f"got shape {arr.shape}"
        )
    return readonly_copy(arr)


@dataclass(frozen=True, eq=False)
class Scene(ValueObject):
    """Obstacles, robot base pose and an optional default task, in the world frame.

    Attributes
    ----------
    obstacles: the obstacles (tuple; names unique).
    robot_base: (4, 4) rigid pose of the robot base frame in the world [m]; default identity.
    start: optional (nq,) default start configuration, in the robot's joint order
        [rad for revolute, m for prismatic joints]; given together with ``goal``.
    goal: optional (nq,) default goal configuration, same length as ``start``.
    name: the scene's name.
    allowed_contacts: ``(robot link, obstacle)`` name pairs never checked (a floor under
        the base): the link's solids and the obstacle count as always clear.

    Array-like inputs are copied into new read-only arrays.
    """

    obstacles: tuple[Obstacle, ...] = ()
    robot_base: np.ndarray = field(default_factory=_identity)
    start: np.ndarray | None = None
    goal: np.ndarray | None = None
    name: str = "scene"
    allowed_contacts: tuple[tuple[str, str], ...] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise InvalidInputError(f"name must be a non-empty string; got {self.name!r}")
        if isinstance(self.obstacles, (str, bytes)) or not isinstance(self.obstacles, Sequence):
            raise InvalidInputError(
                f"obstacles must be a sequence of Obstacle; got {type(self.obstacles).__name__}"
            )
        obstacles = tuple(self.obstacles)
        check_obstacle_count(len(obstacles), f"scene {self.name!r}")
        for i, ob in enumerate(obstacles):
            if not isinstance(ob, Obstacle):
                raise InvalidInputError(
                    f"obstacles[{i}] must be an Obstacle; got {type(ob).__name__}"
                )
        seen: set[str] = set()
        for ob in obstacles:
            if ob.name in seen:
                raise SceneError(
                    f"obstacle {ob.name!r}: field 'name' must be unique; {ob.name!r} is used "
                    "more than once"
                )
            seen.add(ob.name)
        base = as_rigid_transform(self.robot_base, "robot_base")
        if (self.start is None) != (self.goal is None):
            raise SceneError("start and goal must be given together (or neither)")
        start = goal = None
        if self.start is not None and self.goal is not None:
            start = _as_joint_vector(self.start, "start")
            goal = _as_joint_vector(self.goal, "goal")
            if start.shape != goal.shape:
                raise SceneError(
                    f"start and goal must have the same length; got {start.size} and {goal.size}"
                )
        allowed = tuple((str(a), str(b)) for a, b in self.allowed_contacts)
        unknown = sorted({b for _, b in allowed} - seen)
        if unknown:
            raise SceneError(
                f"allowed_contacts name obstacle(s) {unknown} the scene does not have; its "
                f"obstacles are {sorted(seen)}"
            )
        object.__setattr__(self, "allowed_contacts", allowed)
        object.__setattr__(self, "obstacles", obstacles)
        object.__setattr__(self, "robot_base", readonly_copy(base))
        object.__setattr__(self, "start", start)
        object.__setattr__(self, "goal", goal)

    # ------------------------------------------------------------------ queries
    @property
    def names(self) -> tuple[str, ...]:
        """Obstacle names, in order."""
        return tuple(ob.name for ob in self.obstacles)

    @property
    def moving(self) -> tuple[Obstacle, ...]:
        """The obstacles whose pose depends on time, in order."""
        return tuple(ob for ob in self.obstacles if ob.is_moving)

    @property
    def fixed(self) -> tuple[Obstacle, ...]:
        """The obstacles that do not move, in order."""
        return tuple(ob for ob in self.obstacles if not ob.is_moving)

    @property
    def pendulums(self) -> dict[str, PendulumMotion]:
        """Each pendulum's name (its obstacles' before the last dot) and its motion law."""
        found: dict[str, PendulumMotion] = {}
        for ob in self.obstacles:
            if isinstance(ob.motion, PendulumMotion):
                found.setdefault(ob.name.rpartition(".")[0] or ob.name, ob.motion)
        return found

    def obstacle(self, name: str) -> Obstacle:
        """The obstacle called ``name`` (raises InvalidInputError listing the names if absent)."""
        for ob in self.obstacles:
            if ob.name == name:
                return ob
        raise InvalidInputError(
            f"scene {self.name!r} has no obstacle {name!r}; obstacles: {list(self.names)}"
        )

    def obstacle_poses(self, t: Any, *, in_base_frame: bool = False) -> np.ndarray:
        """Poses of every obstacle at times ``t``.

        Parameters
        ----------
        t: times [s], any shape (...); e.g. (n,).
        in_base_frame: if True, poses relative to the robot base frame
            (``inv(robot_base) @ world pose``); else world poses.

        Returns
        -------
        (n_obs, ..., 4, 4) homogeneous transforms, obstacles in scene order.
        """
        times = as_finite_array(t, "t")
        if not self.obstacles:
            return np.zeros((0, *times.shape, 4, 4))
        poses = np.stack([ob.pose(times) for ob in self.obstacles])
        if in_base_frame:
            poses = self.base_from_world @ poses
        return poses

    @property
    def base_from_world(self) -> np.ndarray:
        """(4, 4) inverse of ``robot_base`` (``pin.SE3.inverse``): maps world coordinates to
        base coordinates [m]."""
        return pin.SE3(self.robot_base).inverse().homogeneous

    # ------------------------------------------------------------------ scene files
    # The reader and writer (adept_traj.scene.scene_file) build Scenes, so they import this
    # module; these methods import them when called.
    @classmethod
    def paper(cls) -> Scene:
        """The paper's scene: two fixed cubes and the pendulum (``data/scenes/paper.toml``).

        The cubes and the pendulum law are the paper's; the robot base pose, the task's d3
        values and the pivot are a reconstruction (the paper does not give them), see
        ``docs/paper-scenario.md``.
        """
        from adept_traj.scene.scene_file import read_paper_scene

        return read_paper_scene()

    @classmethod
    def shipped(cls, name: str) -> Scene:
        """A scene shipped with the package, by name: ``"paper"`` (:meth:`paper`) or
        ``"detour"`` (the paper's cell with a post on the straight path and the pendulum
        across the arm's way on fast moves: ``docs/detour-scene.md``).

        Raises
        ------
        SceneError
            ``name`` is not one of ``adept_traj.scene.SHIPPED_SCENES``.
        """
        from adept_traj.scene.scene_file import read_shipped_scene

        return read_shipped_scene(name)

    @classmethod
    def from_file(cls, path: str | os.PathLike[str]) -> Scene:
        """Read a TOML scene file (format: ``docs/scene-files.md``).

        Raises
        ------
        SceneFileNotFoundError
            the file does not exist.
        SceneError
            the file cannot be read, is not valid TOML (the message gives the line and column),
            or does not describe a valid scene; the message names the file, the entry (obstacle
            or pendulum, by name or 1-based position) and the field.
        """
        from adept_traj.scene.scene_file import read_scene_file

        return read_scene_file(path)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "<dict>") -> Scene:
        """Build a scene from the parsed content of a scene file.

        Parameters
        ----------
        data: mapping with the scene-file schema (what ``tomllib`` returns).
        source: name used in error messages (a file name).

        Raises
        ------
        ResourceLimitError
            more than :data:`MAX_OBSTACLES` obstacles (checked before any is built).
        SceneError
            ``data`` does not describe a valid scene.
        """
        from adept_traj.scene.scene_file import scene_from_dict

        return scene_from_dict(data, source)  # it checks the count first

    def to_dict(self) -> dict[str, Any]:
        """The scene as a scene-file mapping (plain str, float and list values).

        ``Scene.from_dict(scene.to_dict())`` describes the same scene (see
        :func:`adept_traj.scene.scene_file.scene_to_dict`).

        Raises
        ------
        SceneError
            an obstacle cannot be expressed in a scene file.
        """
        from adept_traj.scene.scene_file import scene_to_dict

        return scene_to_dict(self)

    def to_toml(self) -> str:
        """The scene as the text of a TOML scene file."""
        from adept_traj.scene.scene_file import scene_to_toml

        return scene_to_toml(self)

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the scene to a TOML scene file (UTF-8, atomically); OSError if it cannot be
        written."""
        from adept_traj.scene.scene_file import write_scene_file

        write_scene_file(self, path)
