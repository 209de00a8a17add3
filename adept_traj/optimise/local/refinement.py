r"""The certified local solver: the fastest move of a start's basin, ending certified.

:func:`refine_minimum_time` solves, from a start :math:`x_0`,

.. math::
    \min_{x = [T, P]} T \quad \text{s.t.} \quad g_k(x) \le 0 \ \ \forall k \in K, \qquad
    x_l \le x \le x_u,

with the smooth per-sample rows :math:`g_k` of :func:`~adept_traj.problem.local_constraints`
(velocity, acceleration, jerk at their exact grids; torque and distance at the problem's
samples **and at adaptive samples** :math:`K_a`), and ends with the move its certificate
(:func:`~adept_traj.analysis.certify_member`, 1 kHz with the continuous distance bound)
accepts. Rounds:

1. **Solve** the sampled problem by SQP in trust boxes (below) from the current point.
2. **Certify** the solve's answer (T raised to the spline's exact kinematic minimum,
   :func:`~adept_traj.optimise.kinematic_time`). Certified: done — the feasible set of
   the continuous problem lies inside the sampled one, so a certified optimum of the
   sampled problem is one of the continuous problem.
3. Otherwise **add samples** where the certificate's dense distance comes within
   :data:`DIP_WINDOW` of the margin — a grid of step :data:`DIP_STEP` (normalised time)
   over each such window, its local minima below the margin plus :data:`DIP_TOLERANCE`,
   and the instant of the smallest distance — and where the dense torque exceeds
   :math:`(1 - \text{tolerance})\,UC`, at the normalised times :math:`s = t / T` of the
   failing move, and solve again from it. A fast move near a thin moving obstacle (the
   pendulum's rod) passes between the problem's 116 samples closer than at them; the new
   rows stop exactly that, and a window sampled finer than the problem's grid lets the
   solver slide past the obstacle instead of stepping back in T (measured on the detour
   scene from the fixed-obstacle optimum: one sample per dip ends at 1.1145 s, windows of
   step 0.005 at 1.0985–1.1023 s; ``docs/detour-scene.md``). The start's own certificate
   seeds these samples before the first solve.
4. A round that finds nothing new to sample (the failure is elsewhere: a self-distance, a
   pair the rows do not model) raises an extra distance buffer, :data:`BUFFERS` in turn —
   the last resort.

The returned move is the fastest certified one met (the start itself when it is certified
and nothing faster is): **never worse than a certified start, and never uncertified when
the start was certified**.

The solve is :func:`~adept_traj.optimise.local.trust_box.trust_box_solve` (an SQP,
:func:`~adept_traj.optimise.local.sqp.sqp`, over the whole domain, then in elastic trust boxes;
its module says why). A start outside the rows (the
straight move through an obstacle) is solved from too; a refinement that finds no point
inside the rows ends at once with the start (``certified`` False).

Everything is deterministic (one BLAS thread): the same problem and start give the same
move.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.certification.member_certificate import (
    MemberCertificate,
    certify_member,
    certifying_problem,
)
from adept_traj.errors import ConfigurationError
from adept_traj.optimise.local.minimum_time import at_kinematic_minimum
from adept_traj.optimise.local.trust_box import SolveCounts, trust_box_solve
from adept_traj.process_pool import map_forked
from adept_traj.robot.limits import LIMITS
from adept_traj.validation import as_integer, as_scalar, as_vector

__all__ = [
    "BUFFERS",
    "DIP_STEP",
    "DIP_TOLERANCE",
    "DIP_WINDOW",
    "MAX_EXTRA_SAMPLES",
    "NO_MOVE_INSIDE",
    "SCREEN_BOXES",
    "SCREEN_KEEP",
    "Refinement",
    "refine_minimum_time",
    "refine_starts",
    "screen_starts",
]

#: Distance [m] above the margin below which a dip of the certificate's dense distance
#: becomes a constraint sample.
DIP_TOLERANCE = 0.002

#: Distance [m] above the margin within which the certificate's dense distance makes a
#: window of constraint samples, and their step [normalised time] (finer than the
#: problem's grid of 116 samples, step ≈ 0.0087).
DIP_WINDOW, DIP_STEP = 0.005, 0.005

#: Extra distance buffers [m] of the solves, raised in turn only when a failing move
#: shows no new place to sample (the last resort).
BUFFERS: tuple[float, ...] = (0.0, 0.002, 0.005, 0.01)

#: The message of a refinement that found no point inside the sampled constraints.
NO_MOVE_INSIDE = "no move inside the sampled constraints found"

#: Trust boxes of a screening refinement (:func:`screen_starts`), and how many of the
#: screened moves :func:`refine_starts` refines to the end.
SCREEN_BOXES, SCREEN_KEEP = 3, 2

#: Most adaptive samples of one refinement (each adds one distance row per obstacle and
#: two torque rows per joint).
MAX_EXTRA_SAMPLES = 400

#: Samples closer than this (normalised time) to an existing one are not added.
_SAMPLE_GAP = 2e-4


@dataclass(frozen=True)
class Refinement:
    """One certified local solve (:func:`refine_minimum_time`).

    Attributes
    ----------
    x: (n_var,) the returned move: the fastest certified one met, else the solve's last.
    objectives: (6,) its z1…z6 by the problem's evaluator.
    constraints: (n_constr,) its evaluator constraints.
    feasible: every evaluator constraint ≤ 0 (the population's verdict).
    certified: it passed its certificate (``certificate.feasible``).
    certificate: the summary of its certificate (as :func:`certify_members` makes it).
    start: (n_var,) the start.
    start_certified: whether the start passed its certificate.
    start_certificate: the summary of the start's certificate.
    n_rounds: certify-and-resample rounds.
    n_iterations: SQP iterations, all rounds and boxes.
    n_evaluations: constraint-and-Jacobian evaluations plus evaluator calls.
    extra_samples: (k,) the adaptive samples [normalised time] of the last solve.
    buffer: the extra distance buffer [m] of the last solve.
    seconds: wall time [s].
    evaluation_s: the part spent evaluating rows, Jacobians and moves [s].
    message: how the refinement ended.
    """

    x: np.ndarray
    objectives: np.ndarray
    constraints: np.ndarray
    feasible: bool
    certified: bool
    certificate: MemberCertificate
    start: np.ndarray
    start_certified: bool
    start_certificate: MemberCertificate
    n_rounds: int
    n_iterations: int
    n_evaluations: int
    extra_samples: np.ndarray
    buffer: float
    seconds: float
    evaluation_s: float
    message: str


def refine_minimum_time(
    problem: Any,
    x0: Any,
    *,
    rate_hz: float = 1000.0,
    max_rounds: int = 8,
    max_boxes: int = 40,
    start_certificate: MemberCertificate | None = None,
    extra_samples: Any = None,
) -> Refinement:
    """The fastest certified move from ``x0`` (see the module docstring).

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    x0:
        (n_var,) start ``[T [s], free control points [rad | m]]`` inside the bounds
        (certified or not).
    rate_hz:
        Rate [Hz] of the certificates (> 0).
    max_rounds:
        Most solve-and-certify rounds (≥ 1).
    max_boxes:
        Most trust boxes per round (≥ 1).
    start_certificate:
        The start's certificate summary when already known (made at ``rate_hz`` by
        :func:`~adept_traj.analysis.certify_members`), else it is made here (and seeds
        the adaptive samples).
    extra_samples:
        (k,) adaptive samples [normalised time, in [0, 1]] to start from (e.g. those of an
        earlier refinement of the same start), added to those the start's certificate
        seeds.
    """
    x0 = as_vector(x0, "x0", problem.n_var)
    if np.any(x0 < problem.xl) or np.any(x0 > problem.xu):
        raise ConfigurationError("x0 must lie inside the decision bounds (problem.xl, problem.xu)")
    rate = as_scalar(rate_hz, "rate_hz", "[Hz]", minimum=0.0, strict=True)
    rounds = as_integer(max_rounds, "max_rounds", minimum=1, error=ConfigurationError)
    boxes = as_integer(max_boxes, "max_boxes", minimum=1, error=ConfigurationError)
    from threadpoolctl import threadpool_limits  # lazy: only the local solver needs it

    extra = np.empty(0) if extra_samples is None else np.asarray(extra_samples, dtype=float)
    if extra.ndim != 1 or np.any(~np.isfinite(extra)) or np.any((extra < 0) | (extra > 1)):
        raise ConfigurationError(
            "extra_samples must be a 1-D array of normalised times in [0, 1]; got "
            f"{np.array2string(np.atleast_1d(extra), threshold=6)}"
        )
    with threadpool_limits(limits=1, user_api="blas"):
        return _refine(problem, x0, rate, rounds, boxes, start_certificate, np.unique(extra))


def screen_starts(
    problem: Any,
    starts: Any,
    *,
    rate_hz: float = 1000.0,
    stop: Any = None,
    max_boxes: int = SCREEN_BOXES,
    processes: int | None = None,
) -> list[Refinement]:
    """A short refinement (one round, ``max_boxes`` trust boxes) of each of ``starts``
    (k, n_var), in order; ``stop(outcomes)`` (optional) is asked after each and ends the
    screening when true. ``processes`` starts (default: the problem's ``workers``) are
    screened at once (:func:`~adept_traj.process_pool.map_forked`), the stop asked after
    each in order: the same outcomes as one at a time."""
    xs = list(np.atleast_2d(np.asarray(starts, dtype=float)))
    n_proc = _processes(problem, processes, len(xs))

    def screen(x: np.ndarray) -> Refinement:
        return refine_minimum_time(problem, x, rate_hz=rate_hz, max_rounds=1, max_boxes=max_boxes)

    screened: list[Refinement] = []
    for i in range(0, len(xs), n_proc):
        for one in map_forked(screen, xs[i : i + n_proc], n_proc):
            screened.append(one)
            if stop is not None and stop(screened):
                return screened
    return screened


def refine_starts(
    problem: Any,
    screened: list[Refinement],
    *,
    rate_hz: float = 1000.0,
    processes: int | None = None,
) -> list[Refinement]:
    """The full refinements (:func:`refine_minimum_time`) of the :data:`SCREEN_KEEP`
    fastest screened moves (:func:`screen_starts`) that reached a point inside the
    constraints, from where their screening ended: a multi-start that spends its
    iterations on the most promising starts (each with its screening's adaptive samples),
    ``processes`` at once (default: the problem's ``workers``)."""
    inside = [o for o in screened if o.message != NO_MOVE_INSIDE]
    inside.sort(key=lambda o: float(o.x[0]))
    kept = inside[:SCREEN_KEEP]

    def refine(o: Refinement) -> Refinement:
        return refine_minimum_time(
            problem,
            o.x,
            rate_hz=rate_hz,
            start_certificate=o.certificate,
            extra_samples=o.extra_samples,
        )

    return map_forked(refine, kept, _processes(problem, processes, len(kept)))


def _processes(problem: Any, processes: int | None, n: int) -> int:
    """Processes for ``n`` refinements at once (≥ 1; the certifying problem made first,
    so that forked ones inherit it)."""
    wanted = problem.settings.workers if processes is None else processes
    n_proc = max(1, min(as_integer(wanted, "processes", minimum=1), n))
    if n_proc > 1:
        certifying_problem(problem)
    return n_proc


def _refine(
    problem: Any,
    x0: np.ndarray,
    rate: float,
    max_rounds: int,
    max_boxes: int,
    start_certificate: MemberCertificate | None,
    extra: np.ndarray,
) -> Refinement:
    started = time.perf_counter()
    counts = SolveCounts()
    if start_certificate is None:
        tic = time.perf_counter()
        start_certificate, dense = certify_member(problem, x0, rate_hz=rate)
        counts.evaluation_s += time.perf_counter() - tic
        seeded = _failing_samples(problem, dense, np.concatenate([problem.s, extra]))
        extra = np.sort(np.concatenate([extra, seeded]))  # seeded by the start
    best: tuple[np.ndarray, Any, MemberCertificate] | None = None
    if start_certificate.feasible:
        ev = problem.evaluate_batch(x0)
        counts.evaluations += 1
        best = (x0.copy(), ev, start_certificate)
    buffers = list(BUFFERS)
    buffer = buffers.pop(0)
    x, last = x0.copy(), None
    message = "round limit reached"
    n_rounds = 0
    for n_rounds in range(1, max_rounds + 1):  # noqa: B007 (reported)
        x, inside = trust_box_solve(problem, x, extra, buffer, max_boxes, counts)
        if not inside:
            message = NO_MOVE_INSIDE
            break
        x, ev = _evaluated(problem, x)
        counts.evaluations += 1
        counts.evaluation_s += ev.seconds
        tic = time.perf_counter()
        summary, certificate = certify_member(problem, x, rate_hz=rate)
        counts.evaluation_s += time.perf_counter() - tic
        last = (x, ev, summary)
        if summary.feasible:
            if best is None or x[0] < best[0][0]:
                best = last
            message = "certified"
            break
        new = _failing_samples(problem, certificate, np.concatenate([problem.s, extra]))
        if len(new) and len(extra) + len(new) <= MAX_EXTRA_SAMPLES:
            extra = np.sort(np.concatenate([extra, new]))
        elif buffers:
            buffer = buffers.pop(0)
        else:
            message = "no certified move: samples and buffers exhausted"
            break
    if best is None and last is None:  # nothing inside the rows: the start, as it is
        ev = problem.evaluate_batch(x0)
        counts.evaluations += 1
        last = (x0.copy(), ev, start_certificate)
    x, ev, summary = best if best is not None else last
    return Refinement(
        x=x,
        objectives=ev.objectives,
        constraints=ev.constraints,
        feasible=bool(np.all(ev.constraints <= 0.0)),
        certified=bool(summary.feasible),
        certificate=summary,
        start=x0.copy(),
        start_certified=bool(start_certificate.feasible),
        start_certificate=start_certificate,
        n_rounds=n_rounds,
        n_iterations=counts.iterations,
        n_evaluations=counts.evaluations,
        extra_samples=extra,
        buffer=buffer,
        seconds=time.perf_counter() - started,
        evaluation_s=counts.evaluation_s,
        message=message,
    )


def _failing_samples(problem: Any, certificate: Any, existing: np.ndarray) -> np.ndarray:
    """Normalised times (k,) where ``certificate`` (of the certifying problem) shows the
    distance within :data:`DIP_WINDOW` of the margin (a grid of step :data:`DIP_STEP` over
    those windows), within :data:`DIP_TOLERANCE` of it (local minima of the dense
    distance, and the instant of the smallest one) or a torque above its limit, farther
    than :data:`_SAMPLE_GAP` from every ``existing`` sample."""
    dense = certificate.dense
    T = certificate.T
    d = dense.min_distance
    level = certificate.margin + DIP_TOLERANCE
    times = []
    if len(d) > 2:
        inner = (d[1:-1] <= d[:-2]) & (d[1:-1] <= d[2:]) & (d[1:-1] < level)
        times.append(dense.t[1:-1][inner])
    close = dense.t[d < certificate.margin + DIP_WINDOW] / T
    if len(close):  # a grid of step DIP_STEP over the windows where the distance binds
        grid = np.arange(0.0, 1.0 + 0.5 * DIP_STEP, DIP_STEP)
        within = np.abs(grid[:, None] - close[None, :]).min(axis=1) <= DIP_STEP
        times.append(grid[within] * T)
    if certificate.t_min_distance is not None and certificate.min_distance < level:
        times.append([certificate.t_min_distance])
    limit = problem.robot.limits.bound(LIMITS[4].name)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.max(np.abs(dense.tau) / limit, axis=1)
    if len(ratio) > 2:
        peak = (ratio[1:-1] >= ratio[:-2]) & (ratio[1:-1] >= ratio[2:]) & (ratio[1:-1] > 1.0)
        times.append(dense.t[1:-1][peak])
    if not times:
        return np.empty(0)
    s = np.unique(np.clip(np.concatenate(times) / T, 0.0, 1.0))
    gap = np.min(np.abs(s[:, None] - existing[None, :]), axis=1) if len(existing) else s + 1
    s = s[gap > _SAMPLE_GAP]
    if len(s) > 1:  # no two new samples closer than the gap either
        keep = np.concatenate([[True], np.diff(s) > _SAMPLE_GAP])
        s = s[keep]
    return s


def _evaluated(problem: Any, x: np.ndarray) -> tuple[np.ndarray, Any]:
    """:func:`~adept_traj.optimise.local.minimum_time.at_kinematic_minimum` of ``x`` (n_var,),
    refused unless its T is finite, and its evaluation by the problem."""
    x = at_kinematic_minimum(problem, x)
    if not math.isfinite(x[0]):
        raise ConfigurationError(f"the refined travel time is not finite: {x[0]}")
    return x, problem.evaluate_batch(x)
