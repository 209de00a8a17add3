"""Planning results: the record, its codecs and the ROS export."""

from __future__ import annotations

from adept_traj.results.record import (
    FORMAT,
    FRONT_FILE,
    NO_FEASIBLE_WARNING,
    RESULT_FILE,
    SHIPPED_ROBOT,
    TRAJECTORY_FILE,
    VERSION,
    BestSolution,
    Front,
    GenerationRecord,
    Metrics,
    PlanningResult,
    ResultFormatError,
    RobotInfo,
    Timing,
    software_versions,
)
from adept_traj.results.replay import (
    Replay,
)
from adept_traj.results.ros_export import (
    MAX_ROS_POINTS,
    save_ros_joint_trajectory,
    to_csv,
    to_ros_joint_trajectory,
)

__all__ = [
    "FORMAT",
    "FRONT_FILE",
    "MAX_ROS_POINTS",
    "NO_FEASIBLE_WARNING",
    "RESULT_FILE",
    "SHIPPED_ROBOT",
    "TRAJECTORY_FILE",
    "VERSION",
    "BestSolution",
    "Front",
    "GenerationRecord",
    "Metrics",
    "PlanningResult",
    "Replay",
    "ResultFormatError",
    "RobotInfo",
    "Timing",
    "save_ros_joint_trajectory",
    "software_versions",
    "to_csv",
    "to_ros_joint_trajectory",
]
