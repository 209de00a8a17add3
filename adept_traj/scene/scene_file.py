"""Scene files: reading and writing the TOML form of a :class:`~adept_traj.scene.Scene`.

The format is described in ``docs/scene-files.md``; the paper's scene ships as
``adept_traj/data/scenes/paper.toml``. Reading checks every field and raises
:class:`~adept_traj.errors.SceneError` whose message names the source (file), the entry
(obstacle or pendulum, by name or by its 1-based position in the file) and the field, with
what was expected and what was found. Writing produces the canonical form (boxes as
``size`` + ``xyz`` + ``rpy``, every optional field written out) through ``tomli-w``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import tomli_w

from adept_traj.errors import SceneError, SceneFileNotFoundError
from adept_traj.files import parse_toml, read_toml, write_text_atomic
from adept_traj.robot import ROBOT_FILE_KEYS, RobotSource
from adept_traj.scene.machine_entries import (
    MACHINE_LAWS,
    file_shape_fields,
    motion_table,
    parse_cloud_entry,
    parse_mesh_entry,
    parse_motion_entry,
    parse_robot_motion_entry,
    robot_motion_table,
)
from adept_traj.scene.motion_laws import FixedPose, PendulumMotion
from adept_traj.scene.robot_motion import RobotSolidMotion
from adept_traj.scene.scene import (
    BOB_SUFFIX,
    ROD_SUFFIX,
    Obstacle,
    Scene,
    check_obstacle_count,
    pendulum_obstacles,
)
from adept_traj.scene.shapes import Box, Capsule, Cylinder, Shape, Sphere
from adept_traj.schema import Node, error_factory
from adept_traj.transforms import transform_from_xyz_rpy, xyz_rpy_from_transform

__all__ = [
    "SHIPPED_SCENES",
    "read_paper_scene",
    "read_robot_files",
    "read_scene_file",
    "read_shipped_scene",
    "scene_from_dict",
    "scene_to_dict",
    "scene_to_toml",
    "write_scene_file",
]

#: The scenes shipped in ``adept_traj/data/scenes/``: the paper's
#: (``docs/paper-scenario.md``), a harder one where the obstacles bind the fastest moves
#: (``docs/detour-scene.md``) and a work cell of CAD meshes and moving machines
#: (``docs/example-cell.md``).
SHIPPED_SCENES = ("paper", "detour", "cell")

#: First lines of a written scene file (TOML comments; tomli-w writes none).
_HEADER = (
    "# adept_traj scene file (format: docs/scene-files.md). World frame, SI units:\n"
    "# lengths [m], angles [rad], times [s], speeds [m/s].\n"
)


# ====================================================================== public functions


def read_scene_file(path: str | os.PathLike[str]) -> Scene:
    """Read a TOML scene file (what :meth:`Scene.from_file` does).

    Raises
    ------
    SceneFileNotFoundError
        the file does not exist.
    SceneError
        the file cannot be read, is not valid TOML (the message gives the line
        and column), or does not describe a valid scene.
    """
    p = Path(path)
    data = read_toml(p, SceneError, not_found=SceneFileNotFoundError, what="scene file")
    return _parse_scene(data, str(p), p.stem or "scene", p.parent)


def read_robot_files(path: str | os.PathLike[str]) -> RobotSource:
    """The robot a scene file's ``[robot]`` table names
    (:meth:`~adept_traj.robot.RobotSource.from_table`: file and folder paths relative to
    the scene file's folder; ``urdf`` may be a ``package://`` URI; no ``urdf``: the shipped
    AdeptOne XL). The scene itself does not keep them (a :class:`~adept_traj.scene.Scene`
    is obstacles and the base pose); the command line loads that robot.

    Raises the errors of :func:`read_scene_file`.
    """
    p = Path(path)
    data = read_toml(p, SceneError, not_found=SceneFileNotFoundError, what="scene file")
    _parse_scene(data, str(p), p.stem or "scene", p.parent)  # the whole file is checked
    return RobotSource.from_table(Node(data, str(p), _ERROR)["robot"], p.parent)


def read_shipped_scene(name: str) -> Scene:
    """The shipped scene ``name`` (one of :data:`SHIPPED_SCENES`), read from
    ``adept_traj/data/scenes/<name>.toml``."""
    if name not in SHIPPED_SCENES:
        raise SceneError(f"shipped scene must be one of {', '.join(SHIPPED_SCENES)}; got {name!r}")
    source = f"adept_traj/data/scenes/{name}.toml"
    try:
        raw = resources.files("adept_traj.data").joinpath("scenes", f"{name}.toml").read_bytes()
    except OSError as exc:
        raise SceneError(f"{source}: cannot read: {exc}") from None
    folder = Path(str(resources.files("adept_traj.data").joinpath("scenes")))
    return _parse_scene(parse_toml(raw, source, SceneError), source, name, folder)


def read_paper_scene() -> Scene:
    """The paper's scene, read from the shipped ``adept_traj/data/scenes/paper.toml``."""
    return read_shipped_scene("paper")


def _count_entries(data: Mapping[str, Any]) -> int:
    """Obstacles a scene-file mapping describes: ``[[obstacle]]`` entries plus two per
    ``[[pendulum]]`` (non-list values count 0: the reader reports them)."""
    count = 0
    for key, per_entry in (("obstacle", 1), ("pendulum", 2)):
        entries = data.get(key) if isinstance(data, Mapping) else None
        if isinstance(entries, list):
            count += per_entry * len(entries)
    return count


def scene_from_dict(
    data: Mapping[str, Any], source: str = "<dict>", folder: str | os.PathLike[str] = "."
) -> Scene:
    """A scene from the parsed content of a scene file (what ``tomllib`` returns); ``source``
    names it in error messages; relative mesh and motion file paths are taken from
    ``folder`` (default: the working directory). More than
    :data:`~adept_traj.scene.MAX_OBSTACLES` obstacles are refused before any is built."""
    check_obstacle_count(_count_entries(data), source)
    return _parse_scene(data, source, "scene", Path(folder))


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """The scene as a scene-file mapping (plain str, float and list values).

    ``scene_from_dict(scene_to_dict(scene))`` describes the same scene: fixed obstacles
    become ``[[obstacle]]`` entries (``size``/``radius``/``length`` + ``xyz`` + ``rpy``; an
    obstacle's ``offset`` is folded into its pose), pendulums ``[[pendulum]]`` entries.
    Poses are written as xyz [m] + rpy [rad], so rotations round-trip to rounding (~1e-16).

    Raises
    ------
    SceneError
        an obstacle cannot be expressed in a scene file: a motion law other than
        FixedPose / PendulumMotion, or a pendulum-moved obstacle that is not one of a
        rod/bob pair made by :func:`~adept_traj.scene.pendulum_obstacles`.
    """
    out: dict[str, Any] = {"name": scene.name}
    xyz, rpy = xyz_rpy_from_transform(scene.robot_base)
    out["robot"] = {"xyz": _floats(xyz), "rpy": _floats(rpy)}
    if scene.start is not None and scene.goal is not None:
        out["task"] = {"start": _floats(scene.start), "goal": _floats(scene.goal)}
    if scene.allowed_contacts:
        out["allowed_contacts"] = [list(pair) for pair in scene.allowed_contacts]
    obstacles: list[dict[str, Any]] = []
    pendulums: list[dict[str, Any]] = []
    robots: dict[str, dict[str, Any]] = {}
    by_name = {ob.name: ob for ob in scene.obstacles}
    done: set[str] = set()
    for ob in scene.obstacles:
        if ob.name in done:
            continue
        if isinstance(ob.motion, FixedPose):
            obstacles.append(_fixed_obstacle_dict(ob, ob.motion))
            done.add(ob.name)
        elif isinstance(ob.motion, RobotSolidMotion):
            if ob.motion.group not in robots:
                robots[ob.motion.group] = robot_motion_table(ob.motion)
            done.add(ob.name)
        elif isinstance(ob.motion, MACHINE_LAWS):
            obstacles.append(_moving_obstacle_dict(ob))
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
    if robots:
        out["robot_motion"] = list(robots.values())
    return out


def scene_to_toml(scene: Scene) -> str:
    """The text of the TOML scene file of ``scene`` (a comment header, then
    :func:`scene_to_dict` written by ``tomli_w``)."""
    return _HEADER + tomli_w.dumps(scene_to_dict(scene))


def write_scene_file(scene: Scene, path: str | os.PathLike[str]) -> Path:
    """Write ``scene`` to the TOML scene file ``path`` (UTF-8; written to a temporary file
    and renamed, so a reader never sees half a file); return the path. OSError if it
    cannot be written."""
    return write_text_atomic(Path(path), scene_to_toml(scene))


# ====================================================================== writing


def _floats(values: Any) -> list[float]:
    return [float(v) + 0.0 for v in np.asarray(values).ravel()]  # + 0.0 turns -0.0 into 0.0


def _moving_obstacle_dict(ob: Obstacle) -> dict[str, Any]:
    entry = _fixed_obstacle_dict(ob, FixedPose(np.eye(4)))  # xyz, rpy: the offset
    entry["motion"] = motion_table(ob.motion)
    return entry


def _fixed_obstacle_dict(ob: Obstacle, motion: FixedPose) -> dict[str, Any]:
    shape = ob.shape
    file_fields = file_shape_fields(ob)
    if file_fields is not None:
        fields: dict[str, Any] = file_fields
    elif type(shape) is Box:
        fields = {"size": _floats(shape.size)}
    elif type(shape) is Sphere:
        fields = {"radius": shape.radius}
    elif type(shape) in (Cylinder, Capsule):
        fields = {"radius": shape.radius, "length": shape.length}  # type: ignore[attr-defined]
    else:
        raise SceneError(
            f"obstacle {ob.name!r}: shape {type(shape).__name__} cannot be written to a scene file"
        )
    xyz, rpy = xyz_rpy_from_transform(motion.transform @ ob.offset)
    return {
        "name": ob.name,
        "shape": shape.kind,
        **fields,
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
    for suffix in (ROD_SUFFIX, BOB_SUFFIX):
        if ob.name.endswith(suffix) and len(ob.name) > len(suffix):
            base = ob.name[: -len(suffix)]
    if base is None:
        raise SceneError(problem)
    rod = by_name.get(base + ROD_SUFFIX)
    bob = by_name.get(base + BOB_SUFFIX)
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


# ====================================================================== reading

#: Errors of a scene file: SceneError naming the source (file) and the field path.
_ERROR = error_factory(SceneError)
_TOP_KEYS = ("name", "robot", "task", "obstacle", "pendulum", "robot_motion", "allowed_contacts")
_ROBOT_KEYS = ("xyz", "rpy", *ROBOT_FILE_KEYS)
_TASK_KEYS = ("start", "goal")
_SHAPE_KEYS = {
    "box": ("size", "min", "max"),
    "sphere": ("radius",),
    "cylinder": ("radius", "length"),
    "capsule": ("radius", "length"),
    "mesh": ("file", "scale"),
    "cloud": ("file", "resolution"),
}
_OBSTACLE_COMMON = ("name", "shape", "xyz", "rpy", "motion")
_PENDULUM_KEYS = (
    "name", "pivot", "length", "v0", "omega", "g", "swing_axis", "rod_radius", "bob_radius",
)  # fmt: skip


def _parse_obstacle(name: str, node: Node, folder: Path) -> Obstacle:
    kind = node["shape"].string(choices=tuple(_SHAPE_KEYS))
    node.check_keys(_OBSTACLE_COMMON + _SHAPE_KEYS[kind])
    positive = {"minimum": 0.0, "strict": True}
    shape: Shape
    if kind in ("mesh", "cloud"):
        shape = (parse_mesh_entry if kind == "mesh" else parse_cloud_entry)(node, folder)
        xyz = node["xyz"].array((3,), "[m] (the mesh frame's origin)", default=np.zeros(3))
        rpy = node["rpy"].array((3,), "[rad]", default=np.zeros(3))
    elif kind == "box" and (node["min"].present or node["max"].present):
        for other in ("size", "xyz", "rpy"):
            if node[other].present:
                raise node[other].error(
                    "cannot be combined with 'min'/'max' (a box given by its corners is "
                    "axis-aligned, centred at (min + max) / 2)"
                )
        lo = node["min"].array((3,), "[m] (the lower corner)")
        hi = node["max"].array((3,), "[m] (the upper corner)")
        if not (hi > lo).all():
            raise node["max"].error(
                f"must be greater than 'min' = {lo.tolist()} in every axis [m]; got {hi.tolist()}"
            )
        xyz, rpy = 0.5 * (hi + lo), np.zeros(3)
        shape = node.build(Box, hi - lo)
    else:
        if kind == "box":
            shape = node.build(Box, node["size"].array((3,), "[m]", **positive))
        elif kind == "sphere":
            shape = node.build(Sphere, node["radius"].number("[m]", **positive))
        else:
            cls = Cylinder if kind == "cylinder" else Capsule
            radius = node["radius"].number("[m]", **positive)
            shape = node.build(cls, radius, node["length"].number("[m]", **positive))
        xyz = node["xyz"].array((3,), "[m] (the centre)")
        rpy = node["rpy"].array((3,), "[rad]", default=np.zeros(3))
    pose = transform_from_xyz_rpy(xyz, rpy)
    if node["motion"].present:  # xyz, rpy: the pose in the moving frame
        motion = parse_motion_entry(node["motion"], folder)
        return node.build(Obstacle, name, shape, motion, pose)
    return node.build(Obstacle, name, shape, node.build(FixedPose, pose))


def _parse_pendulum(name: str, node: Node) -> tuple[Obstacle, Obstacle]:
    node.check_keys(_PENDULUM_KEYS)
    positive = {"minimum": 0.0, "strict": True}
    motion = node.build(
        PendulumMotion,
        pivot=node["pivot"].array((3,), "[m]"),
        length=node["length"].number("[m]", **positive),
        v0=node["v0"].number("[m/s]", minimum=0.0),
        omega=node["omega"].number("[rad/s]", **positive),
        g=node["g"].number("[m/s²]", **positive, default=9.81),
        swing_axis=node["swing_axis"].array((3,), "[-] (horizontal)", default=np.eye(3)[0]),
    )
    return node.build(
        pendulum_obstacles,
        name,
        motion,
        bob_radius=node["bob_radius"].number("[m]", **positive),
        rod_radius=node["rod_radius"].number("[m]", **positive, default=0.01),
    )


def _parse_scene(data: Any, source: str, default_name: str, folder: Path) -> Scene:
    top = Node(data, source, _ERROR).check_keys(_TOP_KEYS)
    name = top["name"].string(nonempty=True, default=default_name)

    base = np.eye(4)
    robot = top["robot"]
    if robot.present:
        robot.check_keys(_ROBOT_KEYS)
        xyz = robot["xyz"].array((3,), "[m]", default=np.zeros(3))
        base = transform_from_xyz_rpy(xyz, robot["rpy"].array((3,), "[rad]", default=np.zeros(3)))

    start = goal = None
    task = top["task"]
    if task.present:
        task.check_keys(_TASK_KEYS)
        start = task["start"].array((None,), "[rad | m]")
        goal = task["goal"].array((None,), "[rad | m]")
        if start.size != goal.size:
            raise task.error(
                f"'start' and 'goal' must have the same length; got {start.size} and {goal.size}"
            )

    obstacles: list[Obstacle] = []
    for entry_name, node in top["obstacle"].named_tables():
        obstacles.append(_parse_obstacle(entry_name, node, folder))
    for entry_name, node in top["pendulum"].named_tables():
        obstacles.extend(_parse_pendulum(entry_name, node))
    for entry_name, node in top["robot_motion"].named_tables():
        obstacles.extend(parse_robot_motion_entry(entry_name, node, folder))
    allowed = tuple(
        tuple(n.strings(min_items=2)) for n in top["allowed_contacts"].items(default=[])
    )
    if any(len(pair) != 2 for pair in allowed):
        raise top["allowed_contacts"].error("must hold [link, obstacle] pairs of names")
    return top.build(
        Scene,
        obstacles=tuple(obstacles),
        robot_base=base,
        start=start,
        goal=goal,
        name=name,
        allowed_contacts=allowed,
    )
