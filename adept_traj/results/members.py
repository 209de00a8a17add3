"""Picking a member of a result's front: its index, whether it is certified, its replay.

Picking a member is the point of a front. The viewer (``adept-traj show --member N``), the
ROS and CSV exports and the joint-motion figure (``member=N``) and the listing
(``adept-traj front``) share these rules:

- :func:`member_index`: ``None`` is the best trade-off (``result.best.index``); any other
  value must be an integer in [0, n − 1], n = ``len(result.front)``.
- :func:`certified_members`: ``front.feasible`` when :func:`~adept_traj.plan` certified
  every member (``front.n_certified`` set); for a result saved before that, only the best
  trade-off has a certificate (``result.feasible``) and no other member counts as
  certified.
- :func:`member_replay`: the :class:`~adept_traj.results.Replay` of a member, the
  caller's when it shows that member, else built once.
- :func:`member_dense`: the member's samples on the certificate's grid, in the columns of
  ``best_trajectory.csv``: the stored ones for the best trade-off, resampled for another.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from adept_traj.certification import DenseTrajectory, dense_samples
from adept_traj.collision import CollisionChecker
from adept_traj.errors import InvalidInputError
from adept_traj.results.record import PlanningResult
from adept_traj.results.replay import Replay
from adept_traj.validation import as_integer, check_type

__all__ = [
    "MAX_MEMBER_SAMPLES",
    "certified_members",
    "member_dense",
    "member_index",
    "member_replay",
]

#: Largest number of samples :func:`member_dense` resamples (T · rate_hz + 1).
MAX_MEMBER_SAMPLES = 1_000_000


def member_index(result: PlanningResult, member: Any = None) -> int:
    """The row of ``result.front`` that ``member`` names: ``None`` → the best trade-off.

    Raises
    ------
    InvalidInputError: ``member`` is not an integer in [0, ``len(result.front)`` − 1].
    """
    check_type(result, PlanningResult, "result")
    if member is None:
        return int(result.best.index)
    return as_integer(member, "member", minimum=0, maximum=len(result.front) - 1)


def certified_members(result: PlanningResult) -> np.ndarray:
    """(n,) bool: which members of ``result.front`` are certified (see the module)."""
    check_type(result, PlanningResult, "result")
    front = result.front
    if front.n_certified is not None:
        return front.feasible.copy()
    certified = np.zeros(len(front), dtype=bool)
    certified[result.best.index] = result.feasible
    return certified


def member_replay(result: PlanningResult, index: int, replay: Any = None) -> Replay:
    """The :class:`~adept_traj.results.Replay` of ``result.front.x[index]``.

    Parameters
    ----------
    result: the planning result.
    index: a row of the front (:func:`member_index`).
    replay: the caller's replay of that member (no robot reload), or ``None`` to build
        ``Replay.of(result, result.front.x[index])``.

    Raises
    ------
    InvalidInputError: ``replay`` is not a Replay, or shows another move.
    """
    index = member_index(result, index)
    if index == result.best.index:
        return Replay.of_best(result, replay)
    x = result.front.x[index]
    if replay is None:
        return Replay.of(result, x)
    check_type(replay, Replay, "replay")
    if not replay.shows(result, x):
        raise InvalidInputError(
            f"replay must show member {index} of the front, result.front.x[{index}] "
            f"(Replay.of(result, result.front.x[{index}])); its joints, start, goal, n_knots "
            f"or x differ (replay T = {replay.duration:.6g} s, member T = {float(x[0]):.6g} s)"
        )
    return replay


def member_dense(result: PlanningResult, index: int, replay: Any = None) -> DenseTrajectory:
    r"""Member ``index`` of the front sampled on its certificate's grid.

    For the best trade-off: the stored dense certificate samples
    (``result.best_trajectory``), exactly. For another member, whose samples are not
    stored: its B-spline resampled on the grid of the dense certificate at
    ``result.certificate.rate_hz``,

    .. math::

        t_k = T \, \frac{k}{n - 1}, \quad n = \lceil T \cdot \text{rate} \rceil + 1,

    positions and derivatives exact from the spline, torques from the robot's inverse
    dynamics (:meth:`~adept_traj.results.Replay.torques`) and, per sample, the smallest
    exact signed distance over every (solid, obstacle) pair
    (``CollisionChecker(robot, scene, start_time=t0).distances(q, t, exact=True)``, the
    obstacles at scene time t0 + t; ``inf`` when the scene has no obstacle), as
    :func:`~adept_traj.analysis.certify` computes them.

    Parameters
    ----------
    result: the planning result.
    index: a row of the front (:func:`member_index`).
    replay: the caller's replay of that member (see :func:`member_replay`).

    Returns
    -------
    :class:`~adept_traj.analysis.DenseTrajectory`: ``t`` (n,) [s]; ``q``, ``qd``, ``qdd``,
    ``qddd`` (n, nq) [rad | m per s^r]; ``tau`` (n, nq) [N·m | N]; ``min_distance`` (n,) [m].

    Raises
    ------
    InvalidInputError
        ``index`` out of range; ``replay`` shows another move; more than
        :data:`MAX_MEMBER_SAMPLES` samples.
    """
    index = member_index(result, index)
    if index == result.best.index:
        if replay is not None:
            Replay.of_best(result, replay)
        return result.best_trajectory
    motion = member_replay(result, index, replay)
    rate = float(result.certificate.rate_hz)
    n = dense_samples(motion.duration, rate)
    if n > MAX_MEMBER_SAMPLES:
        raise InvalidInputError(
            f"member {index} at {rate:g} Hz needs {n} samples over T = {motion.duration:.6g} s; "
            f"at most {MAX_MEMBER_SAMPLES} are resampled"
        )
    smp = motion.sample_uniform(n, orders=(0, 1, 2, 3))
    checker = CollisionChecker(motion.robot, motion.scene, start_time=motion.start_time)
    if checker.n_obstacles and checker.n_solids:
        pairs = checker.distances(smp.q[None], smp.t[None], exact=True).distance[0]
        per_sample = pairs.min(axis=(1, 2))
    else:
        per_sample = np.full(n, np.inf)
    return DenseTrajectory(
        t=smp.t,
        q=smp.q,
        qd=smp.qd,
        qdd=smp.qdd,
        qddd=smp.qddd,
        tau=motion.torques(smp),
        min_distance=per_sample,
    )
