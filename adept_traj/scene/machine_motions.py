r"""Motion laws of the machines of a cell: a conveyor (linear motion, with wrap-around) and
a turntable (rotation about a fixed axis).

Both are functions of the absolute scene time ``t`` [s], batched over any shape of ``t``
like every :class:`~adept_traj.scene.MotionLaw`, with an exact speed bound of every point
for the continuous certificate. An obstacle's shape is placed in the moving frame by its
``offset`` (the obstacle's pose at displacement 0, angle 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.scene.motion_laws import MotionLaw, as_times, check_ball
from adept_traj.validation import as_scalar, as_vector, readonly_copy

__all__ = ["LinearMotion", "RotationMotion", "rotation_about"]


@dataclass(frozen=True, eq=False)
class LinearMotion(MotionLaw):
    r"""Translation at a constant velocity, wrapping around every ``wrap`` metres.

    The frame is translated by :math:`u\, s(t)` (no rotation), :math:`u = v / |v|`, with

    .. math::
        s(t) = \sigma + |v|\, t \quad\text{(no wrap)}, \qquad
        s(t) = (\sigma + |v|\, t) \bmod L \in [0, L) \quad\text{(wrap } L\text{)},

    :math:`\sigma` the ``phase`` [m]. With a wrap, a part rides the belt from displacement
    0 to L and reappears at 0: parts that recur every L metres (several parts on one belt:
    one law each, phases ``k L / n``). Every point moves at exactly :math:`|v|` between the
    jumps, which come every :math:`L / |v|` seconds (:attr:`jump_interval`).

    Attributes
    ----------
    velocity: (3,) belt velocity [m/s], non-zero.
    wrap: L [m], positive, or ``inf`` (no wrap-around; the default).
    phase: σ [m], in [0, L) with a wrap.
    """

    velocity: np.ndarray
    wrap: float = math.inf
    phase: float = 0.0

    def __post_init__(self) -> None:
        v = as_vector(self.velocity, "velocity", 3, "[m/s]")
        speed = float(np.linalg.norm(v))
        if speed == 0.0:
            raise InvalidInputError("velocity must be non-zero [m/s] (a belt at rest: FixedPose)")
        wrap = self.wrap
        if not (isinstance(wrap, (int, float)) and math.isinf(wrap) and wrap > 0):
            wrap = as_scalar(wrap, "wrap", "[m]", minimum=0.0, strict=True)
        phase = as_scalar(self.phase, "phase", "[m]")
        if math.isfinite(wrap) and not 0.0 <= phase < wrap:
            raise InvalidInputError(f"phase must be in [0, wrap = {wrap}) [m]; got {phase}")
        object.__setattr__(self, "velocity", readonly_copy(v))
        object.__setattr__(self, "wrap", float(wrap))
        object.__setattr__(self, "phase", phase)
        object.__setattr__(self, "_direction", v / speed)  # not fields
        object.__setattr__(self, "_speed", speed)

    def displacement(self, t: Any) -> np.ndarray:
        """s(t) [m] along the belt for times ``t`` (...) [s] (class docstring)."""
        s = self.phase + self._speed * as_times(t)  # type: ignore[attr-defined]
        return np.mod(s, self.wrap) if math.isfinite(self.wrap) else s

    def pose(self, t: Any) -> np.ndarray:
        """(..., 4, 4) translations by :math:`u\\, s(t)` for times ``t`` (...) [s]."""
        s = self.displacement(t)
        out = np.zeros((*s.shape, 4, 4))
        out[..., 0, 0] = out[..., 1, 1] = out[..., 2, 2] = out[..., 3, 3] = 1.0
        out[..., :3, 3] = s[..., None] * self._direction  # type: ignore[attr-defined]
        return out

    @property
    def jump_interval(self) -> float:
        """:math:`L / |v|` [s] with a wrap, else ``inf``."""
        return self.wrap / self._speed  # type: ignore[attr-defined]

    def _point_velocity(self, t: np.ndarray, points: np.ndarray) -> np.ndarray:
        return np.broadcast_to(self.velocity, points.shape).copy()

    def swept_ball(
        self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0
    ) -> tuple[np.ndarray, float]:
        """The ball about the segment the point sweeps, :math:`p + u [0, L]`, grown by
        ``radius`` (radius ``inf`` without a wrap)."""
        p, r = check_ball(point, radius)
        if not math.isfinite(self.wrap):
            return p, math.inf
        return p + 0.5 * self.wrap * self._direction, 0.5 * self.wrap + r  # type: ignore[attr-defined]

    def max_point_speed(self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0) -> float:
        """The belt's speed :math:`\\lVert v \\rVert` [m/s] (every point moves with the
        belt, between the jumps)."""
        check_ball(point, radius)
        return self._speed  # type: ignore[attr-defined]


def rotation_about(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    r"""Rotation matrices (..., 3, 3) by ``angle`` (...) [rad] about the unit ``axis`` (3,),
    Rodrigues' formula :math:`R = I + \sin\theta\, [a]_\times + (1 - \cos\theta) [a]_\times^2`."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s, c = np.sin(angle)[..., None, None], np.cos(angle)[..., None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


@dataclass(frozen=True, eq=False)
class RotationMotion(MotionLaw):
    r"""Rotation about a fixed axis at a constant rate (a turntable).

    The frame is turned by :math:`\theta(t) = \theta_0 + \omega t` about the line through
    ``point`` along ``axis``: :math:`x \mapsto c + R(\theta)(x - c)`. A point at distance
    :math:`\rho` from the axis moves at exactly :math:`|\omega| \rho`.

    Attributes
    ----------
    axis: (3,) direction of the axis (non-zero; stored normalised).
    point: (3,) a point c of the axis [m].
    omega: ω [rad/s], non-zero (positive: counter-clockwise about ``axis``).
    angle: θ0 [rad] at t = 0.
    """

    axis: np.ndarray
    point: np.ndarray
    omega: float
    angle: float = 0.0

    def __post_init__(self) -> None:
        a = as_vector(self.axis, "axis", 3)
        norm = float(np.linalg.norm(a))
        if norm == 0.0:
            raise InvalidInputError("axis must be a non-zero vector")
        omega = as_scalar(self.omega, "omega", "[rad/s]")
        if omega == 0.0:
            raise InvalidInputError("omega must be non-zero [rad/s] (a table at rest: FixedPose)")
        object.__setattr__(self, "axis", readonly_copy(a / norm))
        object.__setattr__(self, "point", readonly_copy(as_vector(self.point, "point", 3, "[m]")))
        object.__setattr__(self, "omega", omega)
        object.__setattr__(self, "angle", as_scalar(self.angle, "angle", "[rad]"))

    def pose(self, t: Any) -> np.ndarray:
        """(..., 4, 4) rotations about the axis by θ(t), for times ``t`` (...) [s]."""
        theta = self.angle + self.omega * as_times(t)
        rot = rotation_about(self.axis, theta)
        out = np.zeros((*theta.shape, 4, 4))
        out[..., :3, :3] = rot
        out[..., :3, 3] = self.point - rot @ self.point
        out[..., 3, 3] = 1.0
        return out

    def _point_velocity(self, t: np.ndarray, points: np.ndarray) -> np.ndarray:
        return np.cross(self.omega * self.axis, points - self.point)

    def _axis_distance(self, p: np.ndarray) -> tuple[np.ndarray, float]:
        d = p - self.point
        foot = self.point + (d @ self.axis) * self.axis
        return foot, float(np.linalg.norm(p - foot))

    def swept_ball(
        self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0
    ) -> tuple[np.ndarray, float]:
        """The ball about the circle the point sweeps: centre its foot on the axis, radius
        its distance from the axis plus ``radius``."""
        p, r = check_ball(point, radius)
        foot, rho = self._axis_distance(p)
        return foot, rho + r

    def max_point_speed(self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0) -> float:
        """:math:`|\\omega| (\\rho + r)` [m/s], ρ the ball centre's distance from the axis."""
        p, r = check_ball(point, radius)
        return abs(self.omega) * (self._axis_distance(p)[1] + r)
