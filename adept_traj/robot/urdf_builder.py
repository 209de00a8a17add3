"""Write a URDF from a robot parameter file (the AdeptOne XL's ``urdf/adept_one_xl.toml``).

Each link's ``<inertial>`` is derived from its solids (:mod:`adept_traj.robot.inertia`); the
solids are also its ``<collision>`` and ``<visual>`` geometry; joints get their origins,
axes, ``<limit>`` (position [rad | m], velocity, effort) and ``<dynamics>`` (viscous
``damping`` and Coulomb ``friction``). What URDF cannot hold (acceleration and jerk limits,
rotor inertia) stays in the parameter file, which :class:`~adept_traj.robot.Robot` reads
beside the URDF.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from adept_traj.errors import RobotModelError
from adept_traj.robot.inertia import (
    MassProperties,
    box_inertia,
    combine,
    cylinder_inertia,
    sphere_inertia,
)
from adept_traj.robot.parameter_file import (
    JointParameters,
    LinkParameters,
    RobotParameters,
    SolidParameters,
)
from adept_traj.transforms import rotation_from_rpy

__all__ = ["build_urdf", "link_mass_properties", "solid_inertia"]

_JOINT_FIELDS = (
    "type", "parent", "child", "xyz", "rpy", "axis",
    "lower", "upper", "velocity", "effort", "coulomb", "viscous",
)  # fmt: skip


#: What :func:`_quoteattr` replaces, in this order (``&`` first).
_ATTRIBUTE_ESCAPES = (
    ("&", "&amp;"), (">", "&gt;"), ("<", "&lt;"),
    ("\n", "&#10;"), ("\r", "&#13;"), ("\t", "&#9;"),
)  # fmt: skip


def _quoteattr(value: str) -> str:
    """``value`` escaped and quoted as an XML attribute value: the same text as the
    standard library's ``xml.sax.saxutils.quoteattr``, whose module imports
    ``urllib.request`` (and with it ``http``, ``email`` and ``ssl``; moocore, which the
    optimiser uses, imports it too, so ``plan`` saves ``xml.sax`` itself). Double
    quotes, unless ``value`` holds a ``"`` and no ``'`` (then single quotes); a ``"``
    inside double quotes becomes ``&quot;``."""
    for plain, entity in _ATTRIBUTE_ESCAPES:
        value = value.replace(plain, entity)
    if '"' not in value:
        return f'"{value}"'
    if "'" not in value:
        return f"'{value}'"
    return '"{}"'.format(value.replace('"', "&quot;"))


def _num(x: float) -> str:
    return repr(float(x))


def _vec(v) -> str:
    return " ".join(_num(x) for x in v)


def solid_inertia(solid: SolidParameters) -> np.ndarray:
    """Inertia (3, 3) [kg·m²] of a uniform solid about its centre, in its own axes."""
    if solid.shape == "box":
        return box_inertia(solid.mass, solid.size)
    if solid.shape == "cylinder":
        return cylinder_inertia(solid.mass, solid.radius, solid.length)
    return sphere_inertia(solid.mass, solid.radius)


def link_mass_properties(link: LinkParameters) -> MassProperties | None:
    """Mass [kg], centre of mass (3,) [m] and inertia (3, 3) [kg·m²] of a link from its
    solids, in the link frame; ``None`` for a link without solids (a massless link)."""
    if not link.solids:
        return None
    return combine(
        (s.mass, np.array(s.xyz), rotation_from_rpy(s.rpy), solid_inertia(s)) for s in link.solids
    )


def _geometry(solid: SolidParameters) -> str:
    if solid.shape == "box":
        return f'<box size="{_vec(solid.size)}"/>'
    if solid.shape == "cylinder":
        return f'<cylinder radius="{_num(solid.radius)}" length="{_num(solid.length)}"/>'
    return f'<sphere radius="{_num(solid.radius)}"/>'


def _link_xml(link: LinkParameters) -> list[str]:
    lines = [f"  <link name={_quoteattr(link.name)}>"]
    props = link_mass_properties(link)
    if props is not None:
        i = props.inertia
        lines += [
            "    <inertial>",
            f'      <origin xyz="{_vec(props.com)}" rpy="0 0 0"/>',
            f'      <mass value="{_num(props.mass)}"/>',
            f'      <inertia ixx="{_num(i[0, 0])}" ixy="{_num(i[0, 1])}" ixz="{_num(i[0, 2])}"'
            f' iyy="{_num(i[1, 1])}" iyz="{_num(i[1, 2])}" izz="{_num(i[2, 2])}"/>',
            "    </inertial>",
        ]
    for s in link.solids:
        origin = f'<origin xyz="{_vec(s.xyz)}" rpy="{_vec(s.rpy)}"/>'
        lines += [
            f"    <visual name={_quoteattr(s.name)}>",
            f"      {origin}",
            f"      <geometry>{_geometry(s)}</geometry>",
            f"      <material name={_quoteattr(link.name + '/' + s.name)}>"
            f'<color rgba="{_vec(s.rgba)}"/></material>',
            "    </visual>",
            f"    <collision name={_quoteattr(s.name)}>",
            f"      {origin}",
            f"      <geometry>{_geometry(s)}</geometry>",
            "    </collision>",
        ]
    lines.append("  </link>")
    return lines


def _joint_xml(j: JointParameters, where: str) -> list[str]:
    missing = [f for f in _JOINT_FIELDS if getattr(j, f) is None]
    if missing:
        raise RobotModelError(f"{where}: joint '{j.name}': building a URDF needs {missing}")
    return [
        f"  <joint name={_quoteattr(j.name)} type={_quoteattr(j.type)}>",
        f"    <parent link={_quoteattr(j.parent)}/>",
        f"    <child link={_quoteattr(j.child)}/>",
        f'    <origin xyz="{_vec(j.xyz)}" rpy="{_vec(j.rpy)}"/>',
        f'    <axis xyz="{_vec(j.axis)}"/>',
        f'    <limit lower="{_num(j.lower)}" upper="{_num(j.upper)}"'
        f' velocity="{_num(j.velocity)}" effort="{_num(j.effort)}"/>',
        f'    <dynamics damping="{_num(j.viscous)}" friction="{_num(j.coulomb)}"/>',
        "  </joint>",
    ]


def build_urdf(params: RobotParameters | str | Path) -> str:
    """URDF text (str) of the robot described by a parameter file or its parsed content.

    Raises :class:`~adept_traj.errors.RobotModelError` naming the file and item when the
    description is incomplete (e.g. a joint without ``effort``) or a link is unknown.
    """
    if not isinstance(params, RobotParameters):
        params = RobotParameters.from_file(params)
    if params.name is None:
        raise RobotModelError(f"{params.source}: building a URDF needs a top-level 'name'")
    links = {link.name for link in params.links}
    for j in params.joints:
        for end in (j.parent, j.child):
            if end is not None and end not in links:
                raise RobotModelError(
                    f"{params.source}: joint '{j.name}' refers to unknown link '{end}'"
                )
    for f in params.frames:
        if f.parent not in links:
            raise RobotModelError(
                f"{params.source}: frame '{f.name}' refers to unknown link '{f.parent}'"
            )
    out = [
        '<?xml version="1.0"?>',
        f"<!-- Generated by adept_traj.robot.urdf_builder from {Path(params.source).name};"
        " edit that file, not this one. -->",
        f"<robot name={_quoteattr(params.name)}>",
    ]
    for link in params.links:
        out += _link_xml(link)
    for j in params.joints:
        out += _joint_xml(j, params.source)
    for f in params.frames:
        out += [
            f"  <link name={_quoteattr(f.name)}/>",
            f'  <joint name={_quoteattr(f.name + "_joint")} type="fixed">',
            f"    <parent link={_quoteattr(f.parent)}/>",
            f"    <child link={_quoteattr(f.name)}/>",
            f'    <origin xyz="{_vec(f.xyz)}" rpy="{_vec(f.rpy)}"/>',
            "  </joint>",
        ]
    out.append("</robot>")
    return "\n".join(out) + "\n"
