"""Export a trajectory of a planning result: CSV and ROS ``JointTrajectory`` JSON.

- :func:`to_csv` writes a member's trajectory on the certificate's grid (default: the best
  trade-off's certified dense samples, ``result.best_trajectory``) with its torques and
  distances: header ``t, q_<joint>…, qd_<joint>…, qdd_<joint>…, qddd_<joint>…,
  tau_<joint>…, min_distance``, one row per sample of the certificate's grid, floats in
  Python's shortest round-trip form (the format the result folder's
  ``best_trajectory.csv`` had before issue #29; that file is now the fixed-step CSV of
  :mod:`adept_traj.results.fixed_step`, as ``adept-traj export`` writes it).
- :func:`to_ros_joint_trajectory` builds a dictionary shaped like a ROS 2
  ``trajectory_msgs/msg/JointTrajectory`` (``time_from_start`` as
  ``builtin_interfaces/Duration``: ``sec``, ``nanosec``); :func:`save_ros_joint_trajectory`
  writes it as JSON. The move is the best trade-off by default, or any member of the front
  (``member=N``). The points are the best trade-off's stored dense samples, or the spline
  resampled at a given rate (always resampled for another member: only the best trade-off
  stores its dense samples). Units are SI, as ROS expects: rad, m, rad/s, m/s, rad/s²,
  m/s², N·m, N.

Both exports refuse an uncertified member (the best trade-off: ``result.feasible``;
another member: :func:`~adept_traj.results.certified_members`) unless
``allow_infeasible=True``: the file is meant to be sent to a controller. Either way the
ROS output says whether it was certified (``"certified"``, ``"certificate_rate_hz"``; when it
was not, a ``"warning"`` says why) and which member it is (``"member"``,
``"best_tradeoff"``).
Resampling goes through a :class:`~adept_traj.results.Replay` (robot and spline,
built once or handed in), never the full problem. See ``docs/plots-and-export.md`` and
``docs/results.md``.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.certification.certificate import dense_samples
from adept_traj.errors import InvalidInputError
from adept_traj.files import write_text_atomic
from adept_traj.results.csv_codec import csv_text, trajectory_header
from adept_traj.results.members import (
    certified_members,
    member_dense,
    member_index,
    member_replay,
)
from adept_traj.results.record import PlanningResult
from adept_traj.results.replay import Replay
from adept_traj.validation import as_path, as_scalar, check_type

__all__ = [
    "MAX_ROS_POINTS",
    "ros_duration",
    "ros_json_text",
    "save_ros_joint_trajectory",
    "to_csv",
    "to_ros_joint_trajectory",
]

#: Largest number of points :func:`to_ros_joint_trajectory` resamples (T · rate_hz + 1).
MAX_ROS_POINTS = 1_000_000
_NS_PER_S = 1_000_000_000


def _as_result(result: Any) -> PlanningResult:
    check_type(result, PlanningResult, "result")
    return result


# ============================================================================ CSV
def to_csv(
    result: PlanningResult,
    path: str | os.PathLike[str],
    *,
    member: int | None = None,
    allow_infeasible: bool = False,
    replay: Replay | None = None,
) -> Path:
    """Write a member's trajectory (default: the best trade-off) on the certificate's grid
    as CSV, with its jerks, torques and distances (for a fixed step:
    :func:`adept_traj.export.export_member`).

    Columns: ``t`` [s], ``q_<joint>`` [rad | m], ``qd_<joint>`` [rad/s | m/s],
    ``qdd_<joint>`` [rad/s² | m/s²], ``qddd_<joint>`` [rad/s³ | m/s³], ``tau_<joint>``
    [N·m | N], ``min_distance`` [m] (``inf`` when the scene has no obstacle); one row per
    sample of the certificate's grid, values in shortest round-trip form.
    For the best trade-off the rows are its stored dense samples
    (``result.best_trajectory``, as ``result.json`` stores them). For another member they
    are its spline resampled on the same grid (``ceil(T·certificate.rate_hz) + 1``
    samples), torques from the robot's inverse dynamics and exact distances by coal
    (:func:`~adept_traj.results.members.member_dense`).

    Parameters
    ----------
    result: the planning result.
    path: the file to write (folders created, an existing file replaced).
    member: the row of ``result.front`` to export, in [0, ``len(result.front)`` − 1];
        ``None`` (default): the best trade-off, ``result.best.index``.
    allow_infeasible: export even when the member is not certified
        (:func:`~adept_traj.results.certified_members`).
    replay: the :class:`~adept_traj.results.Replay` of the member when the caller has one
        (no robot reload).

    Returns
    -------
    pathlib.Path
        ``path``, the CSV of the member's dense samples.

    Raises
    ------
    InvalidInputError
        ``member`` not an integer in [0, n − 1] (the message names the range); the member
        is not certified and ``allow_infeasible`` is false; ``allow_infeasible`` not a bool;
        ``replay`` not a Replay of the member.
    """
    r = _as_result(result)
    out = as_path(path)
    index = member_index(r, member)
    check_type(allow_infeasible, bool, "allow_infeasible")
    _refuse_uncertified(r, index, allow_infeasible)
    d = member_dense(r, index, replay)
    rows = np.column_stack([d.t, d.q, d.qd, d.qdd, d.qddd, d.tau, d.min_distance])
    return write_text_atomic(out, csv_text(trajectory_header(r.robot.joint_names), rows))


def _refuse_uncertified(r: PlanningResult, index: int, allow_infeasible: bool) -> None:
    """Raise unless member ``index`` is certified or ``allow_infeasible``."""
    if allow_infeasible or certified_members(r)[index]:
        return
    if index == r.best.index:
        detail = "; ".join(r.certificate.violations[:3]) or "see result.certificate"
        raise InvalidInputError(
            "the best trade-off is not verified feasible (" + detail + "); refusing to export "
            "it for a robot controller (pass allow_infeasible=True to export anyway)"
        )
    raise InvalidInputError(
        f"member {index} of the front is not certified: it {_why_not(r)}; refusing to "
        "export it for a robot controller (pass allow_infeasible=True to export anyway)"
    )


# ============================================================================ ROS
def _rate(rate_hz: Any) -> float:
    return as_scalar(rate_hz, "rate_hz", "[Hz]", minimum=0.0, strict=True)


def ros_duration(t: float) -> dict[str, int]:
    """ROS 2 ``builtin_interfaces/Duration`` of ``t`` ≥ 0 [s], rounded to 1 ns:
    ``{"sec": …, "nanosec": …}`` with 0 ≤ nanosec < 10⁹."""
    sec, nanosec = divmod(round(t * _NS_PER_S), _NS_PER_S)
    return {"sec": int(sec), "nanosec": int(nanosec)}


def _resample(r: PlanningResult, index: int, rate: float, replay: Any) -> tuple[np.ndarray, ...]:
    """(t, q, qd, qdd, tau) of member ``index`` on ``ceil(T·rate) + 1`` uniform samples."""
    motion = member_replay(r, index, replay)
    n = dense_samples(motion.duration, rate)  # the grid of analysis.certify
    if n > MAX_ROS_POINTS:
        raise InvalidInputError(
            f"rate_hz = {rate:g} Hz gives {n} points over T = {motion.duration:.6g} s; at "
            f"most {MAX_ROS_POINTS} are exported"
        )
    smp = motion.sample_uniform(n)
    return smp.t, smp.q, smp.qd, smp.qdd, motion.torques(smp)


def _certification(r: PlanningResult, index: int) -> dict[str, Any]:
    """The top-level ``certified``, ``certificate_rate_hz``, ``warning``, ``member`` and
    ``best_tradeoff`` entries."""
    c = r.certificate
    best = index == r.best.index
    certified = bool(certified_members(r)[index])
    warning = None
    if not certified and best:
        found = "; ".join(c.violations) or "see result.certificate"
        warning = (
            f"NOT CERTIFIED: the dense check at {c.rate_hz:g} Hz failed ({found}); exported "
            "with allow_infeasible=True, do not send it to a robot as is"
        )
    elif not certified:
        warning = (
            f"NOT CERTIFIED: member {index} of the front {_why_not(r)}; exported with "
            "allow_infeasible=True, do not send it to a robot as is"
        )
    return {
        "certified": certified,
        "certificate_rate_hz": c.rate_hz,
        "warning": warning,
        "member": index,
        "best_tradeoff": best,
    }


def _why_not(r: PlanningResult) -> str:
    """Why a member other than the best trade-off is not certified."""
    if r.front.n_certified is None:
        return "has no certificate (result saved before every member was certified)"
    return "failed its continuous certificate (run adept-traj verify for the violations)"


def to_ros_joint_trajectory(
    result: PlanningResult,
    *,
    member: int | None = None,
    rate_hz: float | None = None,
    allow_infeasible: bool = False,
    replay: Replay | None = None,
) -> dict[str, Any]:
    """A member's trajectory (default: the best trade-off) as a ROS 2
    ``trajectory_msgs/msg/JointTrajectory`` dictionary, with which member it is and whether
    it was certified.

    Shape::

        {
            "certified": true,
            "certificate_rate_hz": 1000.0,
            "warning": null,
            "member": 5,
            "best_tradeoff": true,
            "header": {"frame_id": ""},
            "joint_names": ["joint1", ...],
            "points": [
                {
                    "positions": [...],
                    "velocities": [...],
                    "accelerations": [...],
                    "effort": [...],
                    "time_from_start": {"sec": 0, "nanosec": 0},
                },
                ...,
            ],
        }

    ``member`` is the row of ``result.front`` exported and ``best_tradeoff`` whether it
    is ``result.best.index``. ``certified`` is, for the best trade-off, ``result.feasible``
    (its dense certificate passed), for another member ``result.front.feasible[member]``
    when every member was certified (``front.n_certified`` set; else false:
    :func:`~adept_traj.results.certified_members`); ``certificate_rate_hz`` is the rate
    [Hz] of the result's certificate. An uncertified export (``allow_infeasible=True``)
    has ``"certified": false`` and a ``warning`` saying why (every violation, for the best
    trade-off); a certified one has ``"warning": null``. These five entries are not fields
    of ``JointTrajectory``: drop them before filling the message.

    ``header.stamp`` is left out (zero: start on receipt). ``time_from_start`` is the
    sample time rounded to the nanosecond, split into whole seconds and nanoseconds
    (0 ≤ nanosec < 10⁹). ROS 1's ``duration`` names the fields ``secs``/``nsecs``.

    Parameters
    ----------
    result: the planning result.
    member: the row of ``result.front`` to export, in [0, ``len(result.front)`` − 1];
        ``None`` (default): the best trade-off, ``result.best.index``.
    rate_hz: ``None`` (default): for the best trade-off, the certificate's dense samples
        (``result.best_trajectory``, ≥ ``certificate.rate_hz``), values exactly as stored;
        for another member (whose dense samples are not stored), its spline resampled at
        ``certificate.rate_hz`` as below.
        A rate [Hz] (> 0): the B-spline of the member resampled on
        ``ceil(T·rate_hz) + 1`` uniform samples over [0, T] (both ends included, spacing
        ≤ 1/rate_hz; the grid of the dense verification), exact positions, velocities and
        accelerations from the spline and efforts from the robot's inverse dynamics.
    allow_infeasible: export even when the member is not certified (the output then says
        ``"certified": false`` and why).
    replay: the :class:`~adept_traj.results.Replay` of the member when the caller has one
        (no robot reload); by default ``Replay.of(result, result.front.x[member])`` is
        built when resampling. Never the full problem.

    Returns
    -------
    A JSON-compatible dictionary (plain ``str``, ``int``, ``float``, ``bool``, ``None``,
    lists; no NaN).

    Raises
    ------
    InvalidInputError
        ``member`` not an integer in [0, n − 1] (the message names the range);
        ``rate_hz`` not a finite number > 0, or more than :data:`MAX_ROS_POINTS` points;
        the member is not certified and ``allow_infeasible`` is false;
        ``allow_infeasible`` not a bool; ``replay`` not a Replay of the member.
    """
    r = _as_result(result)
    index = member_index(r, member)
    check_type(allow_infeasible, bool, "allow_infeasible")
    best = index == r.best.index
    _refuse_uncertified(r, index, allow_infeasible)
    if rate_hz is None and best:
        d = member_dense(r, index, replay)  # the stored certificate samples (replay checked)
        t, q, qd, qdd, tau = d.t, d.q, d.qd, d.qdd, d.tau
    else:
        rate = r.certificate.rate_hz if rate_hz is None else _rate(rate_hz)
        t, q, qd, qdd, tau = _resample(r, index, rate, replay)
    for name, arr in (("q", q), ("qd", qd), ("qdd", qdd), ("tau", tau), ("t", t)):
        if not np.isfinite(arr).all():
            raise InvalidInputError(f"the trajectory's {name} is not finite; cannot export")
    points = [
        {
            "positions": q[k].tolist(),
            "velocities": qd[k].tolist(),
            "accelerations": qdd[k].tolist(),
            "effort": tau[k].tolist(),
            "time_from_start": ros_duration(float(t[k])),
        }
        for k in range(t.shape[0])
    ]
    return {
        **_certification(r, index),
        "header": {"frame_id": ""},
        "joint_names": list(r.robot.joint_names),
        "points": points,
    }


def save_ros_joint_trajectory(
    result: PlanningResult,
    path: str | os.PathLike[str],
    *,
    member: int | None = None,
    rate_hz: float | None = None,
    allow_infeasible: bool = False,
    replay: Replay | None = None,
) -> Path:
    """Write :func:`to_ros_joint_trajectory` as a JSON file (UTF-8, one entry per line and
    one point per line, floats in shortest round-trip form, no NaN); folders are created, an
    existing file replaced. The file starts with ``"certified"``, ``"certificate_rate_hz"``,
    ``"warning"``, ``"member"`` and ``"best_tradeoff"`` (see
    :func:`to_ros_joint_trajectory`).
    Returns the path written. Arguments and errors as :func:`to_ros_joint_trajectory`."""
    out = as_path(path)
    msg = to_ros_joint_trajectory(
        result, member=member, rate_hz=rate_hz, allow_infeasible=allow_infeasible, replay=replay
    )
    return write_text_atomic(out, ros_json_text(msg))


def ros_json_text(message: dict[str, Any]) -> str:
    """A ``JointTrajectory`` dictionary as JSON text: UTF-8, one top-level entry per line and
    one point per line, floats in shortest round-trip form, no NaN (``"points"`` last)."""

    def dump(value: Any) -> str:
        return json.dumps(value, allow_nan=False, ensure_ascii=False)

    head = [f"  {dump(key)}: {dump(value)}," for key, value in message.items() if key != "points"]
    body = ",\n".join(f"    {dump(p)}" for p in message["points"])
    return "\n".join(["{", *head, '  "points": [', body, "  ]", "}"]) + "\n"
