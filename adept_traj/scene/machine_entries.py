"""The scene-file entries of mesh obstacles and of machines' motion laws (a part of
:mod:`adept_traj.scene.scene_file`; format in ``docs/scene-files.md``): reading the
``mesh`` shape and the ``motion`` table of an ``[[obstacle]]``, writing the table back."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.errors import MeshFileError, MotionFileError, ResourceLimitError, SceneError
from adept_traj.robot import ROBOT_FILE_KEYS, RobotSource
from adept_traj.scene.machine_motions import LinearMotion, RotationMotion
from adept_traj.scene.meshes import Mesh
from adept_traj.scene.motion_laws import MotionLaw
from adept_traj.scene.point_clouds import PointCloud
from adept_traj.scene.recorded_motion import RecordedMotion
from adept_traj.scene.robot_motion import JointTrajectory, RobotSolidMotion, robot_obstacles
from adept_traj.scene.scene import Obstacle
from adept_traj.schema import Node
from adept_traj.transforms import transform_from_xyz_rpy, xyz_rpy_from_transform

__all__ = [
    "MACHINE_LAWS",
    "MOTION_KEYS",
    "file_shape_fields",
    "motion_table",
    "parse_cloud_entry",
    "parse_mesh_entry",
    "parse_motion_entry",
    "parse_robot_motion_entry",
    "robot_motion_table",
]

#: The motion laws a scene file writes as an obstacle's ``motion`` table.
MACHINE_LAWS = (LinearMotion, RotationMotion, RecordedMotion)
#: The keys of each kind of ``motion`` table.
MOTION_KEYS = {
    "linear": ("kind", "velocity", "wrap", "phase"),
    "rotation": ("kind", "axis", "point", "omega", "angle"),
    "recorded": ("kind", "file", "periodic"),
}


def _floats(values: Any) -> list[float]:
    return [float(v) + 0.0 for v in np.asarray(values).ravel()]  # + 0.0 turns -0.0 into 0.0


def motion_table(motion: Any) -> dict[str, Any]:
    """The ``motion`` table of a machine's motion law."""
    if isinstance(motion, LinearMotion):
        out: dict[str, Any] = {"kind": "linear", "velocity": _floats(motion.velocity)}
        if math.isfinite(motion.wrap):
            out["wrap"] = motion.wrap
        return {**out, "phase": motion.phase}
    if isinstance(motion, RotationMotion):
        return {
            "kind": "rotation",
            "axis": _floats(motion.axis),
            "point": _floats(motion.point),
            "omega": motion.omega,
            "angle": motion.angle,
        }
    if not motion.source:
        raise SceneError("a recorded motion built from arrays (no file) cannot be written")
    return {"kind": "recorded", "file": motion.source, "periodic": motion.periodic}


def parse_mesh_entry(node: Node, folder: Path) -> Mesh:
    """The ``mesh`` shape of an obstacle entry: its ``file`` (relative to ``folder``) read
    with its ``scale``; a missing or unreadable file is a MeshFileError naming both files."""
    file = node["file"].string(nonempty=True)
    scale_node = node["scale"]
    if scale_node.present and isinstance(scale_node.value, list):
        scale: Any = scale_node.array((3,), "[-]", minimum=0.0, strict=True)
    else:
        scale = scale_node.number("[-]", minimum=0.0, strict=True, default=1.0)
    path = Path(file) if Path(file).is_absolute() else folder / file
    try:
        return Mesh.from_file(path, scale)
    except MeshFileError as exc:
        raise MeshFileError(str(node["file"].error(str(exc)))) from None


def parse_motion_entry(node: Node, folder: Path) -> MotionLaw:
    """The ``motion`` table of an obstacle entry: a conveyor's, a turntable's or a recorded
    trajectory's law (``docs/scene-files.md``)."""
    kind = node["kind"].string(choices=tuple(MOTION_KEYS))
    node.check_keys(MOTION_KEYS[kind])
    if kind == "linear":
        return node.build(
            LinearMotion,
            node["velocity"].array((3,), "[m/s]"),
            node["wrap"].number("[m]", minimum=0.0, strict=True, default=math.inf),
            node["phase"].number("[m]", default=0.0),
        )
    if kind == "rotation":
        return node.build(
            RotationMotion,
            node["axis"].array((3,), "[-]"),
            node["point"].array((3,), "[m]", default=np.zeros(3)),
            node["omega"].number("[rad/s]"),
            node["angle"].number("[rad]", default=0.0),
        )
    file = node["file"].string(nonempty=True)
    periodic = node["periodic"].boolean() if node["periodic"].present else False
    path = Path(file) if Path(file).is_absolute() else folder / file
    try:
        return RecordedMotion.from_csv(path, periodic=periodic)
    except MotionFileError as exc:
        raise MotionFileError(str(node["file"].error(str(exc)))) from None


def parse_cloud_entry(node: Node, folder: Path) -> PointCloud:
    """The ``cloud`` shape of an obstacle entry: its ``file`` (relative to ``folder``) at
    the octree ``resolution`` [m]; a missing, unreadable or too large file is an error
    naming both files."""
    file = node["file"].string(nonempty=True)
    resolution = node["resolution"].number("[m]", minimum=0.0, strict=True)
    path = Path(file) if Path(file).is_absolute() else folder / file
    try:
        return PointCloud.from_file(path, resolution)
    except MeshFileError as exc:
        raise MeshFileError(str(node["file"].error(str(exc)))) from None
    except ResourceLimitError as exc:
        raise ResourceLimitError(str(node["file"].error(str(exc)))) from None


def file_shape_fields(ob: Any) -> dict[str, Any] | None:
    """The shape fields of an obstacle whose shape is read from a file (a mesh's ``file``
    and ``scale``, a point cloud's ``file`` and ``resolution``), else None."""
    shape = ob.shape
    if not isinstance(shape, (Mesh, PointCloud)):
        return None
    if not shape.source:
        raise SceneError(
            f"obstacle {ob.name!r}: a {shape.kind} built from arrays (no file) cannot be "
            "written to a scene file"
        )
    if isinstance(shape, Mesh):
        return {"file": shape.source, "scale": _floats(shape.scale)}
    return {"file": shape.source, "resolution": shape.resolution}


def parse_robot_motion_entry(name: str, node: Node, folder: Path) -> tuple[Obstacle, ...]:
    """A ``[[robot_motion]]`` entry: another robot (its files as in ``[robot]``; default
    the AdeptOne XL) at ``xyz``/``rpy`` following the joint ``trajectory`` CSV (relative
    to ``folder``): its collision solids as moving obstacles ``<name>.<solid>``."""
    node.check_keys(("name", "xyz", "rpy", "trajectory", *ROBOT_FILE_KEYS))
    base = transform_from_xyz_rpy(
        node["xyz"].array((3,), "[m]", default=np.zeros(3)),
        node["rpy"].array((3,), "[rad]", default=np.zeros(3)),
    )
    file = node["trajectory"].string(nonempty=True)
    path = Path(file) if Path(file).is_absolute() else folder / file
    try:
        trajectory = JointTrajectory.from_csv(path)
    except MotionFileError as exc:
        raise MotionFileError(str(node["trajectory"].error(str(exc)))) from None
    source = RobotSource.from_table(node, folder)
    return node.build(robot_obstacles, name, source, trajectory, base)


def robot_motion_table(law: RobotSolidMotion) -> dict[str, Any]:
    """The ``[[robot_motion]]`` table of the robot whose solid ``law`` moves."""
    if not law.trajectory.source:
        raise SceneError(f"robot {law.group!r}: a trajectory without a file cannot be written")
    xyz, rpy = xyz_rpy_from_transform(law.base)
    out: dict[str, Any] = {"name": law.group, "xyz": _floats(xyz), "rpy": _floats(rpy)}
    out["trajectory"] = law.trajectory.source
    src = law.source
    for key in ("urdf", "params", "tool_frame", "srdf"):
        if getattr(src, key) is not None:
            out[key] = str(getattr(src, key))
    if src.package_dirs:
        out["package_dirs"] = [str(d) for d in src.package_dirs]
    if src.locked_joints:
        out["locked_joints"] = dict(src.locked_joints)
    return out
