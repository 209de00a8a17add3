"""Exports of a front member for a robot controller, at a fixed time step: CSV and ROS
``trajectory_msgs/JointTrajectory`` (JSON, YAML) (:mod:`~adept_traj.export.fixed_step`;
``adept-traj export``). The certificate-grid exports of earlier versions stay in
:mod:`adept_traj.results.ros_export`."""

from __future__ import annotations

from adept_traj.export.fixed_step import (
    DEFAULT_DT,
    FORMATS,
    MAX_SAMPLES,
    FixedStepTrajectory,
    csv_text,
    export_member,
    fixed_step_times,
    member_spline,
    ros_json_text,
    ros_message,
    ros_yaml_text,
    sample_member,
)

__all__ = [
    "DEFAULT_DT",
    "FORMATS",
    "MAX_SAMPLES",
    "FixedStepTrajectory",
    "csv_text",
    "export_member",
    "fixed_step_times",
    "member_spline",
    "ros_json_text",
    "ros_message",
    "ros_yaml_text",
    "sample_member",
]
