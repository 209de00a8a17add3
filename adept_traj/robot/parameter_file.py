"""Robot parameter files: what a URDF cannot say, and the source the AdeptOne URDF is built from.

A parameter file is TOML (see ``urdf/adept_one_xl.toml`` and ``docs/robot-model.md``). For a
robot loaded from any URDF it may give, per joint, the acceleration and jerk limits, the
rotor inertia and gear ratio (their product ``rotor_inertia · gear_ratio²`` becomes
Pinocchio's ``model.armature``) and Coulomb/viscous friction; at the top level the tool frame,
the rows of the square task Jacobian and ``disable_collisions = [["link1", "link2"], …]``:
link pairs left out of the self-collision check (as an SRDF's ``disable_collisions``).
Values given here override the URDF's. The AdeptOne XL file additionally describes the
whole chain (joint origins, link solids and masses), from which
:mod:`adept_traj.robot.urdf_builder` writes the shipped URDF.

Units: SI — [m], [rad], [s], [kg], [kg·m²], [N], [N·m].
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from adept_traj.errors import RobotModelError
from adept_traj.files import read_toml
from adept_traj.schema import Node, error_factory

__all__ = [
    "TASK_ROWS",
    "FrameParameters",
    "JointParameters",
    "LinkParameters",
    "RobotParameters",
    "SolidParameters",
]

#: Row names of a 6×n frame Jacobian (linear velocity first, then angular velocity).
TASK_ROWS: tuple[str, ...] = ("vx", "vy", "vz", "wx", "wy", "wz")

_SHAPES = {"box": ("size",), "cylinder": ("radius", "length"), "sphere": ("radius",)}

#: Errors of a parameter file: RobotModelError naming the file and the field path.
_ERROR = error_factory(RobotModelError)

_TOP_KEYS = (
    "name",
    "base_link",
    "tool_frame",
    "task_rows",
    "disable_collisions",
    "joint",
    "link",
    "frame",
)
_SOLID_KEYS = ("name", "shape", "xyz", "rpy", "mass", "rgba")
_FRAME_KEYS = ("name", "parent", "xyz", "rpy")
#: The numbers of a [[joint]] table: key -> (unit, minimum, strictly above the minimum).
_JOINT_NUMBERS: dict[str, tuple[str, float, bool]] = {
    "lower": ("[rad | m]", -math.inf, False),
    "upper": ("[rad | m]", -math.inf, False),
    "velocity": ("[rad/s | m/s]", 0.0, True),
    "acceleration": ("[rad/s² | m/s²]", 0.0, True),
    "jerk": ("[rad/s³ | m/s³]", 0.0, True),
    "effort": ("[N·m | N]", 0.0, True),
    "gear_ratio": ("[-]", 0.0, True),
    "rotor_inertia": ("[kg·m²]", 0.0, False),
    "coulomb": ("[N·m | N]", 0.0, False),
    "viscous": ("[N·m·s/rad | N·s/m]", 0.0, False),
}
_JOINT_VECTORS = {"xyz": "[m]", "rpy": "[rad]", "axis": "[-]"}
_JOINT_KEYS = ("name", "type", "parent", "child", *_JOINT_VECTORS, *_JOINT_NUMBERS)


@dataclass(frozen=True)
class SolidParameters:
    """One uniform solid of a link: shape, dimensions [m], pose in the link frame
    (``xyz`` [m], ``rpy`` [rad]), ``mass`` [kg] and display colour ``rgba``."""

    name: str
    shape: str
    size: tuple[float, float, float] | None
    radius: float | None
    length: float | None
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    mass: float
    rgba: tuple[float, float, float, float]


@dataclass(frozen=True)
class LinkParameters:
    """A link and its solids (possibly none)."""

    name: str
    solids: tuple[SolidParameters, ...]


@dataclass(frozen=True)
class FrameParameters:
    """A fixed frame (e.g. the tool) attached to ``parent`` at ``xyz`` [m], ``rpy`` [rad]."""

    name: str
    parent: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]


@dataclass(frozen=True)
class JointParameters:
    """Parameters of one joint; ``None`` means "not given here" (the URDF's value is kept).

    Units: positions [rad] or [m]; ``velocity`` [rad/s | m/s]; ``acceleration`` [rad/s² |
    m/s²]; ``jerk`` [rad/s³ | m/s³]; ``effort`` [N·m | N]; ``rotor_inertia`` [kg·m²];
    ``gear_ratio`` [-] (revolute) or [rad/m] (prismatic); ``coulomb`` [N·m | N];
    ``viscous`` [N·m·s/rad | N·s/m].
    """

    name: str
    type: str | None = None
    parent: str | None = None
    child: str | None = None
    xyz: tuple[float, float, float] | None = None
    rpy: tuple[float, float, float] | None = None
    axis: tuple[float, float, float] | None = None
    lower: float | None = None
    upper: float | None = None
    velocity: float | None = None
    acceleration: float | None = None
    jerk: float | None = None
    effort: float | None = None
    rotor_inertia: float | None = None
    gear_ratio: float | None = None
    coulomb: float | None = None
    viscous: float | None = None

    @property
    def armature(self) -> float | None:
        r"""Reflected rotor inertia :math:`J_m N^2` [kg·m² | kg], or ``None`` if not given."""
        if self.rotor_inertia is None:
            return None
        ratio = 1.0 if self.gear_ratio is None else self.gear_ratio
        return self.rotor_inertia * ratio**2


@dataclass(frozen=True)
class RobotParameters:
    """Content of a robot parameter file (see the module docstring)."""

    source: str
    name: str | None = None
    base_link: str | None = None
    tool_frame: str | None = None
    task_rows: tuple[str, ...] | None = None
    disabled_pairs: tuple[tuple[str, str], ...] = ()
    joints: tuple[JointParameters, ...] = ()
    links: tuple[LinkParameters, ...] = ()
    frames: tuple[FrameParameters, ...] = ()

    @classmethod
    def from_file(cls, path: str | Path) -> RobotParameters:
        """Read and validate a parameter file; errors name the file, item and field."""
        return cls.from_dict(read_toml(path, RobotModelError), source=str(path))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "<dict>") -> RobotParameters:
        """Validate a parsed parameter mapping (same schema as the TOML file)."""
        top = Node(data, source, _ERROR).check_keys(_TOP_KEYS)
        off = top["disable_collisions"]
        pairs = tuple(tuple(n.strings(min_items=2)) for n in off.items(default=[]))
        if any(len(pair) != 2 for pair in pairs):
            raise off.error("must hold [link1, link2] pairs of link names")
        params = cls(
            source=source,
            name=top["name"].string(nonempty=True, default=None),
            base_link=top["base_link"].string(nonempty=True, default=None),
            tool_frame=top["tool_frame"].string(nonempty=True, default=None),
            task_rows=top["task_rows"].strings(
                choices=TASK_ROWS, distinct=True, min_items=1, default=None
            ),
            disabled_pairs=pairs,
            joints=tuple(_joint(name, node) for name, node in top["joint"].named_tables()),
            links=tuple(_link(name, node) for name, node in top["link"].named_tables()),
            frames=tuple(_frame(name, node) for name, node in top["frame"].named_tables()),
        )
        for key in ("joint", "link", "frame"):
            _check_distinct(top[key], [x.name for x in getattr(params, f"{key}s")])
        return params

    def joint(self, name: str) -> JointParameters | None:
        """The parameters of joint ``name``, or ``None`` if this file does not list it."""
        return next((j for j in self.joints if j.name == name), None)


def _check_distinct(node: Node, names: list[str]) -> None:
    """Refuse an array of tables that gives a name twice."""
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise node.error(f"names must be distinct; got {twice[0]!r} more than once")


def _floats(node: Node, size: int, unit: str, default: Any = None, **bounds: Any) -> Any:
    """``size`` numbers as a tuple of floats (``default`` when absent); ``bounds``: the
    ``minimum``/``strict`` of :meth:`Node.array <adept_traj.schema.Node.array>`."""
    arr = node.array((size,), unit, default=None, **bounds)
    return default if arr is None else tuple(arr.tolist())


def _joint(name: str, node: Node) -> JointParameters:
    node.check_keys(_JOINT_KEYS)
    values: dict[str, Any] = {
        "name": name,
        "type": node["type"].string(choices=("revolute", "prismatic"), default=None),
        "parent": node["parent"].string(nonempty=True, default=None),
        "child": node["child"].string(nonempty=True, default=None),
    }
    for key, unit in _JOINT_VECTORS.items():
        values[key] = _floats(node[key], 3, unit)
    for key, (unit, minimum, strict) in _JOINT_NUMBERS.items():
        values[key] = node[key].number(unit, minimum=minimum, strict=strict, default=None)
    lower, upper = values["lower"], values["upper"]
    if lower is not None and upper is not None and not lower < upper:
        raise node["upper"].error(f"must be above 'lower' ({lower}); got {upper}")
    return JointParameters(**values)


def _solid(name: str, node: Node) -> SolidParameters:
    shape = node["shape"].string(choices=sorted(_SHAPES))
    node.check_keys(_SOLID_KEYS + _SHAPES[shape])
    dims: dict[str, Any] = {"size": None, "radius": None, "length": None}
    for key in _SHAPES[shape]:  # required for this shape (and refused for the others)
        field, positive = node[key], {"minimum": 0.0, "strict": True}
        dims[key] = (
            tuple(field.array((3,), "[m]", **positive).tolist())
            if key == "size"
            else field.number("[m]", **positive)
        )
    return SolidParameters(
        name=name,
        shape=shape,
        **dims,
        xyz=_floats(node["xyz"], 3, "[m]", (0.0, 0.0, 0.0)),
        rpy=_floats(node["rpy"], 3, "[rad]", (0.0, 0.0, 0.0)),
        mass=node["mass"].number("[kg]", minimum=0.0, strict=True),
        rgba=_floats(node["rgba"], 4, "[-]", (0.7, 0.7, 0.7, 1.0)),
    )


def _link(name: str, node: Node) -> LinkParameters:
    node.check_keys(("name", "solid"))
    solids = tuple(_solid(sname, snode) for sname, snode in node["solid"].named_tables())
    return LinkParameters(name=name, solids=solids)


def _frame(name: str, node: Node) -> FrameParameters:
    node.check_keys(_FRAME_KEYS)
    return FrameParameters(
        name=name,
        parent=node["parent"].string(nonempty=True),
        xyz=_floats(node["xyz"], 3, "[m]", (0.0, 0.0, 0.0)),
        rpy=_floats(node["rpy"], 3, "[rad]", (0.0, 0.0, 0.0)),
    )
