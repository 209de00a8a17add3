r"""Continuous-time distance guarantee: what happens *between* the certificate's samples.

On a sample interval :math:`[t_a, t_b]` of length :math:`h` the signed distance
:math:`d_{so}(t)` of robot solid :math:`s` and obstacle :math:`o` changes at most as fast as
the relative speed of their points, :math:`|\dot d_{so}| \le L_{so} = v_s + w_o`. With the
exact distances at both ends, the smallest value on the interval is at least the apex of the
two Lipschitz cones:

.. math::
    \min_{t \in [t_a, t_b]} d_{so}(t) \;\ge\; \underline d_{so}
    = \tfrac12 \bigl(d_{so}(t_a) + d_{so}(t_b) - L_{so}\, h\bigr).

**Robot solids.** A point :math:`p` of solid :math:`s` moves at
:math:`\dot p = \sum_j \dot q_j\, a_j \times (p - o_j)` (revolute joints :math:`j` moving
the solid, axis :math:`a_j` through :math:`o_j`) :math:`+ \sum_j \dot q_j a_j` (prismatic), so

.. math::
    v_s \le \sum_{j\ \text{revolute}} \bar{\dot q}_j\, r_{sj}
          + \sum_{j\ \text{prismatic}} \bar{\dot q}_j,
    \qquad
    r_{sj} = \sum_{m \in (j, p_s]} \bigl(\lVert t_m \rVert + \max |q_m|_{\text{prismatic}}\bigr)
          + \lVert c_s \rVert + R_s,

with :math:`r_{sj}` a configuration-free bound on the distance from :math:`o_j` to any point
of the solid: the joint placements :math:`t_m` [m] along the chain from joint :math:`j` to
the solid's parent joint :math:`p_s` (a prismatic joint adds its largest stroke, from its
limits), then the centre :math:`c_s` [m] (in the parent joint's frame) and radius
:math:`R_s` [m] of the solid's enclosing ball. The joint-speed bound on the interval
follows from the exact acceleration bound :math:`A_j = \max_t |\ddot q_j|` of the spline
(:meth:`~adept_traj.problem.BSplineTrajectory.bounds`):

.. math::
    \bar{\dot q}_j = \tfrac12 \bigl(|\dot q_j(t_a)| + |\dot q_j(t_b)| + A_j h\bigr).

**Obstacles.** :math:`w_o` is :meth:`~adept_traj.scene.MotionLaw.max_point_speed` of the
obstacle's enclosing ball (0 for a fixed one; for the pendulum the largest swing rate times
the distance from the swing axis plus the radius).

**Obstacles whose pose jumps** (a conveyor's part wrapping around:
:attr:`~adept_traj.scene.MotionLaw.jump_interval` finite): on an interval holding one jump
at :math:`\tau`, the distance on :math:`[t_a, \tau)` is at least :math:`d(t_a) - L h` and
on :math:`[\tau, t_b]` at least :math:`d(t_b) - L h`; so for those pairs the bound is the
one-sided :math:`\min(d_a, d_b) - L h` on every interval (valid with or without a jump in
it), and :math:`-\infty` on an interval longer than the jump interval (two jumps could
hide a pose never sampled).

**Refinement.** Intervals whose bound is below the margin while both ends clear it are
bisected (one exact distance evaluation per pair at each midpoint), only those, up to
``max_depth`` times (default :data:`DEFAULT_MAX_DEPTH`: spacing :math:`h / 2^{10}`). The
guarantee is ``"continuous"`` when every interval's bound reaches the margin, otherwise
``"sampled at N Hz"`` with N the finest rate reached. A midpoint below the margin is a
violation found between the uniform samples.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from adept_traj.collision import SelfCollision
from adept_traj.collision import solid_lever_arms as lever_arms
from adept_traj.errors import InvalidInputError
from adept_traj.problem.trajectory_problem import TrajectoryProblem

__all__ = [
    "CONTINUOUS",
    "DEFAULT_MAX_DEPTH",
    "DistanceGuarantee",
    "SampledMove",
    "continuous_distance",
    "continuous_self_distance",
    "obstacle_jump_intervals",
    "obstacle_speeds",
    "sampled_move",
    "self_check_of",
    "solid_lever_arms",
]

#: Default number of bisections of a sample interval whose bound misses the margin.
DEFAULT_MAX_DEPTH = 10

#: The guarantee's name when the bound holds on every interval.
CONTINUOUS = "continuous"


@dataclass(frozen=True, eq=False)
class DistanceGuarantee:
    """Result of :func:`continuous_distance`.

    Attributes
    ----------
    guarantee: ``"continuous"`` or ``"sampled at N Hz"`` (see the module docstring).
    lower_bound: smallest interval bound :math:`\\underline d` over [0, T] and all pairs
        [m] (``inf``: no obstacle); a true lower bound of the distance at every instant.
    min_distance: smallest exact distance over the uniform and refined samples [m].
    t_min_distance: its time [s] (``None``: no obstacle).
    pair: ``(solid, obstacle)`` indices at that sample (``None``: no obstacle).
    depth: bisection levels used (0: the uniform grid sufficed).
    n_refined: exact distance evaluations (samples × all pairs) added by the refinement.
    """

    guarantee: str
    lower_bound: float
    min_distance: float
    t_min_distance: float | None
    pair: tuple[int, int] | None
    depth: int
    n_refined: int


def solid_lever_arms(problem: TrajectoryProblem) -> np.ndarray:
    r"""(n_solids, nq) factors :math:`r_{sj}` of the problem's robot: solid ``s`` moves at
    most :math:`\sum_j r_{sj} |\dot q_j|` [m/s]; [m] for a revolute joint (bound on the
    distance of its points from the joint origin), 1 for a prismatic joint, 0 for a joint
    that does not move the solid (see the module docstring;
    :func:`adept_traj.collision.solid_lever_arms`)."""
    return lever_arms(problem.robot)


def obstacle_speeds(problem: TrajectoryProblem) -> np.ndarray:
    """(n_obstacles,) bound [m/s] on the speed of every point of each obstacle, at any time
    (:meth:`~adept_traj.scene.MotionLaw.max_point_speed` of its enclosing ball)."""
    obstacles = problem.scene.obstacles
    return np.array(
        [ob.motion.max_point_speed(ob.offset[:3, 3], ob.shape.bounding_radius) for ob in obstacles]
    ).reshape(len(obstacles))


def obstacle_jump_intervals(problem: TrajectoryProblem) -> np.ndarray:
    """(n_obstacles,) shortest time [s] between two jumps of each obstacle's pose
    (:attr:`~adept_traj.scene.MotionLaw.jump_interval`; ``inf``: continuous)."""
    obstacles = problem.scene.obstacles
    return np.array([ob.motion.jump_interval for ob in obstacles]).reshape(len(obstacles))


def _rates(problem: TrajectoryProblem) -> tuple[np.ndarray, np.ndarray]:
    """:func:`solid_lever_arms` and :func:`obstacle_speeds` of ``problem``, read-only, made
    once and kept on the (frozen) problem: they depend on its robot and scene alone, and a
    front certifies hundreds of moves of one problem."""
    return problem.derived("analysis.continuous.rates", _made_rates)


def _made_rates(problem: TrajectoryProblem) -> tuple[np.ndarray, np.ndarray]:
    arms, speeds = solid_lever_arms(problem), obstacle_speeds(problem)
    arms.flags.writeable = speeds.flags.writeable = False
    return arms, speeds


def _interval_bounds(
    d_a: np.ndarray,
    d_b: np.ndarray,
    qd_a: np.ndarray,
    qd_b: np.ndarray,
    h: np.ndarray,
    arms: np.ndarray,
    acc: np.ndarray,
    speeds: np.ndarray,
    jumps: np.ndarray | None = None,
) -> np.ndarray:
    """Per interval and pair, the lower bound (m, ns, no) [m] of the module docstring, from
    the end distances (m, ns, no), joint speeds (m, nq) and lengths h (m,); ``jumps``
    (no,): each obstacle's :attr:`~adept_traj.scene.MotionLaw.jump_interval` [s] (None:
    every pose continuous)."""
    qd_bar = 0.5 * (np.abs(qd_a) + np.abs(qd_b) + acc * h[:, None])  # (m, nq)
    v = qd_bar @ arms.T  # (m, ns)
    lipschitz = v[:, :, None] + speeds[None, None, :]
    lipschitz *= h[:, None, None]
    low = d_a + d_b
    if jumps is not None:  # one-sided bounds for the obstacles whose pose jumps
        j = np.flatnonzero(np.isfinite(jumps))
        one_sided = np.minimum(d_a[..., j], d_b[..., j]) - lipschitz[..., j]
        one_sided = np.where(h[:, None, None] > jumps[j], -np.inf, one_sided)  # ≥ 2 jumps
    low -= lipschitz
    low *= 0.5  # the same operations in the same order as ½(d_a + d_b − L h), in place
    if jumps is not None:
        low[..., j] = one_sided
    return low


@dataclass(frozen=True, eq=False)
class SampledMove:
    r"""A move and its samples, as the continuous bounds take them (made by
    :func:`sampled_move`, or by :func:`~adept_traj.certification.certify`, which has the
    spline's bounds already).

    Attributes
    ----------
    x: (n_var,) checked decision vector ``[T [s], free control points [rad | m]]``.
    t: (n,) sample times [s], increasing, ``t[0] = 0``, ``t[-1] = T``.
    q: (n, nq) configurations at ``t`` [rad | m].
    qd: (n, nq) joint speeds at ``t`` [rad/s | m/s].
    acc: (nq,) the spline's exact largest :math:`|\ddot q_i|` over the move [rad/s² | m/s²]
        (:meth:`~adept_traj.problem.BSplineTrajectory.bounds` ``(x).qdd_abs_max``). A
        smaller value voids every guarantee made from the move: give only that value.
    """

    x: np.ndarray
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    acc: np.ndarray

    @property
    def rate_hz(self) -> float:
        """The uniform grid's rate [Hz], ``(n − 1) / T``."""
        return (len(self.t) - 1) / float(self.x[0])


def sampled_move(
    problem: TrajectoryProblem, x: np.ndarray, t: np.ndarray, q: np.ndarray, qd: np.ndarray
) -> SampledMove:
    """The :class:`SampledMove` of ``x`` (n_var,) sampled at ``t`` (n,) [s] with
    configurations ``q`` and speeds ``qd`` (n, nq), its acceleration bound computed from
    ``problem``'s spline (so never below the true one)."""
    return SampledMove(x, t, q, qd, problem.trajectory.bounds(x).qdd_abs_max)


def continuous_distance(
    problem: TrajectoryProblem,
    move: SampledMove,
    pairs: np.ndarray,
    max_depth: int = DEFAULT_MAX_DEPTH,
    exact: bool = True,
) -> DistanceGuarantee:
    """Lower-bound the robot–obstacle distance between the samples and refine where needed.

    Parameters
    ----------
    problem: the problem (robot, scene, margin).
    move: the move and its samples (:func:`sampled_move`).
    pairs: (n, ns, no) exact distances at ``move.t`` [m], or lower bounds of them.
    max_depth: most bisections (≥ 0).
    exact: distances at the midpoints exact for every pair (``False``: lower bounds
        above the checker's influence distance, as
        :meth:`~adept_traj.collision.CollisionChecker.distances`).

    Returns
    -------
    :class:`DistanceGuarantee`.
    """
    checker = problem.checker

    def distances(q: np.ndarray, t_m: np.ndarray) -> np.ndarray:
        return checker.distances(q[None], t_m[None], exact=exact).distance[0]

    arms, speeds = _rates(problem)
    jumps = obstacle_jump_intervals(problem)
    return _bisect(
        problem, move, pairs, max_depth, arms, speeds, distances,
        jumps if np.isfinite(jumps).any() else None,
    )  # fmt: skip


def self_check_of(problem: TrajectoryProblem) -> SelfCollision:
    """The problem's :attr:`~adept_traj.problem.TrajectoryProblem.self_check`, which the
    self-distance bounds need.

    Raises
    ------
    InvalidInputError
        The problem's self-collision check is off.
    """
    check = problem.self_check
    if check is None:
        raise InvalidInputError("the problem's self-collision check is off")
    return check


def continuous_self_distance(
    problem: TrajectoryProblem,
    move: SampledMove,
    pairs: np.ndarray,
    max_depth: int = DEFAULT_MAX_DEPTH,
) -> DistanceGuarantee:
    """:func:`continuous_distance` for the robot's own solid pairs
    (:attr:`~adept_traj.problem.TrajectoryProblem.self_check`, which must be on): ``pairs``
    (n, n_pairs) [m] are the self-distances at ``move.t`` (or lower bounds of them); the
    Lipschitz constant of pair :math:`(a, b)` counts only the joints that move one of its
    solids (:attr:`~adept_traj.collision.SelfCollision.lever_arms`), nothing moves otherwise (no
    obstacle speed). The midpoints' distances are exact below the margin, lower bounds
    above it. The returned ``pair`` is ``(pair index, 0)``.

    Raises
    ------
    InvalidInputError
        The problem's self-collision check is off (:func:`self_check_of`).
    """
    check = self_check_of(problem)

    def distances(q: np.ndarray, t_m: np.ndarray) -> np.ndarray:
        return check.distances(q, exact_below=problem.settings.margin)[..., None]

    arms, speeds = check.lever_arms, np.zeros(1)
    return _bisect(problem, move, pairs[..., None], max_depth, arms, speeds, distances)


def _bisect(
    problem: TrajectoryProblem,
    move: SampledMove,
    pairs: np.ndarray,
    max_depth: int,
    arms: np.ndarray,
    speeds: np.ndarray,
    distances: Callable[[np.ndarray, np.ndarray], np.ndarray],
    jumps: np.ndarray | None = None,
) -> DistanceGuarantee:
    """The refinement of :func:`continuous_distance` for distances ``pairs`` (n, ns, no) at
    ``move.t``, rate factors ``arms`` (ns, nq) and ``speeds`` (no,); ``distances(q, t)``
    gives them (m, ns, no) at configurations (m, nq) and times (m,) [s]."""
    x, t, qd, acc, rate_hz = move.x, move.t, move.qd, move.acc, move.rate_hz
    margin = float(problem.settings.margin)
    T = float(x[0])
    k, s, o = np.unravel_index(int(np.argmin(pairs)), pairs.shape)
    best = (float(pairs[k, s, o]), float(t[k]), (int(s), int(o)))
    t_a, t_b, d_a, d_b, v_a, v_b = t[:-1], t[1:], pairs[:-1], pairs[1:], qd[:-1], qd[1:]
    at_sample = pairs.reshape(len(pairs), -1).min(axis=1)  # (n,) smallest over the pairs
    m_a, m_b = at_sample[:-1], at_sample[1:]  # of each interval's ends
    lower = math.inf
    depth = n_refined = 0
    while len(t_a):
        low = _interval_bounds(d_a, d_b, v_a, v_b, t_b - t_a, arms, acc, speeds, jumps)
        per = low.reshape(len(low), -1).min(axis=1)
        ok = per >= margin
        if ok.any():
            lower = min(lower, float(per[ok].min()))
        # Refine the intervals that miss the margin with both ends clear of it.
        ends_clear = (m_a >= margin) & (m_b >= margin)
        todo = ~ok & ends_clear
        stuck = ~ok & ~ends_clear
        if stuck.any():
            lower = min(lower, float(per[stuck].min()))
        if depth == max_depth:
            if todo.any():
                lower = min(lower, float(per[todo].min()))
            break
        if not todo.any():
            break
        depth += 1
        t_a, t_b, d_a, d_b, v_a, v_b, m_a, m_b = (
            a[todo] for a in (t_a, t_b, d_a, d_b, v_a, v_b, m_a, m_b)
        )
        t_m = 0.5 * (t_a + t_b)
        smp = problem.trajectory.sample(x, t_m / T, orders=(0, 1))
        d_m = distances(smp.q, t_m)
        n_refined += len(t_m)
        k, s, o = np.unravel_index(int(np.argmin(d_m)), d_m.shape)
        if d_m[k, s, o] < best[0]:
            best = (float(d_m[k, s, o]), float(t_m[k]), (int(s), int(o)))
        t_a, t_b = np.concatenate([t_a, t_m]), np.concatenate([t_m, t_b])
        d_a, d_b = np.concatenate([d_a, d_m]), np.concatenate([d_m, d_b])
        at_m = d_m.reshape(len(d_m), -1).min(axis=1)
        m_a, m_b = np.concatenate([m_a, at_m]), np.concatenate([at_m, m_b])
        v_a, v_b = np.concatenate([v_a, smp.qd]), np.concatenate([smp.qd, v_b])
    finest = f"sampled at {rate_hz * 2**depth:g} Hz"
    guarantee = CONTINUOUS if lower >= margin else finest
    return DistanceGuarantee(
        guarantee=guarantee,
        lower_bound=lower,
        min_distance=best[0],
        t_min_distance=best[1],
        pair=best[2],
        depth=depth,
        n_refined=n_refined,
    )
