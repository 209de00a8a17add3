"""Loading a robot description: the shipped files, the URDF into Pinocchio, the parameter file.

:meth:`Robot.from_urdf <adept_traj.robot.Robot.from_urdf>` calls these: the URDF becomes a
Pinocchio model with its collision and visual geometry (solids named ``<link>/<name>``), and a
parameter file's values (limits [rad | m, rad/s | m/s, …], friction, rotor inertia) are
written into the model and its :class:`~adept_traj.robot.limits.JointLimits`.
"""

from __future__ import annotations

import contextlib
import xml.etree.ElementTree as ET
from importlib import resources
from pathlib import Path

import numpy as np
import pinocchio as pin

from adept_traj.errors import RobotModelError
from adept_traj.robot.limits import JointLimits
from adept_traj.robot.parameter_file import RobotParameters

__all__ = ["apply_parameters", "load_urdf_models", "shipped_file"]


def shipped_file(name: str) -> Path:
    """Path of a shipped robot file (``adept_one_xl.urdf``, ``adept_one_xl.toml``).

    The top-level ``urdf/`` folder is packaged as ``adept_traj.urdf``; it is found with
    :mod:`importlib.resources` in a wheel or an editable install, and as ``urdf/`` beside the
    package in a plain source checkout.
    """
    candidates = []
    with contextlib.suppress(ModuleNotFoundError):
        candidates.append(Path(str(resources.files("adept_traj.urdf").joinpath(name))))
    candidates.append(Path(__file__).resolve().parents[2] / "urdf" / name)
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    raise RobotModelError(
        f"shipped robot file '{name}' not found (looked in {', '.join(map(str, candidates))})"
    )


def load_urdf_models(path: Path) -> tuple[str, pin.Model, pin.GeometryModel, pin.GeometryModel]:
    """``(name, model, collision model, visual model)`` of the URDF at ``path``.

    Raises :class:`~adept_traj.errors.RobotModelError` for a missing file, malformed XML, a
    root element other than ``<robot>``, a URDF Pinocchio cannot load, or a robot without a
    moving joint.
    """
    if not path.is_file():
        raise RobotModelError(f"URDF not found: {path}")
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise RobotModelError(f"{path}: malformed XML: {exc}") from None
    if root.tag != "robot":
        raise RobotModelError(f"{path}: root element is <{root.tag}>, expected <robot>")
    try:
        model = pin.buildModelFromUrdf(str(path))
        collision = pin.buildGeomFromUrdf(model, str(path), pin.COLLISION)
        visual = pin.buildGeomFromUrdf(model, str(path), pin.VISUAL)
    except (RuntimeError, ValueError) as exc:
        raise RobotModelError(f"{path}: Pinocchio cannot load this URDF: {exc}") from None
    if model.nq == 0:
        raise RobotModelError(f"{path}: the robot has no moving joint")
    _name_geometries(collision, root, "collision")
    _name_geometries(visual, root, "visual")
    return root.get("name", path.stem), model, collision, visual


def apply_parameters(model: pin.Model, params: RobotParameters | None, path: Path) -> JointLimits:
    """Write a parameter file's values into ``model`` (limits, ``friction`` (Coulomb),
    ``damping`` (viscous), ``armature`` (rotor inertia)) and return the joint limits: the
    model's position [rad | m], velocity and torque (URDF: effort) limits with the file's
    acceleration and jerk limits (``inf`` where not given). ``path`` (the URDF) names it in
    error messages."""
    acceleration, jerk = _write_parameters(model, params, path)
    return JointLimits(
        names=tuple(model.names[1:]),
        units=tuple(_joint_unit(model, i) for i in range(1, model.njoints)),
        lower=model.lowerPositionLimit,
        upper=model.upperPositionLimit,
        velocity=model.velocityLimit,
        acceleration=acceleration,
        jerk=jerk,
        torque=model.effortLimit,
    )


def _joint_unit(model: pin.Model, i: int) -> str:
    short = model.joints[i].shortname()
    return "m" if "Prismatic" in short or short.startswith("JointModelP") else "rad"


def _name_geometries(gm: pin.GeometryModel, root: ET.Element, tag: str) -> None:
    """Rename Pinocchio's ``<link>_<k>`` geometry objects to ``<link>/<name>`` when the URDF
    names its ``<collision>``/``<visual>`` elements."""
    names = {}
    for link in root.iter("link"):
        for k, element in enumerate(link.findall(tag)):
            if element.get("name"):
                names[f"{link.get('name')}_{k}"] = f"{link.get('name')}/{element.get('name')}"
    for obj in gm.geometryObjects:
        obj.name = names.get(obj.name, obj.name)


def _write_parameters(
    model: pin.Model, params: RobotParameters | None, path: Path
) -> tuple[np.ndarray, np.ndarray]:
    """Write a parameter file's values into ``model``; return acceleration and jerk limits."""
    acceleration = np.full(model.nq, np.inf)
    jerk = np.full(model.nq, np.inf)
    if params is None:
        return acceleration, jerk
    known = set(model.names[1:])
    unknown = [j.name for j in params.joints if j.name not in known]
    if unknown:
        raise RobotModelError(
            f"{params.source}: joint(s) {unknown} are not in {path}; its joints are {sorted(known)}"
        )
    for j in params.joints:
        k = model.joints[model.getJointId(j.name)].idx_q
        targets = {
            "lower": model.lowerPositionLimit,
            "upper": model.upperPositionLimit,
            "velocity": model.velocityLimit,
            "effort": model.effortLimit,
            "coulomb": model.friction,
            "viscous": model.damping,
        }
        for key, vector in targets.items():
            value = getattr(j, key)
            if value is not None:
                vector[k] = value
        if j.armature is not None:
            model.armature[k] = j.armature
        if j.acceleration is not None:
            acceleration[k] = j.acceleration
        if j.jerk is not None:
            jerk[k] = j.jerk
    return acceleration, jerk
