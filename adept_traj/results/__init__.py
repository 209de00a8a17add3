"""Planning results: the record (:mod:`~adept_traj.results.record`, its parts in
:mod:`~adept_traj.results.parts`), its file codecs (:mod:`~adept_traj.results.json_codec`,
:mod:`~adept_traj.results.csv_codec`), the motion built once for viewing
(:mod:`~adept_traj.results.replay`), the choice of a front member
(:mod:`~adept_traj.results.members`) and the ROS export
(:mod:`~adept_traj.results.ros_export`).

The audit behind ``adept-traj verify`` lives in :mod:`adept_traj.certification.audit` (it
reads a :class:`PlanningResult`, so it sits after this package); ``Audit``, ``audit``,
``AUDIT_RTOL`` and ``Mismatch`` are still found here, imported on first use, for code
written before it moved."""

from __future__ import annotations

from adept_traj.errors import ResultFormatError
from adept_traj.lazy_names import lazy_names
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
    "FORMAT",
    "FRONT_FILE",
    "MAX_MEMBER_SAMPLES",
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
    "certified_members",
    "member_dense",
    "member_index",
    "member_replay",
    "save_ros_joint_trajectory",
    "software_versions",
    "to_csv",
    "to_ros_joint_trajectory",
]

#: The names that moved to :mod:`adept_traj.certification` (issue #27), by module.
_MOVED = {
    "Audit": "adept_traj.certification.audit",
    "audit": "adept_traj.certification.audit",
    "AUDIT_RTOL": "adept_traj.certification.mismatches",
    "Mismatch": "adept_traj.certification.mismatches",
}

#: The moved names of :data:`_MOVED`, imported on first use (PEP 562).
__getattr__ = lazy_names(__name__, _MOVED)
