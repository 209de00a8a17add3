"""The robot.

URDF + parameter file -> Pinocchio model, batched kinematics, joint limits, URDF builder."""

from __future__ import annotations

from adept_traj.robot.collision_meshes import (
    HullReport,
    convex_hull_solids,
)
from adept_traj.robot.forward_kinematics import (
    place_solids,
    solid_frames,
)
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
    stack_times,
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
from adept_traj.robot.package_paths import (
    installed_data_dirs,
    package_search_dirs,
    resolve_package_file,
    resolve_package_uris,
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
from adept_traj.robot.robot_source import (
    ROBOT_FILE_KEYS,
    RobotSource,
)
from adept_traj.robot.urdf_builder import (
    build_urdf,
    link_mass_properties,
    solid_inertia,
)
from adept_traj.robot.urdf_loading import (
    CONTINUOUS_RANGE,
    apply_parameters,
    coordinate_joints,
    load_urdf_models,
    read_srdf_disabled_pairs,
    shipped_file,
)

__all__ = [
    "CONTINUOUS_RANGE",
    "ELBOWS",
    "LIMITS",
    "LIMIT_KINDS",
    "ROBOT_FILE_KEYS",
    "TASK_ROWS",
    "VELOCITY_AT_REST",
    "BatchKinematics",
    "ForwardKinematics",
    "FrameParameters",
    "HullReport",
    "JointLimits",
    "JointParameters",
    "LimitKind",
    "LinkParameters",
    "MassProperties",
    "Robot",
    "RobotParameters",
    "RobotSource",
    "ScaraGeometry",
    "SolidParameters",
    "apply_parameters",
    "box_inertia",
    "build_urdf",
    "combine",
    "compose",
    "convex_hull_solids",
    "coordinate_joints",
    "coulomb_sign",
    "cylinder_inertia",
    "frames_to_poses",
    "installed_data_dirs",
    "link_mass_properties",
    "load_urdf_models",
    "manipulability_measure",
    "numeric_ik",
    "package_search_dirs",
    "place_solids",
    "read_srdf_disabled_pairs",
    "resolve_package_file",
    "resolve_package_uris",
    "scara_ik",
    "scara_location",
    "shipped_file",
    "solid_frames",
    "solid_inertia",
    "solve_location",
    "sphere_inertia",
    "stack_times",
]
