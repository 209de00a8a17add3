r"""The robot at rest while the obstacles move: the certificate of a dwell
(:func:`certify_rest`) and, for a periodic scene, where over one period the robot may rest
at a location (:class:`RestProfile`, a conservative prefilter of the certificate).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.collision import CollisionChecker
from adept_traj.problem import ProblemSettings
from adept_traj.robot import Robot
from adept_traj.scene import Scene

__all__ = ["RestCheck", "RestProfile", "certify_rest"]

#: Finest sample spacing of a rest certificate: its grid is halved at most this often.
_REST_REFINE = 12


@dataclass(frozen=True)
class RestCheck:
    """The certificate of the robot at rest while the obstacles move.

    Attributes
    ----------
    start, duration: the scene time [s] the rest starts and its length [s].
    min_distance: lower bound [m] of the robot–obstacle distance over the rest (``inf``
        for a rest of length 0).
    certified: the bound is ≥ the margin at every instant of the rest.
    """

    start: float
    duration: float
    min_distance: float
    certified: bool


def _rest_checker(robot: Robot, scene: Scene, start: float, settings: ProblemSettings) -> Any:
    """The collision checker of a rest from scene time ``start`` [s] and every obstacle's
    largest point speed [m/s] (:func:`certify_rest`)."""
    checker = CollisionChecker(robot, scene, settings.influence, float(start))
    speeds = np.array(
        [
            ob.motion.max_point_speed(ob.offset[:3, 3], ob.shape.bounding_radius)
            for ob in scene.obstacles
        ]
    )
    return checker, speeds


def _rest_bounds(
    checker: Any, speeds: np.ndarray, q: np.ndarray, t: np.ndarray, h: float
) -> tuple[np.ndarray, float]:
    r"""The (n − 1,) lower bounds [m] of the distance of the robot at rest at ``q`` over
    the intervals of the (n,) times ``t`` [s] (``h`` [s] apart) after the checker's start,
    :math:`\min_o \tfrac12 (d_{o,a} + d_{o,b} - w_o h)` capped by the sampled distances,
    and the smallest sampled distance [m]."""
    d = checker.distances(np.broadcast_to(q, (t.size, q.size)), t).distance.min(axis=1)
    low = 0.5 * (d[:-1] + d[1:] - speeds * h)  # (n - 1, n_obstacles)
    return np.minimum(low.min(axis=1), np.minimum(d[:-1], d[1:]).min(axis=1)), float(d.min())


def certify_rest(
    robot: Robot,
    scene: Scene,
    q: Any,
    start: float,
    duration: float,
    *,
    settings: ProblemSettings,
    rate_hz: float,
) -> RestCheck:
    r"""Certify the robot at rest at ``q`` (nq,) [rad | m] over the scene times
    ``[start, start + duration]`` [s] against the margin of ``settings``.

    The distances to every obstacle are computed at samples h apart (from ``rate_hz``);
    between two samples a and b an obstacle whose points move at most :math:`w_o` [m/s]
    keeps

    .. math::
        d(t) \ge \tfrac12\,(d_a + d_b - w_o h),

    and the grid is halved where this bound misses the margin (at most
    :data:`_REST_REFINE` times). ``min_distance`` is the smallest bound.
    """
    if duration <= 0.0:
        return RestCheck(float(start), 0.0, math.inf, True)
    checker, speeds = _rest_checker(robot, scene, start, settings)
    if not checker.n_obstacles or not checker.n_solids:
        return RestCheck(float(start), float(duration), math.inf, True)
    qa = np.asarray(q, dtype=float)
    n = max(2, math.ceil(duration * rate_hz) + 1)
    bound = -math.inf
    for _ in range(_REST_REFINE + 1):
        t = np.linspace(0.0, duration, n)
        low, sampled = _rest_bounds(checker, speeds, qa, t, duration / (n - 1))
        bound = float(low.min())
        if bound >= settings.margin or sampled < settings.margin:
            break
        n = 2 * n - 1
    return RestCheck(float(start), float(duration), bound, bound >= settings.margin)


@dataclass(frozen=True)
class RestProfile:
    r"""Where the robot may rest at a location over one period P of a periodic scene: a
    conservative prefilter of :func:`certify_rest` (a dwell it accepts is certified again
    exactly, at its real scene times, before it is reported).

    Attributes
    ----------
    period: P [s]; margin: the margin [m].
    bounds: (n,) lower bound [m] of the distance over each of n equal intervals of
        [0, P) (:func:`certify_rest`'s bound at the samples, not refined).
    """

    period: float
    margin: float
    bounds: np.ndarray

    @classmethod
    def at(
        cls,
        robot: Robot,
        scene: Scene,
        q: Any,
        period: float,
        *,
        settings: ProblemSettings,
        rate_hz: float,
    ) -> RestProfile:
        """The profile of the robot at rest at ``q`` (nq,) [rad | m], sampled at
        ``rate_hz`` [Hz] over one period ``period`` [s]."""
        checker, speeds = _rest_checker(robot, scene, 0.0, settings)
        n = max(2, math.ceil(period * rate_hz) + 1)
        if not checker.n_obstacles or not checker.n_solids:
            bounds = np.full(n - 1, math.inf)
        else:
            t = np.linspace(0.0, period, n)
            qa = np.asarray(q, dtype=float)
            bounds = _rest_bounds(checker, speeds, qa, t, period / (n - 1))[0]
        bounds.setflags(write=False)
        return cls(float(period), float(settings.margin), bounds)

    def allows(self, start: float, duration: float) -> bool:
        """Whether every interval of the profile that meets the scene times
        ``[start, start + duration]`` [s] (taken modulo P), and its two neighbours, keep
        the margin; a rest of length ≤ 0 is always allowed."""
        if duration <= 0.0:
            return True
        n = self.bounds.size
        if duration >= self.period:
            return bool(self.bounds.min() >= self.margin)
        h, phase = self.period / n, math.fmod(start, self.period)
        first = math.floor(phase / h) - 1  # one interval more on each side: rounding
        count = math.floor((phase + duration) / h) + 1 - first + 1
        rows = (first + np.arange(count)) % n
        return bool(self.bounds[rows].min() >= self.margin)
