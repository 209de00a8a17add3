"""Exports of a front member for a robot controller, at a fixed time step: CSV and ROS
``trajectory_msgs/JointTrajectory`` (JSON, YAML) (:mod:`~adept_traj.export.fixed_step`;
``adept-traj export``). The sampling and the CSV are those of
:mod:`adept_traj.results.fixed_step`, re-exported here, which also writes a result
folder's ``best_trajectory.csv``. The certificate-grid exports (torques, distances) stay in
:mod:`adept_traj.results.ros_export`."""

from __future__ import annotations

from adept_traj.export.fixed_step import (
    FORMATS,
    WRITERS,
    export_member,
    ros_json_text,
    ros_message,
    ros_yaml_text,
)
from adept_traj.results.fixed_step import (
    DEFAULT_DT,
    MAX_SAMPLES,
    FixedStepTrajectory,
    csv_header,
    csv_text,
    file_step,
    fixed_step_times,
    member_spline,
    sample_member,
)

__all__ = [
    "DEFAULT_DT",
    "FORMATS",
    "MAX_SAMPLES",
    "WRITERS",
    "FixedStepTrajectory",
    "csv_header",
    "csv_text",
    "export_member",
    "file_step",
    "fixed_step_times",
    "member_spline",
    "ros_json_text",
    "ros_message",
    "ros_yaml_text",
    "sample_member",
]
