"""Planning results: the record (:mod:`~adept_traj.results.record`, its parts in
:mod:`~adept_traj.results.parts`), its file codecs (:mod:`~adept_traj.results.json_codec`,
:mod:`~adept_traj.results.csv_codec`), the motion built once for viewing
(:mod:`~adept_traj.results.replay`), the choice of a front member
(:mod:`~adept_traj.results.members`) and the ROS export
(:mod:`~adept_traj.results.ros_export`)."""

from __future__ import annotations

from adept_traj.certification.audit import Audit, audit
from adept_traj.certification.mismatches import AUDIT_RTOL, Mismatch
from adept_traj.errors import ResultFormatError
from adept_traj.results.members import (
    MAX_MEMBER_SAMPLES,
    certified_members,
    member_dense,
    member_index,
    member_replay,
)
from adept_traj.results.parts import (
    SHIPPED_ROBOT,
    BestSolution,
    Front,
    GenerationRecord,
    Metrics,
    RobotInfo,
    Timing,
    software_versions,
)
from adept_traj.results.record import (
    FORMAT,
    FRONT_FILE,
    NO_FEASIBLE_WARNING,
    RESULT_FILE,
    TRAJECTORY_FILE,
    VERSION,
    PlanningResult,
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
    "AUDIT_RTOL",
    "FORMAT",
    "FRONT_FILE",
    "MAX_MEMBER_SAMPLES",
    "MAX_ROS_POINTS",
    "NO_FEASIBLE_WARNING",
    "RESULT_FILE",
    "SHIPPED_ROBOT",
    "TRAJECTORY_FILE",
    "VERSION",
    "Audit",
    "BestSolution",
    "Front",
    "GenerationRecord",
    "Metrics",
    "Mismatch",
    "PlanningResult",
    "Replay",
    "ResultFormatError",
    "RobotInfo",
    "Timing",
    "audit",
    "certified_members",
    "member_dense",
    "member_index",
    "member_replay",
    "save_ros_joint_trajectory",
    "software_versions",
    "to_csv",
    "to_ros_joint_trajectory",
]
