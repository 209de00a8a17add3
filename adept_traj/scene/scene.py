"""Scenes: obstacles with a shape and a motion law, the robot base pose, an optional task.

A :class:`Scene` is a frozen value object. It is built in Python, or read from a TOML scene
file (:meth:`Scene.from_file`, format in ``docs/scene-files.md``), or taken from the paper's
numerical application (:meth:`Scene.paper`). Everything is in the *world* frame, SI units:
obstacle poses are world poses, ``robot_base`` is the pose of the robot's base frame in the
world.

Every problem found in a scene file or dictionary raises :class:`~adept_traj.errors.SceneError`
whose message names the source (file), the entry (obstacle or pendulum, by name or by its
1-based position in the file) and the field, with what was expected and what was found.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.errors import (
    AdeptTrajError,
    InputShapeError,
    InvalidInputError,
    SceneError,
    SceneFileNotFoundError,
)
from adept_traj.files import parse_toml, read_toml
from adept_traj.scene.motion_laws import FixedPose, MotionLaw, PendulumMotion
from adept_traj.scene.shapes import Box, Capsule, Cylinder, Shape, Sphere, _readonly, _ValueObject
from adept_traj.transforms import as_rigid_transform, transform_from_xyz_rpy, xyz_rpy_from_transform
from adept_traj.validation import as_finite_array

__all__ = ["Obstacle", "Scene", "SceneFileNotFoundError", "pendulum_obstacles"]

#: Suffixes of the two obstacles a pendulum yields.
_ROD_SUFFIX = ".rod"
_BOB_SUFFIX = ".bob"


def _identity() -> np.ndarray:
    return np.eye(4)


def _fixed_identity() -> FixedPose:
    return FixedPose(np.eye(4))


@dataclass(frozen=True, eq=False)
class Obstacle(_ValueObject):
    """A solid obstacle: a shape placed by a motion law.

    The world pose of the shape's frame at time t is ``motion.pose(t) @ offset``.

    Attributes:
        name: unique (within a scene), non-empty name.
        shape: the solid, centred on its own frame (see :mod:`adept_traj.shapes`).
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
        if not isinstance(self.shape, Shape):
            raise InvalidInputError(
                f"obstacle {self.name!r}: shape must be an adept_traj.shapes.Shape; "
                f"got {type(self.shape).__name__}"
            )
        if not isinstance(self.motion, MotionLaw):
            raise InvalidInputError(
                f"obstacle {self.name!r}: motion must be an adept_traj.motion.MotionLaw; "
                f"got {type(self.motion).__name__}"
            )
        offset = as_rigid_transform(self.offset, "offset")
        object.__setattr__(self, "offset", _readonly(offset))

    @property
    def is_moving(self) -> bool:
        """True when the obstacle's pose depends on time."""
        return not self.motion.is_fixed

    def pose(self, t: Any) -> np.ndarray:
        """World pose of the shape's frame.

        Args:
            t: times [s], any shape (...); e.g. (n,).

        Returns:
            (..., 4, 4) homogeneous transforms (a new array).
        """
        return self.motion.pose(t) @ self.offset

    def swept_ball(self) -> tuple[np.ndarray, float]:
        """A fixed ball containing the obstacle at every time (for a broad phase).

        Returns:
            ``(centre, radius)``: (3,) world centre [m] and radius [m]. For a fixed obstacle
            it is the shape's bounding ball; for a moving one, a ball containing that
            bounding ball over the whole motion (see :meth:`MotionLaw.swept_ball`).
        """
        return self.motion.swept_ball(self.offset[:3, 3], self.shape.bounding_radius)


def pendulum_obstacles(
    name: str, motion: PendulumMotion, *, bob_radius: float, rod_radius: float = 0.01
) -> tuple[Obstacle, Obstacle]:
    """The two obstacles of a pendulum, sharing its motion law: its rod and its bob.

    Args:
        name: the pendulum's name; the obstacles are named ``name + ".rod"`` and
            ``name + ".bob"``.
        motion: the pendulum's motion law.
        bob_radius: radius of the spherical bob [m].
        rod_radius: radius of the cylindrical rod [m] (default 0.01).

    Returns:
        ``(rod, bob)``. The rod is a :class:`Cylinder` of length l from the pivot to the bob
        centre: its centre at the middle of pivot–bob, its z axis along the rod. The bob is a
        :class:`Sphere` centred at :meth:`PendulumMotion.bob_position`.
    """
    if not isinstance(motion, PendulumMotion):
        raise InvalidInputError(f"motion must be a PendulumMotion; got {type(motion).__name__}")
    if not isinstance(name, str) or not name:
        raise InvalidInputError(f"name must be a non-empty string; got {name!r}")
    length = motion.length
    rod = Obstacle(
        name + _ROD_SUFFIX,
        Cylinder(rod_radius, length),
        motion,
        transform_from_xyz_rpy((0.0, 0.0, -0.5 * length)),
    )
    bob = Obstacle(
        name + _BOB_SUFFIX,
        Sphere(bob_radius),
        motion,
        transform_from_xyz_rpy((0.0, 0.0, -length)),
    )
    return rod, bob


def _as_joint_vector(value: Any, name: str) -> np.ndarray:
    arr = as_finite_array(value, name)
    if arr.ndim != 1 or arr.size == 0:
        raise InputShapeError(
            f"{name} must be a non-empty joint vector of shape (nq,) [rad | m]; "
            f"got shape {arr.shape}"
        )
    return _readonly(arr)


@dataclass(frozen=True, eq=False)
class Scene(_ValueObject):
    """Obstacles, robot base pose and an optional default task, in the world frame.

    Attributes:
        obstacles: the obstacles (tuple; names unique).
        robot_base: (4, 4) rigid pose of the robot base frame in the world [m]; default
            identity.
        start: optional (nq,) default start configuration, in the robot's joint order
            [rad for revolute, m for prismatic joints]; given together with ``goal``.
        goal: optional (nq,) default goal configuration, same length as ``start``.
        name: the scene's name.

    Array-like inputs are copied into new read-only arrays.
    """

    obstacles: tuple[Obstacle, ...] = ()
    robot_base: np.ndarray = field(default_factory=_identity)
    start: np.ndarray | None = None
    goal: np.ndarray | None = None
    name: str = "scene"

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise InvalidInputError(f"name must be a non-empty string; got {self.name!r}")
        if isinstance(self.obstacles, (str, bytes)) or not isinstance(self.obstacles, Sequence):
            raise InvalidInputError(
                f"obstacles must be a sequence of Obstacle; got {type(self.obstacles).__name__}"
            )
        obstacles = tuple(self.obstacles)
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
        object.__setattr__(self, "obstacles", obstacles)
        object.__setattr__(self, "robot_base", _readonly(base))
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

        Args:
            t: times [s], any shape (...); e.g. (n,).
            in_base_frame: if True, poses relative to the robot base frame
                (``inv(robot_base) @ world pose``); else world poses.

        Returns:
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
        """(4, 4) inverse of ``robot_base``: maps world coordinates to base coordinates."""
        r = self.robot_base[:3, :3]
        inv = np.eye(4)
        inv[:3, :3] = r.T
        inv[:3, 3] = -r.T @ self.robot_base[:3, 3]
        return inv

    # ------------------------------------------------------------------ construction
    @classmethod
    def paper(cls) -> Scene:
        """The paper's scene: two fixed cubes and the pendulum (``data/scenes/paper.toml``).

        The cubes and the pendulum law are the paper's; the robot base pose and the pivot are
        a reconstruction (the paper does not give them), see ``docs/paper-scenario.md``.
        """
        resource = resources.files("adept_traj.data").joinpath("scenes", "paper.toml")
        try:
            raw = resource.read_bytes()
        except OSError as exc:
            raise SceneError(f"adept_traj/data/scenes/paper.toml: cannot read: {exc}") from None
        return _from_toml_bytes(raw, "adept_traj/data/scenes/paper.toml", "paper")

    @classmethod
    def from_file(cls, path: str | os.PathLike[str]) -> Scene:
        """Read a TOML scene file (format: ``docs/scene-files.md``).

        Raises:
            SceneFileNotFoundError: the file does not exist.
            SceneError: the file cannot be read, is not valid TOML (the message gives the
                line and column), or does not describe a valid scene.
        """
        p = Path(path)
        data = read_toml(p, SceneError, not_found=SceneFileNotFoundError, what="scene file")
        return _parse_scene(data, str(p), p.stem or "scene")

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "<dict>") -> Scene:
        """Build a scene from the parsed content of a scene file.

        Args:
            data: mapping with the scene-file schema (what ``tomllib`` returns).
            source: name used in error messages (a file name).
        """
        return _parse_scene(data, source, "scene")

    def to_dict(self) -> dict[str, Any]:
        """The scene as a scene-file mapping (plain str, float and list values).

        ``Scene.from_dict(scene.to_dict())`` describes the same scene: fixed obstacles become
        ``[[obstacle]]`` entries (``size``/``radius``/``length`` + ``xyz`` + ``rpy``; an
        obstacle's ``offset`` is folded into its pose), pendulums ``[[pendulum]]`` entries.
        Poses are written as xyz + rpy, so rotations round-trip to rounding (~1e-16).

        Raises:
            SceneError: an obstacle cannot be expressed in a scene file: a motion law other
                than FixedPose / PendulumMotion, or a pendulum-moved obstacle that is not one
                of a rod/bob pair made by :func:`pendulum_obstacles`.
        """
        out: dict[str, Any] = {"name": self.name}
        xyz, rpy = xyz_rpy_from_transform(self.robot_base)
        out["robot"] = {"xyz": _floats(xyz), "rpy": _floats(rpy)}
        if self.start is not None and self.goal is not None:
            out["task"] = {"start": _floats(self.start), "goal": _floats(self.goal)}
        obstacles: list[dict[str, Any]] = []
        pendulums: list[dict[str, Any]] = []
        by_name = {ob.name: ob for ob in self.obstacles}
        done: set[str] = set()
        for ob in self.obstacles:
            if ob.name in done:
                continue
            if isinstance(ob.motion, FixedPose):
                obstacles.append(_fixed_obstacle_dict(ob, ob.motion))
                done.add(ob.name)
            elif isinstance(ob.motion, PendulumMotion):
                entry, rod, bob = _pendulum_dict(ob, ob.motion, by_name)
                pendulums.append(entry)
                done.update((rod.name, bob.name))
            else:
                raise SceneError(
                    f"obstacle {ob.name!r}: motion law {type(ob.motion).__name__} cannot be "
                    "written to a scene file"
                )
        if obstacles:
            out["obstacle"] = obstacles
        if pendulums:
            out["pendulum"] = pendulums
        return out

    def to_toml(self) -> str:
        """The scene as the text of a TOML scene file."""
        header = (
            "# adept_traj scene file (format: docs/scene-files.md). World frame, SI units:\n"
            "# lengths [m], angles [rad], times [s], speeds [m/s].\n"
        )
        return header + _dump_toml(self.to_dict())

    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the scene to a TOML scene file (UTF-8); OSError if it cannot be written."""
        Path(path).write_text(self.to_toml(), encoding="utf-8")


# ====================================================================== writing


def _floats(values: Any) -> list[float]:
    return [float(v) + 0.0 for v in np.asarray(values).ravel()]  # + 0.0 turns -0.0 into 0.0


def _shape_fields(shape: Shape) -> dict[str, Any]:
    if isinstance(shape, Box):
        return {"size": _floats(shape.size)}
    if isinstance(shape, Sphere):
        return {"radius": shape.radius}
    if isinstance(shape, (Cylinder, Capsule)):
        return {"radius": shape.radius, "length": shape.length}
    raise SceneError(f"shape {type(shape).__name__} cannot be written to a scene file")


def _fixed_obstacle_dict(ob: Obstacle, motion: FixedPose) -> dict[str, Any]:
    if type(ob.shape) not in (Box, Sphere, Cylinder, Capsule):
        raise SceneError(
            f"obstacle {ob.name!r}: shape {type(ob.shape).__name__} cannot be written to a "
            "scene file"
        )
    xyz, rpy = xyz_rpy_from_transform(motion.transform @ ob.offset)
    return {
        "name": ob.name,
        "shape": ob.shape.kind,
        **_shape_fields(ob.shape),
        "xyz": _floats(xyz),
        "rpy": _floats(rpy),
    }


def _pendulum_dict(
    ob: Obstacle, motion: PendulumMotion, by_name: Mapping[str, Obstacle]
) -> tuple[dict[str, Any], Obstacle, Obstacle]:
    problem = (
        f"obstacle {ob.name!r} moves with a PendulumMotion but is not one of a rod/bob pair "
        "made by pendulum_obstacles(); it cannot be written to a scene file"
    )
    base = None
    for suffix in (_ROD_SUFFIX, _BOB_SUFFIX):
        if ob.name.endswith(suffix) and len(ob.name) > len(suffix):
            base = ob.name[: -len(suffix)]
    if base is None:
        raise SceneError(problem)
    rod = by_name.get(base + _ROD_SUFFIX)
    bob = by_name.get(base + _BOB_SUFFIX)
    if (
        rod is None
        or bob is None
        or not isinstance(rod.shape, Cylinder)
        or not isinstance(bob.shape, Sphere)
    ):
        raise SceneError(problem)
    expected = pendulum_obstacles(
        base, motion, bob_radius=bob.shape.radius, rod_radius=rod.shape.radius
    )
    if expected != (rod, bob):
        raise SceneError(problem)
    entry = {
        "name": base,
        "pivot": _floats(motion.pivot),
        "length": motion.length,
        "v0": motion.v0,
        "omega": motion.omega,
        "g": motion.g,
        "swing_axis": _floats(motion.swing_axis),
        "rod_radius": rod.shape.radius,
        "bob_radius": bob.shape.radius,
    }
    return entry, rod, bob


def _toml_string(s: str) -> str:
    escapes = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f"}
    escapes["\r"] = "\\r"
    out = []
    for ch in s:
        if ch in escapes:
            out.append(escapes[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04X}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _toml_value(v: Any) -> str:
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v))
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise SceneError(f"cannot write value {v!r} to TOML")  # unreachable for to_dict output


def _dump_toml(data: Mapping[str, Any]) -> str:
    """Serialise the two-level mappings :meth:`Scene.to_dict` produces."""
    lines: list[str] = []
    tables: list[tuple[str, Mapping[str, Any]]] = []
    arrays: list[tuple[str, list[Mapping[str, Any]]]] = []
    for key, value in data.items():
        if isinstance(value, Mapping):
            tables.append((key, value))
        elif isinstance(value, list) and value and all(isinstance(x, Mapping) for x in value):
            arrays.append((key, value))
        else:
            lines.append(f"{key} = {_toml_value(value)}")
    for key, table in tables:
        lines += ["", f"[{key}]"] + [f"{k} = {_toml_value(v)}" for k, v in table.items()]
    for key, entries in arrays:
        for entry in entries:
            lines += ["", f"[[{key}]]"] + [f"{k} = {_toml_value(v)}" for k, v in entry.items()]
    return "\n".join(lines) + "\n"


# ====================================================================== reading

_MISSING: Any = object()
_TOP_KEYS = ("name", "robot", "task", "obstacle", "pendulum")
_ROBOT_KEYS = ("xyz", "rpy")
_TASK_KEYS = ("start", "goal")
_SHAPE_KEYS = {
    "box": ("size", "min", "max"),
    "sphere": ("radius",),
    "cylinder": ("radius", "length"),
    "capsule": ("radius", "length"),
}
_OBSTACLE_COMMON = ("name", "shape", "xyz", "rpy")
_PENDULUM_KEYS = (
    "name",
    "pivot",
    "length",
    "v0",
    "omega",
    "g",
    "swing_axis",
    "rod_radius",
    "bob_radius",
)


class _Where:
    """Error context: the source (file) and the entry being read."""

    def __init__(self, source: str, entry: str = "") -> None:
        self.source = source
        self.entry = entry

    def error(self, message: str) -> SceneError:
        where = f"{self.entry}: " if self.entry else ""
        return SceneError(f"{self.source}: {where}{message}")

    def field_error(self, key: str, expected: str, got: Any) -> SceneError:
        return self.error(f"field {key!r} must be {expected}; got {got!r}")


def _is_number(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _check_keys(table: Mapping[str, Any], allowed: Sequence[str], w: _Where) -> None:
    for key in table:
        if key not in allowed:
            raise w.error(
                f"unknown field {key!r}; allowed fields: {', '.join(repr(a) for a in allowed)}"
            )


def _table(value: Any, key: str, w: _Where) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise w.field_error(key, f"a table ([{key}])", value)
    return value


def _number(
    table: Mapping[str, Any],
    key: str,
    w: _Where,
    unit: str,
    *,
    sign: str = "positive",
    default: Any = _MISSING,
) -> float:
    article = {"positive": "a positive", "non-negative": "a non-negative"}.get(sign, "a")
    expected = f"{article} number {unit}"
    if key not in table:
        if default is _MISSING:
            raise w.error(f"missing field {key!r} ({expected})")
        return float(default)
    v = table[key]
    if not _is_number(v) or (sign == "positive" and v <= 0) or (sign == "non-negative" and v < 0):
        raise w.field_error(key, expected, v)
    return float(v)


def _numbers(
    table: Mapping[str, Any],
    key: str,
    w: _Where,
    n: int | None,
    unit: str,
    *,
    positive: bool = False,
    default: Any = _MISSING,
) -> list[float]:
    count = f"{n}" if n is not None else "a non-empty list of"
    kind = "positive numbers" if positive else "numbers"
    expected = f"{count} {kind} {unit}"
    if key not in table:
        if default is _MISSING:
            raise w.error(f"missing field {key!r} ({expected})")
        return list(default)
    v = table[key]
    if (
        not isinstance(v, list)
        or (n is not None and len(v) != n)
        or not v
        or not all(_is_number(x) for x in v)
        or (positive and not all(x > 0 for x in v))
    ):
        raise w.field_error(key, expected, v)
    return [float(x) for x in v]


def _string(
    table: Mapping[str, Any],
    key: str,
    w: _Where,
    default: Any = _MISSING,
    expected: str = "a non-empty string",
) -> str:
    if key not in table:
        if default is _MISSING:
            raise w.error(f"missing field {key!r} ({expected})")
        return str(default)
    v = table[key]
    if not isinstance(v, str) or not v:
        raise w.field_error(key, expected, v)
    return v


def _array_of_tables(data: Mapping[str, Any], key: str, w: _Where) -> list[Mapping[str, Any]]:
    if key not in data:
        return []
    v = data[key]
    if not isinstance(v, list) or not all(isinstance(x, Mapping) for x in v):
        raise w.field_error(key, f"an array of tables ([[{key}]] entries)", v)
    return v


def _entry_where(source: str, kind: str, index: int, entry: Mapping[str, Any]) -> _Where:
    name = entry.get("name")
    if isinstance(name, str) and name:
        return _Where(source, f"{kind} {name!r}")
    return _Where(source, f"{kind} #{index + 1} (in file order)")


def _build(w: _Where, make: Any, *args: Any, **kwargs: Any) -> Any:
    """Call a constructor, turning its input errors into SceneErrors with context."""
    try:
        return make(*args, **kwargs)
    except AdeptTrajError as exc:
        raise w.error(str(exc)) from None


def _parse_obstacle(entry: Mapping[str, Any], w: _Where) -> Obstacle:
    name = _string(entry, "name", w)
    kinds = f"one of {', '.join(map(repr, _SHAPE_KEYS))}"
    kind = _string(entry, "shape", w, expected=kinds)
    if kind not in _SHAPE_KEYS:
        raise w.field_error("shape", kinds, kind)
    _check_keys(entry, _OBSTACLE_COMMON + _SHAPE_KEYS[kind], w)
    shape: Shape
    if kind == "box" and ("min" in entry or "max" in entry):
        for other in ("size", "xyz", "rpy"):
            if other in entry:
                raise w.error(
                    f"field {other!r} cannot be combined with 'min'/'max' (a box given by its "
                    "corners is axis-aligned, centred at (min + max) / 2)"
                )
        lo = _numbers(entry, "min", w, 3, "[m] (the lower corner)")
        hi = _numbers(entry, "max", w, 3, "[m] (the upper corner)")
        if not all(h > low for h, low in zip(hi, lo, strict=True)):
            raise w.field_error("max", f"greater than 'min' = {lo} in every axis [m]", hi)
        size = [h - low for h, low in zip(hi, lo, strict=True)]
        xyz = [0.5 * (h + low) for h, low in zip(hi, lo, strict=True)]
        rpy = [0.0, 0.0, 0.0]
        shape = _build(w, Box, size)
    else:
        if kind == "box":
            shape = _build(w, Box, _numbers(entry, "size", w, 3, "[m]", positive=True))
        elif kind == "sphere":
            shape = _build(w, Sphere, _number(entry, "radius", w, "[m]"))
        else:
            cls = Cylinder if kind == "cylinder" else Capsule
            radius = _number(entry, "radius", w, "[m]")
            length = _number(entry, "length", w, "[m]")
            shape = _build(w, cls, radius, length)
        xyz = _numbers(entry, "xyz", w, 3, "[m] (the centre)")
        rpy = _numbers(entry, "rpy", w, 3, "[rad]", default=(0.0, 0.0, 0.0))
    motion = _build(w, FixedPose, transform_from_xyz_rpy(xyz, rpy))
    return _build(w, Obstacle, name, shape, motion)


def _parse_pendulum(entry: Mapping[str, Any], w: _Where) -> tuple[Obstacle, Obstacle]:
    _check_keys(entry, _PENDULUM_KEYS, w)
    name = _string(entry, "name", w)
    motion = _build(
        w,
        PendulumMotion,
        pivot=_numbers(entry, "pivot", w, 3, "[m]"),
        length=_number(entry, "length", w, "[m]"),
        v0=_number(entry, "v0", w, "[m/s]", sign="non-negative"),
        omega=_number(entry, "omega", w, "[rad/s]"),
        g=_number(entry, "g", w, "[m/s²]", default=9.81),
        swing_axis=_numbers(entry, "swing_axis", w, 3, "(horizontal)", default=(1.0, 0.0, 0.0)),
    )
    return _build(
        w,
        pendulum_obstacles,
        name,
        motion,
        bob_radius=_number(entry, "bob_radius", w, "[m]"),
        rod_radius=_number(entry, "rod_radius", w, "[m]", default=0.01),
    )


def _parse_scene(data: Any, source: str, default_name: str) -> Scene:
    top = _Where(source)
    if not isinstance(data, Mapping):
        raise top.error(f"scene data must be a table (mapping); got {type(data).__name__}")
    _check_keys(data, _TOP_KEYS, top)
    name = _string(data, "name", top, default=default_name)

    robot = _Where(source, "[robot]")
    base = np.eye(4)
    if "robot" in data:
        table = _table(data["robot"], "robot", top)
        _check_keys(table, _ROBOT_KEYS, robot)
        xyz = _numbers(table, "xyz", robot, 3, "[m]", default=(0.0, 0.0, 0.0))
        rpy = _numbers(table, "rpy", robot, 3, "[rad]", default=(0.0, 0.0, 0.0))
        base = transform_from_xyz_rpy(xyz, rpy)

    start = goal = None
    if "task" in data:
        task = _Where(source, "[task]")
        table = _table(data["task"], "task", top)
        _check_keys(table, _TASK_KEYS, task)
        start = _numbers(table, "start", task, None, "[rad | m]")
        goal = _numbers(table, "goal", task, None, "[rad | m]")
        if len(start) != len(goal):
            raise task.error(
                f"fields 'start' and 'goal' must have the same length; "
                f"got {len(start)} and {len(goal)}"
            )

    obstacles: list[Obstacle] = []
    for i, entry in enumerate(_array_of_tables(data, "obstacle", top)):
        obstacles.append(_parse_obstacle(entry, _entry_where(source, "obstacle", i, entry)))
    for i, entry in enumerate(_array_of_tables(data, "pendulum", top)):
        obstacles.extend(_parse_pendulum(entry, _entry_where(source, "pendulum", i, entry)))
    return _build(
        top, Scene, obstacles=tuple(obstacles), robot_base=base, start=start, goal=goal, name=name
    )


def _from_toml_bytes(raw: bytes, source: str, default_name: str) -> Scene:
    return _parse_scene(parse_toml(raw, source, SceneError), source, default_name)
