r"""A front member's move sampled at a fixed time step, and its CSV: the one mechanism behind
the result folder's ``best_trajectory.csv`` and ``adept-traj export --format csv``.

The samples are taken exactly from the member's B-spline
(:class:`~adept_traj.problem.BSplineTrajectory` of the result's start, goal and knots: the
closed form of the uniform cubic B-spline, no interpolation; no robot file is read) at the
times

.. math::

    t_k = k \, \Delta t \quad (k = 0, 1, \dots,\ k\,\Delta t < T - 10^{-9}\Delta t),
    \qquad t_\text{last} = T,

so every step is ``dt`` but the last one, which is at most ``dt`` (and more than
:math:`10^{-9}\Delta t`): the last row is the move's end at rest, at ``T``, on the goal.
Each :math:`t_k` is the double nearest to k times the decimal ``dt`` reads as, so the times
read as written (``1.396``, not the ``1.3960000000000001`` of the product of doubles).
With the default ``dt = 0.001 s`` a move of T = 2.1 s has 2 101 samples, t = 0, 0.001, …,
2.099, 2.1; one of T = 1.0765 s has 1 078, the last step 0.0005 s.

The CSV (:func:`csv_text`): a header naming each column and its unit (:func:`csv_header`),
``t [s]``, ``q_<joint> [rad]`` (``[m]`` for a prismatic joint), ``qd_<joint> [rad/s]``,
``qdd_<joint> [rad/s^2]``, then one row per sample, floats in Python's shortest
round-trip form, ``\n`` line ends.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from decimal import Decimal

import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.problem import BSplineTrajectory
from adept_traj.results.members import certified_members, member_index
from adept_traj.results.record import PlanningResult
from adept_traj.validation import as_scalar, check_type, readonly_copy

__all__ = [
    "DEFAULT_DT",
    "MAX_SAMPLES",
    "FixedStepTrajectory",
    "csv_header",
    "csv_text",
    "file_step",
    "fixed_step_times",
    "member_spline",
    "sample_member",
]

#: Default time step [s] of the exports and of ``best_trajectory.csv`` (1 kHz).
DEFAULT_DT = 0.001
#: Largest number of samples of one export.
MAX_SAMPLES = 1_000_000
#: Relative tolerance [·dt] under which the last grid time counts as T itself.
_END_TOLERANCE = 1e-9
#: Integers up to 2^53 are exact in doubles.
_EXACT = 2**53
#: The derivative prefixes of the CSV's joint columns and the time power of their units.
_QUANTITIES = (("q", ""), ("qd", "/s"), ("qdd", "/s^2"))


def fixed_step_times(T: float, dt: float) -> np.ndarray:
    r"""The times [s] of a fixed-step sampling of a move of duration ``T`` [s]:
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
    grid = _multiples(step, k)
    grid = grid[grid < T - _END_TOLERANCE * step]
    return np.append(grid, T)


def _multiples(step: float, n: int) -> np.ndarray:
    """(n,) the times k·``step``, k = 0 … n − 1 [s], each the double nearest to k times the
    decimal that ``step`` reads as (``repr``: 0.001 → 1/1000), so that they read as the
    user writes them (1396 · 0.001 → ``1.396``, where the product of doubles gives
    ``1.3960000000000001``): (k · m) / 10^e of exact integers, one correctly rounded
    division. Where that is not exact in doubles (m·(n − 1) or 10^e ≥ 2^53), k · step.
    The explorer page computes the same (``multiples`` in its script)."""
    _, digits, exponent = Decimal(repr(step)).as_tuple()
    m = int("".join(map(str, digits)))
    num, den = (m * 10**exponent, 1) if exponent >= 0 else (m, 10**-exponent)
    if den <= _EXACT and num * max(n - 1, 1) <= _EXACT:
        return (np.arange(n, dtype=np.int64) * num) / den
    return np.arange(n, dtype=np.float64) * step


def file_step(T: float) -> float:
    """The step [s] of ``best_trajectory.csv`` for a move of ``T`` [s]: :data:`DEFAULT_DT`,
    or ``T`` for a move shorter than it, or ``T / (MAX_SAMPLES − 1)`` for one longer than
    ``(MAX_SAMPLES − 1) · DEFAULT_DT`` (1 000 s)."""
    T = as_scalar(T, "T", "[s]", minimum=0.0, strict=True)
    return min(max(DEFAULT_DT, T / (MAX_SAMPLES - 1)), T)


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
    units: the unit of each joint's position, ``"rad"`` or ``"m"`` (``result.limits.units``).
    t: (n,) times [s] (:func:`fixed_step_times`).
    q, qd, qdd: (n, nq) positions [rad | m], velocities [rad/s | m/s] and accelerations
        [rad/s² | m/s²], exactly from the B-spline.
    """

    member: int
    best_tradeoff: bool
    certified: bool
    dt: float
    joint_names: tuple[str, ...]
    units: tuple[str, ...]
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray

    def __post_init__(self) -> None:
        for name in ("t", "q", "qd", "qdd"):
            object.__setattr__(self, name, readonly_copy(np.asarray(getattr(self, name))))
        object.__setattr__(self, "joint_names", tuple(self.joint_names))
        object.__setattr__(self, "units", tuple(self.units))
        if len(self.units) != len(self.joint_names):
            raise InvalidInputError(
                f"units must name one unit per joint ({len(self.joint_names)}); "
                f"got {len(self.units)}"
            )


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
    dt: time step [s] (default 0.001 s), in [T/(MAX_SAMPLES − 1), T] (:func:`fixed_step_times`).
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
    times = fixed_step_times(T, dt)  # bad dt refused before anything is sampled
    certified = bool(certified_members(result)[index])
    if not certified and not allow_uncertified:
        raise InvalidInputError(
            f"member {index} of the front is not certified ({_why_not(result, index)}); "
            "refusing to export it for a robot controller (allow_uncertified=True, or "
            "--allow-uncertified, exports it anyway)"
        )
    s = np.clip(times / T, 0.0, 1.0)
    smp = member_spline(result).sample(result.front.x[index], s, orders=(0, 1, 2))
    return FixedStepTrajectory(
        member=index,
        best_tradeoff=index == result.best.index,
        certified=certified,
        dt=float(dt),
        joint_names=tuple(result.robot.joint_names),
        units=tuple(result.limits.units),
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


def csv_header(joint_names: Sequence[str], units: Sequence[str]) -> list[str]:
    """The CSV's column names with their units: ``t [s]``, then ``q_<joint> [u]``,
    ``qd_<joint> [u/s]``, ``qdd_<joint> [u/s^2]`` for every joint, ``u`` its position unit
    (``"rad"`` or ``"m"``)."""
    if len(joint_names) != len(units):
        raise InvalidInputError(
            f"one unit per joint: {len(joint_names)} joints, {len(units)} units"
        )
    return [
        "t [s]",
        *(f"{p}_{n} [{u}{per}]" for p, per in _QUANTITIES for n, u in zip(joint_names, units)),
    ]


def csv_text(trajectory: FixedStepTrajectory) -> str:
    """The CSV text: :func:`csv_header`, one row per sample (t, q, qd, qdd), shortest
    round-trip floats, ``\\n`` line ends."""
    check_type(trajectory, FixedStepTrajectory, "trajectory")
    tr = trajectory
    rows = np.column_stack([tr.t, tr.q, tr.qd, tr.qdd])
    lines = [",".join(csv_header(tr.joint_names, tr.units))]
    lines.extend(",".join(map(repr, row)) for row in rows.tolist())
    return "\n".join(lines) + "\n"
