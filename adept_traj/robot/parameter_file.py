"""Robot parameter files: what a URDF cannot say, and the source the AdeptOne URDF is built from.

A parameter file is TOML (see ``urdf/adept_one_xl.toml`` and ``docs/robot-model.md``). For a
robot loaded from any URDF it may give, per joint, the acceleration and jerk limits, the
rotor inertia and gear ratio (their product ``rotor_inertia · gear_ratio²`` becomes
Pinocchio's ``model.armature``) and Coulomb/viscous friction; at the top level the tool frame
and the rows of the square task Jacobian. Values given here override the URDF's. The
AdeptOne XL file additionally describes the whole chain (joint origins, link solids and
masses), from which :mod:`adept_traj.robot.urdf_builder` writes the shipped URDF.

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


class _Reader:
    """Reads fields of one TOML table, naming the file, the item and the field on error."""

    def __init__(self, data: Any, where: str) -> None:
        if not isinstance(data, Mapping):
            raise RobotModelError(f"{where}: must be a table; got {data!r}")
        self.data, self.where, self.used = data, where, set()

    def fail(self, key: str, expected: str) -> RobotModelError:
        return RobotModelError(
            f"{self.where}: field '{key}' must be {expected}; got {self.data.get(key)!r}"
        )

    def get(self, key: str, default: Any = None) -> Any:
        self.used.add(key)
        return self.data.get(key, default)

    def string(self, key: str, required: bool = True) -> str | None:
        value = self.get(key)
        if value is None and not required:
            return None
        if not isinstance(value, str) or not value:
            raise self.fail(key, "a non-empty string")
        return value

    def number(self, key: str, *, positive: bool = False, nonneg: bool = False) -> float | None:
        value = self.get(key)
        if value is None:
            return None
        ok = isinstance(value, int | float) and not isinstance(value, bool)
        ok = ok and math.isfinite(value)
        if ok and positive:
            ok = value > 0
        if ok and nonneg:
            ok = value >= 0
        if not ok:
            kind = "positive" if positive else "non-negative" if nonneg else "finite"
            raise self.fail(key, f"a {kind} number")
        return float(value)

    def vector(self, key: str, size: int, default: tuple[float, ...] | None = None):
        value = self.get(key)
        if value is None:
            return default
        ok = isinstance(value, list) and len(value) == size
        ok = ok and all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
            for v in value
        )
        if not ok:
            raise self.fail(key, f"a list of {size} finite numbers")
        return tuple(float(v) for v in value)

    def finish(self) -> None:
        unknown = sorted(set(self.data) - self.used)
        if unknown:
            raise RobotModelError(f"{self.where}: unknown field(s) {unknown}")


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
        top = _Reader(data, source)
        rows = top.get("task_rows")
        if rows is not None and (
            not isinstance(rows, list)
            or not rows
            or any(r not in TASK_ROWS for r in rows)
            or len(set(rows)) != len(rows)
        ):
            raise top.fail("task_rows", f"a list of distinct names from {list(TASK_ROWS)}")
        params = cls(
            source=source,
            name=top.string("name", required=False),
            base_link=top.string("base_link", required=False),
            tool_frame=top.string("tool_frame", required=False),
            task_rows=tuple(rows) if rows is not None else None,
            joints=tuple(
                _joint(item, f"{source}: joint {i}") for i, item in enumerate(_items(top, "joint"))
            ),
            links=tuple(
                _link(item, f"{source}: link {i}") for i, item in enumerate(_items(top, "link"))
            ),
            frames=tuple(
                _frame(item, f"{source}: frame {i}") for i, item in enumerate(_items(top, "frame"))
            ),
        )
        top.finish()
        for kind in ("joints", "links", "frames"):
            names = [x.name for x in getattr(params, kind)]
            dup = {n for n in names if names.count(n) > 1}
            if dup:
                raise RobotModelError(f"{source}: duplicate {kind[:-1]} name(s) {sorted(dup)}")
        return params

    def joint(self, name: str) -> JointParameters | None:
        """The parameters of joint ``name``, or ``None`` if this file does not list it."""
        return next((j for j in self.joints if j.name == name), None)


def _items(top: _Reader, key: str) -> list[Any]:
    items = top.get(key, [])
    if not isinstance(items, list):
        raise top.fail(key, f"an array of tables ([[{key}]])")
    return items


def _joint(data: Any, where: str) -> JointParameters:
    name = _Reader(data, where).string("name")
    r = _Reader(data, f"{where.rsplit(':', 1)[0]}: joint '{name}'")
    r.get("name")
    jtype = r.string("type", required=False)
    if jtype is not None and jtype not in ("revolute", "prismatic"):
        raise r.fail("type", "'revolute' or 'prismatic'")
    values: dict[str, Any] = {"name": name, "type": jtype}
    for key in ("parent", "child"):
        values[key] = r.string(key, required=False)
    for key in ("xyz", "rpy", "axis"):
        values[key] = r.vector(key, 3)
    for key in ("lower", "upper"):
        values[key] = r.number(key)
    for key in ("velocity", "acceleration", "jerk", "effort", "gear_ratio"):
        values[key] = r.number(key, positive=True)
    for key in ("rotor_inertia", "coulomb", "viscous"):
        values[key] = r.number(key, nonneg=True)
    r.finish()
    lower, upper = values["lower"], values["upper"]
    if lower is not None and upper is not None and not lower < upper:
        raise RobotModelError(f"{r.where}: 'lower' ({lower}) must be below 'upper' ({upper})")
    return JointParameters(**values)


def _solid(data: Any, where: str) -> SolidParameters:
    name = _Reader(data, where).string("name")
    r = _Reader(data, f"{where}: solid '{name}'")
    r.get("name")
    shape = r.string("shape")
    if shape not in _SHAPES:
        raise r.fail("shape", f"one of {sorted(_SHAPES)}")
    size = r.vector("size", 3)
    radius = r.number("radius", positive=True)
    length = r.number("length", positive=True)
    given = {"size": size, "radius": radius, "length": length}
    for key, value in given.items():
        if (key in _SHAPES[shape]) != (value is not None):
            need = "required" if key in _SHAPES[shape] else "not allowed"
            raise RobotModelError(f"{r.where}: field '{key}' is {need} for a {shape}")
    if size is not None and min(size) <= 0:
        raise r.fail("size", "3 positive numbers [m]")
    mass = r.number("mass", positive=True)
    if mass is None:
        raise r.fail("mass", "a positive number [kg]")
    rgba = r.vector("rgba", 4, default=(0.7, 0.7, 0.7, 1.0))
    solid = SolidParameters(
        name=name,
        shape=shape,
        size=size,
        radius=radius,
        length=length,
        xyz=r.vector("xyz", 3, default=(0.0, 0.0, 0.0)),
        rpy=r.vector("rpy", 3, default=(0.0, 0.0, 0.0)),
        mass=mass,
        rgba=rgba,
    )
    r.finish()
    return solid


def _link(data: Any, where: str) -> LinkParameters:
    name = _Reader(data, where).string("name")
    r = _Reader(data, f"{where.rsplit(':', 1)[0]}: link '{name}'")
    r.get("name")
    solids = tuple(_solid(s, r.where) for s in _items(r, "solid"))
    r.finish()
    return LinkParameters(name=name, solids=solids)


def _frame(data: Any, where: str) -> FrameParameters:
    name = _Reader(data, where).string("name")
    r = _Reader(data, f"{where.rsplit(':', 1)[0]}: frame '{name}'")
    r.get("name")
    frame = FrameParameters(
        name=name,
        parent=r.string("parent"),
        xyz=r.vector("xyz", 3, default=(0.0, 0.0, 0.0)),
        rpy=r.vector("rpy", 3, default=(0.0, 0.0, 0.0)),
    )
    r.finish()
    return frame
