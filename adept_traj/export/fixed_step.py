r"""A front member's move at a fixed time step, for a controller: CSV and ROS
``trajectory_msgs/JointTrajectory`` (JSON, YAML).

The samples are taken exactly from the member's B-spline
(:class:`~adept_traj.problem.BSplineTrajectory` of the result's start, goal and knots:
the closed form of the uniform cubic B-spline, no interpolation; no robot file is read) at
the times

.. math::

    t_k = k \, \Delta t \quad (k = 0, 1, \dots,\ k\,\Delta t < T - 10^{-9}\Delta t),
    \qquad t_\text{last} = T,

so every step is exactly ``dt`` but the last one, which is at most ``dt`` (and more than
:math:`10^{-9}\Delta t`): the move ends at rest at ``T``, on the goal. With the default
``dt = 0.001 s`` a move of T = 2.1 s has 2 101 samples, t = 0, 0.001, …, 2.099, 2.1.

Formats (:data:`FORMATS`):

- ``csv``: header ``t,q_<joint>…,qd_<joint>…,qdd_<joint>…``, one row per sample, floats in
  Python's shortest round-trip form; units s; rad | m; rad/s | m/s; rad/s² | m/s².
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
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.files import write_text_atomic
from adept_traj.problem import BSplineTrajectory
from adept_traj.results import PlanningResult, certified_members, member_index
from adept_traj.validation import as_scalar, check_type, readonly_copy

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

#: Default time step [s] of the exports (1 kHz).
DEFAULT_DT = 0.001
#: The export formats, as ``adept-traj export --format`` names them.
FORMATS = ("csv", "ros-json", "ros-yaml")
#: Largest number of samples of one export.
MAX_SAMPLES = 1_000_000
#: Relative tolerance [·dt] under which the last grid time counts as T itself.
_END_TOLERANCE = 1e-9
_NS_PER_S = 1_000_000_000


def fixed_step_times(T: float, dt: float) -> np.ndarray:
    r"""The times [s] of a fixed-step export of a move of duration ``T`` [s]:
    :math:`t_k = k\,\Delta t` while :math:`k\,\Delta t < T - 10^{-9}\Delta t`, then ``T``.

    Parameters
    ----------
    T: travel time [s], > 0.
    dt: time step [s], in [T / (MAX_SAMPLES − 1), T].

    Returns
    -------
    (n,) strictly increasing times, ``t[0] = 0``, ``t[-1] = T``, every step ``dt`` but the
    last (in (0, dt]).

    Raises
    ------
    InvalidInputError
        ``T`` not finite > 0; ``dt`` not a finite number in the range above (the message
        names the value and the range).
    """
    T = as_scalar(T, "T", "[s]", minimum=0.0, strict=True)
    step = as_scalar(dt, "dt", "[s]", minimum=0.0, strict=True)
    smallest = T / (MAX_SAMPLES - 1)
    if not smallest <= step <= T:
        raise InvalidInputError(
            f"dt = {step:g} s is out of range: it must lie in [T/{MAX_SAMPLES - 1} = "
            f"{smallest:.3g} s, T = {T:.6g} s] for this move (T its travel time; at most "
            f"{MAX_SAMPLES} samples)"
        )
    k = math.ceil(T / step - _END_TOLERANCE)  # grid times k·dt < T − tol·dt: 0 … k − 1
    grid = np.arange(k, dtype=np.float64) * step
    grid = grid[grid < T - _END_TOLERANCE * step]
    return np.append(grid, T)


@dataclass(frozen=True)
class FixedStepTrajectory:
    """A member's move sampled at a fixed step (module docstring).

    Attributes
    ----------
    member: the row of ``result.front``.
    best_tradeoff: whether it is ``result.best.index``.
    certified: whether the member is certified (:func:`~adept_traj.results.certified_members`).
    dt: the time step [s].
    joint_names: the joints, in the order of the columns of ``q``.
    t: (n,) times [s] (:func:`fixed_step_times`).
    q, qd, qdd: (n, nq) positions [rad | m], velocities [rad/s | m/s] and accelerations
        [rad/s² | m/s²], exactly from the B-spline.
    """

    member: int
    best_tradeoff: bool
    certified: bool
    dt: float
    joint_names: tuple[str, ...]
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray

    def __post_init__(self) -> None:
        for name in ("t", "q", "qd", "qdd"):
            object.__setattr__(self, name, readonly_copy(np.asarray(getattr(self, name))))
        object.__setattr__(self, "joint_names", tuple(self.joint_names))


def sample_member(
    result: PlanningResult,
    member: int | None = None,
    *,
    dt: float = DEFAULT_DT,
    allow_uncertified: bool = False,
) -> FixedStepTrajectory:
    """Sample member ``member`` of ``result.front`` (default: the best trade-off) at the
    fixed step ``dt``.

    Parameters
    ----------
    result: the planning result.
    member: a row of ``result.front`` in [0, n − 1]; ``None``: ``result.best.index``.
    dt: time step [s] (default 1 ms), in [T/(MAX_SAMPLES − 1), T] (:func:`fixed_step_times`).
    allow_uncertified: sample a member that is not certified too.

    Returns
    -------
    :class:`FixedStepTrajectory`.

    Raises
    ------
    InvalidInputError
        ``member`` not an integer in [0, n − 1]; ``dt`` out of range; the member is not
        certified and ``allow_uncertified`` is false (the message says why and how to
        export it anyway).
    """
    check_type(result, PlanningResult, "result")
    index = member_index(result, member)
    check_type(allow_uncertified, bool, "allow_uncertified")
    T = float(result.front.x[index, 0])
    times = fixed_step_times(T, dt)  # bad dt refused before anything is loaded
    certified = bool(certified_members(result)[index])
    if not certified and not allow_uncertified:
        raise InvalidInputError(
            f"member {index} of the front is not certified ({_why_not(result, index)}); "
            "refusing to export it for a robot controller (allow_uncertified=True, or "
            "--allow-uncertified, exports it anyway)"
        )
    spline = member_spline(result)
    s = np.clip(times / T, 0.0, 1.0)
    smp = spline.sample(result.front.x[index], s, orders=(0, 1, 2))
    return FixedStepTrajectory(
        member=index,
        best_tradeoff=index == result.best.index,
        certified=certified,
        dt=float(dt),
        joint_names=tuple(result.robot.joint_names),
        t=times,
        q=smp.q,
        qd=smp.qd,
        qdd=smp.qdd,
    )


def member_spline(result: PlanningResult) -> BSplineTrajectory:
    """The :class:`~adept_traj.problem.BSplineTrajectory` of ``result``'s moves (its start,
    goal and knot count): ``member_spline(r).sample(r.front.x[i], s)`` samples member i."""
    check_type(result, PlanningResult, "result")
    n_knots = int(result.problem_settings.n_knots)
    return BSplineTrajectory(result.start, result.goal, n_knots=n_knots)


def _why_not(result: PlanningResult, index: int) -> str:
    if index == result.best.index:
        return "its dense certificate failed: " + (
            "; ".join(result.certificate.violations[:3]) or "see adept-traj verify"
        )
    if result.front.n_certified is None:
        return "the result was saved before every member was certified"
    return "it failed its certificate; adept-traj verify lists the violations"


# ============================================================================ formats
def csv_text(trajectory: FixedStepTrajectory) -> str:
    """The CSV text: header ``t,q_<joint>…,qd_<joint>…,qdd_<joint>…``, one row per sample,
    shortest round-trip floats, ``\\n`` line ends."""
    check_type(trajectory, FixedStepTrajectory, "trajectory")
    names = trajectory.joint_names
    header = ["t", *(f"{p}_{n}" for p in ("q", "qd", "qdd") for n in names)]
    rows = np.column_stack([trajectory.t, trajectory.q, trajectory.qd, trajectory.qdd])
    lines = [",".join(header)]
    lines.extend(",".join(map(repr, row)) for row in rows.tolist())
    return "\n".join(lines) + "\n"


def _duration(t: float) -> dict[str, int]:
    """ROS 2 ``builtin_interfaces/Duration`` of ``t`` ≥ 0 [s], rounded to 1 ns."""
    sec, nanosec = divmod(round(t * _NS_PER_S), _NS_PER_S)
    return {"sec": int(sec), "nanosec": int(nanosec)}


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
            "time_from_start": _duration(t),
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
    """:func:`ros_message` as JSON: one entry per line, one point per line."""
    msg = ros_message(trajectory)
    head = [f"  {_json(k)}: {_json(v)}," for k, v in msg.items() if k != "points"]
    body = ",\n".join(f"    {_json(p)}" for p in msg["points"])
    return "\n".join(["{", *head, '  "points": [', body, "  ]", "}"]) + "\n"


def ros_yaml_text(trajectory: FixedStepTrajectory) -> str:
    """:func:`ros_message` as YAML (block mappings, one flow mapping per point; the JSON
    scalars are valid YAML 1.2 scalars), e.g. for ``ros2 topic pub`` or a launch file."""
    msg = ros_message(trajectory)
    lines = [f"{k}: {_json(v)}" for k, v in msg.items() if k not in ("header", "points")]
    lines += ["header:", '  frame_id: ""', "points:"]
    lines += [f"  - {_json(p)}" for p in msg["points"]]
    return "\n".join(lines) + "\n"


_WRITERS = {"csv": csv_text, "ros-json": ros_json_text, "ros-yaml": ros_yaml_text}


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

    Returns the path written. Arguments and errors as :func:`sample_member`, and
    :class:`~adept_traj.errors.InvalidInputError` for a ``format`` not in :data:`FORMATS`
    or a ``path`` that is not a path.
    """
    if format not in _WRITERS:
        raise InvalidInputError(f"format must be one of {', '.join(FORMATS)}; got {format!r}")
    try:
        out = Path(os.fspath(path))
    except TypeError:
        raise InvalidInputError(f"path must be a file path; got {type(path).__name__}") from None
    tr = sample_member(result, member, dt=dt, allow_uncertified=allow_uncertified)
    return write_text_atomic(out, _WRITERS[format](tr))
