"""The robot.

URDF + parameter file -> Pinocchio model, batched kinematics, joint limits, URDF builder."""

from __future__ import annotations

from adept_traj.robot.inertia import (
    MassProperties,
    box_inertia,
    combine,
    cylinder_inertia,
    sphere_inertia,
)
from adept_traj.robot.inverse_kinematics import (
    ELBOWS,
    ScaraGeometry,
    numeric_ik,
    scara_ik,
    scara_location,
    solve_location,
)
from adept_traj.robot.kinematics import (
    BatchKinematics,
    compose,
    frames_to_poses,
)
from adept_traj.robot.limits import (
    LIMIT_KINDS,
    LIMITS,
    JointLimits,
    LimitKind,
)
from adept_traj.robot.manipulability import (
    manipulability_measure,
)
from adept_traj.robot.parameter_file import (
    TASK_ROWS,
    FrameParameters,
    JointParameters,
    LinkParameters,
    RobotParameters,
    SolidParameters,
)
from adept_traj.robot.robot import (
    VELOCITY_AT_REST,
    ForwardKinematics,
    Robot,
    coulomb_sign,
)
from adept_traj.robot.urdf_builder import (
    build_urdf,
    link_mass_properties,
    solid_inertia,
)
from adept_traj.robot.urdf_loading import (
    apply_parameters,
    load_urdf_models,
    shipped_file,
)

__all__ = [
    "ELBOWS",
    "LIMITS",
    "LIMIT_KINDS",
    "TASK_ROWS",
    "VELOCITY_AT_REST",
    "BatchKinematics",
    "ForwardKinematics",
    "FrameParameters",
    "JointLimits",
    "JointParameters",
    "LimitKind",
    "LinkParameters",
    "MassProperties",
    "Robot",
    "RobotParameters",
    "ScaraGeometry",
    "SolidParameters",
    "apply_parameters",
    "box_inertia",
    "build_urdf",
    "combine",
    "compose",
    "coulomb_sign",
    "cylinder_inertia",
    "frames_to_poses",
    "link_mass_properties",
    "load_urdf_models",
    "manipulability_measure",
    "numeric_ik",
    "scara_ik",
    "scara_location",
    "shipped_file",
    "solid_inertia",
    "solve_location",
    "sphere_inertia",
]
