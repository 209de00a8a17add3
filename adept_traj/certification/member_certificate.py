r"""The certificate of every front member, summarised: what ``result.json`` (version 2)
stores for each member as ``front[i].certificate`` and what ``adept-traj front`` lists.

A front member's full :class:`~adept_traj.analysis.Certificate` holds its dense trajectory
(about 50 kB at 1 kHz); a front of 500 members would make ``result.json`` 25 MB. The
:class:`MemberCertificate` keeps the verdict and the numbers a user picks a member by:

- ``feasible``: the certificate passed with the continuous guarantee
  (:attr:`Certificate.certified <adept_traj.analysis.Certificate.certified>`), the member's
  ``front.feasible``;
- ``guarantee`` and ``torque_guarantee``: how the distance and the torque were checked;
- per limit kind (:data:`~adept_traj.robot.limits.LIMIT_KINDS`), the worst value over the
  joints, the joint and the time of its worst dense sample: the position as the fraction
  of the joint range beyond the nearer limit (≤ 0 inside), the others as the ratio to the
  limit (≤ 1 within);
- the smallest distance [m], when [s] and between which solid and obstacle, and the lower
  bound of the distance at every instant;
- with self-collision on, the same for the robot's own solids
  (:class:`~adept_traj.analysis.SelfDistance`: part of ``feasible``).

Every member is certified by :func:`certify_members` on the same problem with the
influence distance lowered to ``margin + 0.01 m`` (``certify(..., exact=False)``): a pair
whose broad-phase lower bound exceeds it keeps that bound instead of a coal call. The
verdict is the one of the exact certificate (every distance at or below the influence is
exact); the smallest distance is exact when it is at most the influence
(``min_distance_exact``), else a lower bound of the true one (the member passes at least
that far from everything). ``adept-traj verify`` recomputes each summary the same way and
compares it field by field.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.certification.certificate import (
    DEFAULT_RATE_HZ,
    Certificate,
    certify_states,
    check_certificate_memory,
)
from adept_traj.certification.continuous import DEFAULT_MAX_DEPTH
from adept_traj.certification.dense_trajectory import batch_samples, dense_samples, dense_states
from adept_traj.certification.limit_check import DEFAULT_TOLERANCE, position_spans
from adept_traj.certification.self_distance import SelfDistance
from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.problem import TrajectoryProblem
from adept_traj.robot.limits import LIMIT_KINDS
from adept_traj.validation import DeepEqual, as_batch, as_integer, as_scalar, check_type

__all__ = [
    "FRONT_INFLUENCE_ABOVE_MARGIN",
    "MemberCertificate",
    "certify_member",
    "certify_members",
    "certifying_problem",
    "checked_members",
]

#: Influence distance above the margin [m] of the front's certificates: the distances at
#: or below ``margin + FRONT_INFLUENCE_ABOVE_MARGIN`` are exact, those above lower bounds.
FRONT_INFLUENCE_ABOVE_MARGIN = 0.01


@dataclass(frozen=True, eq=False)
class MemberCertificate(DeepEqual):
    """The summary of one front member's certificate (module docstring).

    Attributes
    ----------
    feasible: the certificate passed with the continuous guarantee.
    guarantee: the distance's guarantee, ``"continuous"`` or ``"sampled at N Hz"``.
    torque_guarantee: how the torque was checked (``None``: not recorded).
    worst: (5,) the worst value over the joints per limit kind, in the order of
        :data:`~adept_traj.robot.limits.LIMIT_KINDS` (position: fraction of the range beyond
        the nearer limit, ≤ 0 inside; the others: ratio to the limit, ≤ 1 within)
        [dimensionless].
    worst_joint: (5,) the joint index of each worst value.
    t_worst: (5,) time [s] of the worst dense sample of that joint.
    min_distance: the smallest signed distance [m] over the samples and pairs (``inf``: no
        obstacle); exact when ``min_distance_exact``, else a lower bound.
    min_distance_exact: whether :attr:`min_distance` is the exact smallest distance.
    t_min_distance: its time [s] (``None``: no obstacle).
    closest_pair: ``(solid, obstacle)`` at that instant (``None``: no obstacle).
    distance_bound: lower bound [m] of the distance at every instant of [0, T]
        (``None``: not computed; ``inf``: no obstacle).
    violations: every violated limit, as in the certificate.
    self_distance: the robot's distance to itself (``None``: self-collision off).
    """

    feasible: bool
    guarantee: str
    torque_guarantee: str | None
    worst: tuple[float, ...]
    worst_joint: tuple[int, ...]
    t_worst: tuple[float, ...]
    min_distance: float
    min_distance_exact: bool
    t_min_distance: float | None
    closest_pair: tuple[str, str] | None
    distance_bound: float | None
    violations: tuple[str, ...]
    self_distance: SelfDistance | None = None

    def __post_init__(self) -> None:
        check_type(self.feasible, bool, "feasible")
        if self.self_distance is not None:
            check_type(self.self_distance, SelfDistance, "self_distance")
        check_type(self.min_distance_exact, bool, "min_distance_exact")
        for name in ("worst", "worst_joint", "t_worst"):
            values = tuple(getattr(self, name))
            if len(values) != len(LIMIT_KINDS):
                raise InvalidInputError(
                    f"{name} must have one value per limit kind {LIMIT_KINDS}; got {values}"
                )
            object.__setattr__(self, name, values)
        object.__setattr__(self, "violations", tuple(self.violations))
        if self.closest_pair is not None:
            object.__setattr__(self, "closest_pair", tuple(self.closest_pair))

    @classmethod
    def of(cls, certificate: Certificate, influence: float = math.inf) -> MemberCertificate:
        """The summary of ``certificate``, computed with exact distances at or below
        ``influence`` [m] (``inf``: every distance exact)."""
        check_type(certificate, Certificate, "certificate")
        worst, joint, t_worst = [], [], []
        for check in certificate.checks:
            j = int(np.argmax(check.worst))
            worst.append(float(check.worst[j]))
            joint.append(j)
            t_worst.append(float(check.t_worst[j]))
        return cls(
            feasible=certificate.certified,
            guarantee=certificate.guarantee or f"sampled at {certificate.rate_hz:g} Hz",
            torque_guarantee=certificate.torque_guarantee,
            worst=tuple(worst),
            worst_joint=tuple(joint),
            t_worst=tuple(t_worst),
            min_distance=float(certificate.min_distance),
            min_distance_exact=bool(certificate.min_distance <= influence),
            t_min_distance=certificate.t_min_distance,
            closest_pair=certificate.closest_pair,
            distance_bound=certificate.distance_bound,
            violations=certificate.violations,
            self_distance=certificate.self_distance,
        )

    def worst_of(self, kind: str) -> float:
        """The worst value of limit ``kind`` (one of ``LIMIT_KINDS``) over the joints."""
        if kind not in LIMIT_KINDS:
            raise InvalidInputError(f"kind must be one of {LIMIT_KINDS}; got {kind!r}")
        return self.worst[LIMIT_KINDS.index(kind)]

    __hash__ = None  # type: ignore[assignment]


def certify_members(
    problem: TrajectoryProblem,
    x: Any,
    members: Iterable[int] | None = None,
    *,
    rate_hz: float = DEFAULT_RATE_HZ,
    tolerance: float = DEFAULT_TOLERANCE,
) -> tuple[MemberCertificate | None, ...]:
    """Certify the decision vectors ``x`` (n, n_var) with the continuous guarantee and
    summarise each certificate.

    Parameters
    ----------
    problem: the problem the members were planned on (its margin is the one checked).
    x: (n, n_var) decision vectors ``[T [s], free control points]``.
    members: the rows to certify, in this order (default: all); the others get ``None``.
    rate_hz: the dense grid's minimum rate [Hz] (> 0).
    tolerance: slack on the limit values (dimensionless, ≥ 0).

    Returns
    -------
    tuple
        (n,) a :class:`MemberCertificate` per certified row, ``None`` for the others.
    """
    xs, rows, rate = checked_members(problem, x, members, rate_hz)
    tol = as_scalar(tolerance, "tolerance", minimum=0.0)
    out: list[MemberCertificate | None] = [None] * len(xs)
    if not rows:
        return tuple(out)
    bad = [k for k in rows if not xs[k, 0] > 0.0]
    if bad:
        raise InvalidInputError(
            f"x[{bad[0]}, 0] (travel time T [s]) must be > 0; got {xs[bad[0], 0]!r}"
        )
    fast, influence = certifying_problem(problem)
    position_spans(fast.robot.limits)
    for k in rows:  # every member's memory before any is sampled
        check_certificate_memory(fast, rate, float(xs[k, 0]))
    for group in _batches(xs, rows, rate, batch_samples(fast)):
        states = dense_states(fast, xs[group], rate, False)
        for k, dense in zip(group, states):
            certificate = certify_states(
                fast, xs[k], rate, tol, True, DEFAULT_MAX_DEPTH, False, dense
            )
            out[k] = MemberCertificate.of(certificate, influence)
    return tuple(out)


def checked_members(
    problem: Any, x: Any, members: Iterable[int] | None, rate_hz: Any
) -> tuple[np.ndarray, list[int], float]:
    """The input of the front members' certificates, checked: ``problem`` a
    :class:`~adept_traj.problem.TrajectoryProblem`, ``x`` (n, n_var) decision vectors,
    ``members`` rows of ``x`` (``None``: all), ``rate_hz`` [Hz] > 0.

    Returns
    -------
    tuple
        (``x`` as a float array (n, n_var), the rows as integers, the rate [Hz]).

    Raises
    ------
    InvalidInputError
        A value out of its range (:class:`~adept_traj.errors.InputShapeError`: ``x`` of
        another shape).
    """
    check_type(problem, TrajectoryProblem, "problem")
    xs = as_batch(x, "x", problem.n_var)
    if xs.ndim != 2:
        raise InputShapeError(f"x must have shape (n, {problem.n_var}); got {xs.shape}")
    rate = as_scalar(rate_hz, "rate_hz", "[Hz]", minimum=0.0, strict=True)
    rows = range(len(xs)) if members is None else members
    return xs, [as_integer(k, "member", minimum=0, maximum=len(xs) - 1) for k in rows], rate


def certify_member(
    problem: TrajectoryProblem,
    x: Any,
    *,
    rate_hz: float = DEFAULT_RATE_HZ,
    tolerance: float = DEFAULT_TOLERANCE,
) -> tuple[MemberCertificate, Certificate]:
    """The summary of one move's certificate, as :func:`certify_members` makes it (the
    same numbers), and the certificate itself: its dense profile (the distance at every
    sample, the torques) tells a local solver where the move comes closest to failing.

    Parameters
    ----------
    problem: the problem the move was planned on.
    x: (n_var,) decision vector ``[T [s], free control points]``, T > 0.
    rate_hz: the dense grid's minimum rate [Hz] (> 0).
    tolerance: slack on the limit values (dimensionless, ≥ 0).

    Returns
    -------
    tuple
        The :class:`MemberCertificate` and the :class:`~adept_traj.analysis.Certificate`
        of the certifying problem (:func:`certifying_problem`: its distances above the
        influence are lower bounds).
    """
    check_type(problem, TrajectoryProblem, "problem")
    xa = as_batch(x, "x", problem.n_var)
    if xa.ndim != 1:
        raise InputShapeError(f"x must have shape ({problem.n_var},); got {xa.shape}")
    if not xa[0] > 0.0:
        raise InvalidInputError(f"x[0] (travel time T [s]) must be > 0; got {xa[0]!r}")
    rate = as_scalar(rate_hz, "rate_hz", "[Hz]", minimum=0.0, strict=True)
    tol = as_scalar(tolerance, "tolerance", minimum=0.0)
    fast, influence = certifying_problem(problem)
    position_spans(fast.robot.limits)
    check_certificate_memory(fast, rate, float(xa[0]))
    dense = dense_states(fast, xa[None], rate, False)[0]
    certificate = certify_states(fast, xa, rate, tol, True, DEFAULT_MAX_DEPTH, False, dense)
    return MemberCertificate.of(certificate, influence), certificate


def _batches(xs: np.ndarray, rows: list[int], rate_hz: float, most: int) -> list[list[int]]:
    """``rows`` in order, cut into runs whose dense samples at ``rate_hz`` [Hz] add up to at
    most ``most`` (:func:`~adept_traj.certification.dense_trajectory.batch_samples`; a longer move
    alone)."""
    batches: list[list[int]] = []
    total = most + 1
    for k in rows:
        n = dense_samples(float(xs[k, 0]), rate_hz)
        if total + n > most:
            batches.append([])
            total = 0
        batches[-1].append(k)
        total += n
    return batches


def certifying_problem(problem: TrajectoryProblem) -> tuple[TrajectoryProblem, float]:
    """The problem :func:`certify_members` certifies on, and its influence distance [m]:
    ``problem`` with the influence lowered to ``margin +`` :data:`FRONT_INFLUENCE_ABOVE_MARGIN`
    (never raised; a pair whose broad-phase bound exceeds it needs no coal call, which
    makes a front's certificates much cheaper than with the default 0.05 m).

    Made once per ``problem`` and kept on it (:meth:`~adept_traj.problem.TrajectoryProblem.derived`:
    the problem is frozen, so the same object is returned again; it evaluates in one
    process and, like ``problem`` itself, is not for use from several threads at once). A
    caller about to fork certifying processes calls it first, so that they share it.
    """
    check_type(problem, TrajectoryProblem, "problem")
    key = "analysis.member_certificate.certifying"
    fast, influence = problem.derived(key, _certifying_problem)
    return (problem if fast is None else fast), influence


def _certifying_problem(problem: TrajectoryProblem) -> tuple[TrajectoryProblem | None, float]:
    """:func:`certifying_problem`, made (``None``: ``problem`` itself, which does not hold
    itself)."""
    st = problem.settings
    influence = min(st.influence, st.margin + FRONT_INFLUENCE_ABOVE_MARGIN)
    if influence == st.influence:
        return None, influence
    # the certificate checks the true margin: the search buffer is unused
    fast = problem.replace(influence=influence, search_buffer=0.0, workers=1)
    return fast, influence
