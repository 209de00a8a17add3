"""Loading a robot description: the shipped files, the URDF into Pinocchio, the parameter file.

:meth:`Robot.from_urdf <adept_traj.robot.Robot.from_urdf>` calls these: the URDF becomes a
Pinocchio model with its collision and visual geometry (solids named ``<link>/<name>``), and a
parameter file's values (limits [rad | m, rad/s | m/s, …], friction, rotor inertia) are
written into the model and its :class:`~adept_traj.robot.limits.JointLimits`.

Joint kinds beyond 1-DoF revolute and prismatic joints:

- **continuous** joints become revolute joints with **one angle coordinate** [rad] (not
  Pinocchio's (cos θ, sin θ) pair) and the planning range
  ``[-CONTINUOUS_RANGE, CONTINUOUS_RANGE]`` = [−2π, 2π] (two turns: every angle is
  reachable from every start without a joint stop in the way; a parameter file's
  ``lower``/``upper`` narrow or widen it);
- **mimic** joints follow their leader (Pinocchio's own mimic support,
  ``q_follower = multiplier · q_leader + offset``): they have no coordinate of their own
  (the Panda plans with 8 coordinates, not 9);
- **locked** joints (``locked_joints={name: value}``) are removed from the model with
  Pinocchio's ``buildReducedModel``, fixed at the given value [rad | m].
"""

from __future__ import annotations

import contextlib
import math
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterable, Mapping
from importlib import resources
from pathlib import Path

import numpy as np
import pinocchio as pin

from adept_traj.errors import RobotModelError
from adept_traj.robot.limits import JointLimits
from adept_traj.robot.package_paths import resolve_package_uris
from adept_traj.robot.parameter_file import RobotParameters

__all__ = [
    "CONTINUOUS_RANGE",
    "apply_parameters",
    "coordinate_joints",
    "load_urdf_models",
    "read_srdf_disabled_pairs",
    "shipped_file",
]

#: Half-width [rad] of the planning range given to a continuous joint: [−2π, 2π].
CONTINUOUS_RANGE = 2.0 * math.pi


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


def load_urdf_models(
    path: Path,
    package_dirs: Iterable[str | Path] = (),
    locked_joints: Mapping[str, float] | None = None,
) -> tuple[str, pin.Model, pin.GeometryModel, Callable[[], pin.GeometryModel], tuple[Path, ...]]:
    """``(name, model, collision model, visual model loader, package folders used)`` of the
    URDF at ``path`` (see the module docstring for continuous, mimic and locked joints; the
    package folders are those of
    :func:`~adept_traj.robot.package_paths.resolve_package_uris`). The visual model is
    loaded by calling the loader (display only; its meshes can take a second to read).

    Raises :class:`~adept_traj.errors.RobotModelError` for a missing file, malformed XML, a
    root element other than ``<robot>``, a ``package://`` mesh not found, a URDF Pinocchio
    cannot load, a locked joint that is not a joint with a coordinate (or a value that is
    not a finite number), or a robot without a moving joint.
    """
    root = _read_xml(path, "URDF")
    if root.tag != "robot":
        raise RobotModelError(f"{path}: root element is <{root.tag}>, expected <robot>")
    dirs = resolve_package_uris(root, path, package_dirs)
    _check_limit_order(root, path)
    text, unlimited = _continuous_as_revolute(root)
    try:
        full = pin.buildModelFromXML(text, mimic=True)
    except (RuntimeError, ValueError) as exc:
        raise RobotModelError(f"{path}: Pinocchio cannot load this URDF: {exc}") from None
    for name in unlimited:  # as Pinocchio does for a continuous joint without <limit>
        k = full.joints[full.getJointId(name)].idx_q
        full.velocityLimit[k] = full.effortLimit[k] = np.inf
    model, lock = full, _lock(full, locked_joints or {}, path)

    def geometry(kind: pin.GeometryType) -> pin.GeometryModel:
        try:
            gm = pin.buildGeomFromUrdf(full, str(path), kind, package_dirs=[str(d) for d in dirs])
        except (RuntimeError, ValueError) as exc:
            raise RobotModelError(f"{path}: Pinocchio cannot load this URDF: {exc}") from None
        if lock is not None:
            gm = pin.buildReducedModel(full, gm, *lock)[1]
        _name_geometries(gm, root, "collision" if kind == pin.COLLISION else "visual")
        return gm

    if lock is not None:
        model = pin.buildReducedModel(full, *lock)
    if model.nq == 0:
        raise RobotModelError(f"{path}: the robot has no moving joint")
    collision = geometry(pin.COLLISION)
    return root.get("name", path.stem), model, collision, lambda: geometry(pin.VISUAL), dirs


def read_srdf_disabled_pairs(path: Path) -> tuple[tuple[str, str], ...]:
    """The ``(link1, link2)`` pairs of an SRDF's ``<disable_collisions>`` elements (the
    MoveIt convention: link pairs never checked for self-collision).

    Raises :class:`~adept_traj.errors.RobotModelError` for a missing or malformed file."""
    root = _read_xml(path, "SRDF")
    return tuple((e.get("link1", ""), e.get("link2", "")) for e in root.iter("disable_collisions"))


def _check_limit_order(root: ET.Element, path: Path) -> None:
    """Refuse a joint whose ``<limit lower upper>`` are reversed (lower > upper), naming
    the joint, the file and both values [rad | m] (urdfdom and Pinocchio accept them, and
    every value of the joint would later be called outside its limits). Continuous
    joints (whose position limits are ignored) and limits that are not numbers (Pinocchio
    refuses those) are left alone."""
    for joint in root.iter("joint"):
        limit = joint.find("limit")
        if limit is None or joint.get("type") == "continuous":
            continue
        try:
            lower, upper = float(limit.get("lower", "0")), float(limit.get("upper", "0"))
        except ValueError:
            continue
        if lower > upper:
            raise RobotModelError(
                f"{path}: joint {joint.get('name')!r} has reversed limits: lower = {lower:g} > "
                f"upper = {upper:g} [rad | m]; swap them"
            )


def _read_xml(path: Path, what: str) -> ET.Element:
    """The root element of the XML file ``path`` (a ``what``: URDF, SRDF), or
    :class:`~adept_traj.errors.RobotModelError` for a missing file or malformed XML."""
    if not path.is_file():
        raise RobotModelError(f"{what} not found: {path}")
    try:
        return ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise RobotModelError(f"{path}: malformed XML: {exc}") from None


def coordinate_joints(model: pin.Model) -> tuple[str, ...]:
    """Names of the joints that own a coordinate of q, in the order of q (mimic joints,
    which follow a leader, are left out)."""
    return tuple(model.names[i] for i in range(1, model.njoints) if model.joints[i].nq > 0)


def _continuous_as_revolute(root: ET.Element) -> tuple[str, tuple[str, ...]]:
    """The URDF text with every continuous joint made revolute over
    [−CONTINUOUS_RANGE, CONTINUOUS_RANGE] (a copy; ``root`` is not changed), and the names
    of those without a ``<limit>`` element (their speed and effort are unlimited: urdfdom
    needs finite values in the text; they are set to ``inf`` in the model)."""
    root = ET.fromstring(ET.tostring(root))
    unlimited = []
    for joint in root.iter("joint"):
        if joint.get("type") != "continuous":
            continue
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            limit = ET.SubElement(joint, "limit", effort="1", velocity="1")
            unlimited.append(joint.get("name", ""))
        limit.set("lower", repr(-CONTINUOUS_RANGE))
        limit.set("upper", repr(CONTINUOUS_RANGE))
    return ET.tostring(root, encoding="unicode"), tuple(unlimited)


def _lock(
    model: pin.Model, locked: Mapping[str, float], path: Path
) -> tuple[list[int], np.ndarray] | None:
    """``(joint ids, reference configuration)`` for ``pinocchio.buildReducedModel`` that fix
    the ``locked`` joints at their values; ``None`` when there are none."""
    if not locked:
        return None
    names = coordinate_joints(model)
    q_ref = pin.neutral(model)
    ids = []
    for name, value in locked.items():
        if name not in names:
            raise RobotModelError(
                f"{path}: locked joint {name!r} is not a joint with a coordinate; "
                f"those are {list(names)}"
            )
        if not isinstance(value, (int, float)) or not math.isfinite(value):
            raise RobotModelError(
                f"{path}: locked joint {name!r} needs a finite value [rad | m]; got {value!r}"
            )
        joint_id = model.getJointId(name)
        q_ref[model.joints[joint_id].idx_q] = float(value)
        ids.append(joint_id)
    return ids, q_ref


def apply_parameters(model: pin.Model, params: RobotParameters | None, path: Path) -> JointLimits:
    """Write a parameter file's values into ``model`` (limits, ``friction`` (Coulomb),
    ``damping`` (viscous), ``armature`` (rotor inertia)) and return the joint limits: the
    model's position [rad | m], velocity and torque (URDF: effort) limits with the file's
    acceleration and jerk limits (``inf`` where not given). ``path`` (the URDF) names it in
    error messages."""
    acceleration, jerk = _write_parameters(model, params, path)
    return JointLimits(
        names=coordinate_joints(model),
        units=tuple(_joint_unit(model, model.getJointId(n)) for n in coordinate_joints(model)),
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
    known = set(coordinate_joints(model))
    unknown = [j.name for j in params.joints if j.name not in known]
    if unknown:
        raise RobotModelError(
            f"{params.source}: joint(s) {unknown} are not in {path}; its joints are {sorted(known)}"
        )
    links = {f.name for f in model.frames if f.type == pin.FrameType.BODY}
    unknown = sorted({n for pair in params.disabled_pairs for n in pair if n not in links})
    if unknown:
        raise RobotModelError(
            f"{params.source}: disable_collisions names link(s) {unknown} not in {path}; its "
            f"links are {sorted(links)}"
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
        if model.lowerPositionLimit[k] > model.upperPositionLimit[k]:
            raise RobotModelError(
                f"{params.source}: joint {j.name!r} of {path} has reversed limits: lower = "
                f"{model.lowerPositionLimit[k]:g} > upper = {model.upperPositionLimit[k]:g} "
                "[rad | m]; swap them"
            )
    return acceleration, jerk
