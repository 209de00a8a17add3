"""Where a robot is loaded from: :class:`RobotSource`, and the one reader of the ``[robot]``
table that scene files and cycle files share (:meth:`RobotSource.from_table`).

A ``[robot]`` table names the robot by the keys of :data:`ROBOT_FILE_KEYS`, the arguments
of :meth:`~adept_traj.robot.Robot.from_urdf`::

    [robot]
    urdf = "ur5_robot.urdf"            # or "package://ur_description/urdf/ur5_robot.urdf"
    params = "ur5.toml"
    tool_frame = "tool0"
    package_dirs = ["meshes"]
    srdf = "ur5.srdf"
    locked_joints = { wrist_3_joint = 0.0 }   # [rad | m]

File and folder paths are relative to the file that holds the table; the URDF may be a
``package://`` URI (found like its meshes). Without ``urdf`` the robot is the shipped
AdeptOne XL, and the other keys are refused.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from adept_traj.errors import ConfigurationError
from adept_traj.robot.robot import Robot
from adept_traj.schema import Node

__all__ = ["ROBOT_FILE_KEYS", "RobotSource"]

#: The keys of a ``[robot]`` table that name the robot (a scene file's table also has the
#: base pose, ``xyz`` and ``rpy``).
ROBOT_FILE_KEYS = ("urdf", "params", "tool_frame", "package_dirs", "srdf", "locked_joints")

_URI = "package://"


@dataclass(frozen=True)
class RobotSource:
    """The arguments of :meth:`~adept_traj.robot.Robot.from_urdf` that rebuild a robot
    (hashable and picklable: a Dask worker loads its robot from one).

    Attributes
    ----------
    urdf: the URDF's path or ``package://`` URI; ``None``: the shipped AdeptOne XL
        (:meth:`~adept_traj.robot.Robot.adept_one_xl`), and every other field must be
        empty.
    params: the parameter file (TOML), or ``None``.
    tool_frame: the tool frame's name, or ``None`` (the parameter file's, else the last).
    package_dirs: folders searched first for ``package://`` files.
    srdf: the SRDF's path or ``package://`` URI (its ``disable_collisions`` pairs), or
        ``None``.
    locked_joints: ``(name, value)`` pairs of joints fixed at a value [rad | m] (a mapping
        is accepted and stored as pairs).
    """

    urdf: str | Path | None = None
    params: str | Path | None = None
    tool_frame: str | None = None
    package_dirs: tuple[str | Path, ...] = ()
    srdf: str | Path | None = None
    locked_joints: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        pairs = self.locked_joints
        if isinstance(pairs, Mapping):
            pairs = tuple(pairs.items())
        locked = tuple((str(name), float(value)) for name, value in pairs)
        object.__setattr__(self, "locked_joints", locked)
        object.__setattr__(self, "package_dirs", tuple(Path(d) for d in self.package_dirs))
        if self.urdf is None:
            given = [f.name for f in dataclasses.fields(self) if f.name != "urdf" and _set(self, f)]
            if given:
                raise ConfigurationError(
                    f"{', '.join(given)} given without a URDF: they name the files of a robot "
                    "loaded from a URDF (--robot, or the [robot] table's 'urdf'); without one "
                    "the robot is the shipped AdeptOne XL"
                )

    @classmethod
    def from_table(cls, node: Node, folder: str | Path) -> RobotSource:
        """The source a ``[robot]`` table names (module doc); an absent table: the shipped
        AdeptOne XL.

        The caller checks the table's keys (those of :data:`ROBOT_FILE_KEYS`, and its own).
        Paths are made absolute from ``folder`` (that of the file holding the table); a file
        that does not exist is refused, with the node's exception class naming the field.
        """
        if not node.present:
            return cls()
        base = Path(folder).resolve()

        def path(key: str) -> str | Path | None:
            text = node[key].string(nonempty=True, default=None)
            if text is None or (key in ("urdf", "srdf") and text.startswith(_URI)):
                return text
            if not (base / text).is_file():
                raise node[key].error(f"no such file: {base / text}")
            return base / text

        locked = node["locked_joints"]
        pairs = tuple(
            (name, locked[name].number("[rad | m]"))
            for name in (locked.table() if locked.present else {})
        )
        dirs = tuple(base / d for d in node["package_dirs"].strings(default=()))
        return node.build(
            cls,
            urdf=path("urdf"),
            params=path("params"),
            tool_frame=node["tool_frame"].string(nonempty=True, default=None),
            package_dirs=dirs,
            srdf=path("srdf"),
            locked_joints=pairs,
        )

    def overridden(self, **fields: Any) -> RobotSource:
        """This source with the fields given not ``None`` (or not empty) replaced, e.g. by
        the command line's options; ``package_dirs`` given are searched before these."""
        given = {k: v for k, v in fields.items() if v is not None and v != ()}
        if "package_dirs" in given:
            given["package_dirs"] = tuple(given["package_dirs"]) + self.package_dirs
        return dataclasses.replace(self, **given)

    def load(self) -> Robot:
        """The :class:`~adept_traj.robot.Robot` (raises
        :class:`~adept_traj.errors.RobotModelError` when a file is missing or malformed)."""
        if self.urdf is None:
            return Robot.adept_one_xl()
        return Robot.from_urdf(
            self.urdf,
            self.params,
            package_dirs=self.package_dirs,
            srdf=self.srdf,
            tool_frame=self.tool_frame,
            locked_joints=dict(self.locked_joints) or None,
        )


def _set(source: RobotSource, field: dataclasses.Field) -> bool:
    """Whether ``field`` of ``source`` holds something (not ``None``, not empty)."""
    value = getattr(source, field.name)
    return value is not None and value != ()
