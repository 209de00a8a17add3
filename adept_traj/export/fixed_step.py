r"""A front member's move at a fixed time step, for a controller: CSV and ROS
``trajectory_msgs/JointTrajectory`` (JSON, YAML).

The samples and the CSV are those of :mod:`adept_traj.results.fixed_step` (re-exported by
:mod:`adept_traj.export`), the one mechanism that also writes the result folder's
``best_trajectory.csv``: exactly from the member's B-spline at

.. math::

    t_k = k \, \Delta t \quad (k = 0, 1, \dots,\ k\,\Delta t < T - 10^{-9}\Delta t),
    \qquad t_\text{last} = T,

every step exactly ``dt`` but the last one, which is at most ``dt``: the last sample is the
move's end at rest, at ``T``, on the goal. With the default ``dt = 0.001 s`` a move of
T = 2.1 s has 2 101 samples, t = 0, 0.001, …, 2.099, 2.1.

Formats (:data:`FORMATS`):

- ``csv``: header ``t [s],q_<joint> [rad|m]…,qd_<joint> [rad/s|m/s]…,
  qdd_<joint> [rad/s^2|m/s^2]…`` (:func:`~adept_traj.results.fixed_step.csv_header`), one
  row per sample, floats in Python's shortest round-trip form; for the best trade-off at
  the default step, byte-identical to the result folder's ``best_trajectory.csv``.
- ``ros-json`` and ``ros-yaml``: a ROS 2 ``trajectory_msgs/msg/JointTrajectory``:
  ``header.frame_id`` (empty), ``joint_names``, ``points[k]`` with ``positions``,
  ``velocities``, ``accelerations`` and ``time_from_start`` (``sec``, ``nanosec``, the time
  rounded to 1 ns), preceded by entries that are not message fields: ``certified``,
  ``member``, ``best_tradeoff``, ``dt`` [s] and ``warning`` (``null`` when certified).

An uncertified member (:func:`~adept_traj.results.certified_members`) is refused unless
``allow_uncertified=True``: the file is meant for a robot controller.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from adept_traj.errors import InvalidInputError
from adept_traj.files import write_text_atomic
from adept_traj.results import PlanningResult
from adept_traj.results.fixed_step import (
    DEFAULT_DT,
    FixedStepTrajectory,
    csv_text,
    sample_member,
)
from adept_traj.results.ros_export import ros_duration
from adept_traj.results.ros_export import ros_json_text as _message_json
from adept_traj.validation import as_path, check_type

__all__ = [
    "FORMATS",
    "WRITERS",
    "export_member",
    "ros_json_text",
    "ros_message",
    "ros_yaml_text",
]

#: The export formats, as ``adept-traj export --format`` names them.
FORMATS = ("csv", "ros-json", "ros-yaml")


def ros_message(trajectory: FixedStepTrajectory) -> dict[str, Any]:
    """The ``trajectory_msgs/msg/JointTrajectory`` dictionary (module docstring), with the
    entries ``certified``, ``member``, ``best_tradeoff``, ``dt`` and ``warning`` first
    (not message fields: drop them before filling the message)."""
    check_type(trajectory, FixedStepTrajectory, "trajectory")
    tr = trajectory
    warning = (
        None
        if tr.certified
        else f"NOT CERTIFIED: member {tr.member} was exported with allow_uncertified; "
        "do not send it to a robot as is"
    )
    q, qd, qdd = tr.q.tolist(), tr.qd.tolist(), tr.qdd.tolist()
    points = [
        {
            "positions": q[k],
            "velocities": qd[k],
            "accelerations": qdd[k],
            "time_from_start": ros_duration(t),
        }
        for k, t in enumerate(tr.t.tolist())
    ]
    return {
        "certified": tr.certified,
        "member": tr.member,
        "best_tradeoff": tr.best_tradeoff,
        "dt": tr.dt,
        "warning": warning,
        "header": {"frame_id": ""},
        "joint_names": list(tr.joint_names),
        "points": points,
    }


def _json(value: Any) -> str:
    return json.dumps(value, allow_nan=False, ensure_ascii=False)


def ros_json_text(trajectory: FixedStepTrajectory) -> str:
    """:func:`ros_message` as JSON: one entry per line, one point per line (the layout of
    :func:`~adept_traj.results.save_ros_joint_trajectory`)."""
    return _message_json(ros_message(trajectory))


def ros_yaml_text(trajectory: FixedStepTrajectory) -> str:
    """:func:`ros_message` as YAML (block mappings, one flow mapping per point; the JSON
    scalars are valid YAML 1.2 scalars), e.g. for ``ros2 topic pub`` or a launch file."""
    msg = ros_message(trajectory)
    lines = [f"{k}: {_json(v)}" for k, v in msg.items() if k not in ("header", "points")]
    lines += ["header:", '  frame_id: ""', "points:"]
    lines += [f"  - {_json(p)}" for p in msg["points"]]
    return "\n".join(lines) + "\n"


#: The text of each format, from a :class:`FixedStepTrajectory`.
WRITERS = {"csv": csv_text, "ros-json": ros_json_text, "ros-yaml": ros_yaml_text}


def export_member(
    result: PlanningResult,
    path: str | os.PathLike[str],
    *,
    member: int | None = None,
    format: str = "csv",
    dt: float = DEFAULT_DT,
    allow_uncertified: bool = False,
) -> Path:
    """Write member ``member`` (default: the best trade-off) at the fixed step ``dt`` in
    ``format`` (one of :data:`FORMATS`) to ``path`` (folders created, a file replaced).

    Returns the path written. Arguments and errors as
    :func:`~adept_traj.results.fixed_step.sample_member`, and
    :class:`~adept_traj.errors.InvalidInputError` for a ``format`` not in :data:`FORMATS`
    or a ``path`` that is not a path.
    """
    if format not in WRITERS:
        raise InvalidInputError(f"format must be one of {', '.join(FORMATS)}; got {format!r}")
    out = as_path(path)
    tr = sample_member(result, member, dt=dt, allow_uncertified=allow_uncertified)
    return write_text_atomic(out, WRITERS[format](tr))
