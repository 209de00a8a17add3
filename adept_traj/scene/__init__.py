"""The scene: obstacle shapes (primitives, meshes), obstacle motion laws, :class:`Scene` and
scene files."""

from __future__ import annotations

from adept_traj.errors import SceneFileNotFoundError
from adept_traj.scene.machine_motions import LinearMotion, RotationMotion, rotation_about
from adept_traj.scene.meshes import (
    MAX_MESH_TRIANGLES,
    MESH_SUFFIXES,
    Mesh,
    merge_meshes,
    read_mesh_arrays,
)
from adept_traj.scene.motion_laws import (
    FixedPose,
    MotionLaw,
    PendulumMotion,
)
from adept_traj.scene.point_clouds import CLOUD_SUFFIXES, PointCloud, cloud_bytes, read_cloud_points
from adept_traj.scene.recorded_motion import MAX_RECORDED_POSES, RecordedMotion, read_pose_csv
from adept_traj.scene.robot_motion import JointTrajectory, RobotSolidMotion, robot_obstacles
from adept_traj.scene.scene import (
    MAX_OBSTACLES,
    Obstacle,
    Scene,
    check_obstacle_count,
    pendulum_obstacles,
    scene_notes,
)
from adept_traj.scene.scene_file import (
    SHIPPED_SCENES,
    read_paper_scene,
    read_robot_files,
    read_scene_file,
    read_shipped_scene,
    scene_from_dict,
    scene_to_dict,
    scene_to_toml,
    write_scene_file,
)
from adept_traj.scene.shapes import (
    Box,
    Capsule,
    Cylinder,
    Shape,
    Sphere,
    coal_transform,
)
from adept_traj.scene.triangulation import shape_triangles

__all__ = [
    "CLOUD_SUFFIXES",
    "MAX_MESH_TRIANGLES",
    "MAX_OBSTACLES",
    "MAX_RECORDED_POSES",
    "MESH_SUFFIXES",
    "SHIPPED_SCENES",
    "Box",
    "Capsule",
    "Cylinder",
    "FixedPose",
    "JointTrajectory",
    "LinearMotion",
    "Mesh",
    "MotionLaw",
    "Obstacle",
    "PendulumMotion",
    "PointCloud",
    "RecordedMotion",
    "RobotSolidMotion",
    "RotationMotion",
    "Scene",
    "SceneFileNotFoundError",
    "Shape",
    "Sphere",
    "check_obstacle_count",
    "cloud_bytes",
    "coal_transform",
    "merge_meshes",
    "pendulum_obstacles",
    "read_cloud_points",
    "read_mesh_arrays",
    "read_paper_scene",
    "read_pose_csv",
    "read_robot_files",
    "read_scene_file",
    "read_shipped_scene",
    "robot_obstacles",
    "rotation_about",
    "scene_from_dict",
    "scene_notes",
    "scene_to_dict",
    "scene_to_toml",
    "shape_triangles",
    "write_scene_file",
]
