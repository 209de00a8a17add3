"""Motion laws: the world pose of an obstacle's moving frame as a function of time.

A motion law maps times ``t`` of any shape ``(...)`` [s] to homogeneous transforms of shape
``(..., 4, 4)`` (rotation block, translation [m]), batched: no Python loop over time.

For a conservative broad phase every law also gives :meth:`MotionLaw.swept_ball`: the centre
and radius of one fixed ball that contains, **at every time t (not only over a grid)**, a given
ball attached to the moving frame. With the attached ball taken as a shape's bounding ball,
the swept ball contains the whole obstacle at all times: if the robot stays outside it, no
narrow-phase distance needs to be computed for that obstacle.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.scene.shapes import ValueObject
from adept_traj.transforms import as_rigid_transform, transform_from_xyz_rpy
from adept_traj.validation import as_finite_array, as_scalar, as_vector, readonly_copy

__all__ = [
    "FixedPose",
    "MotionLaw",
    "PendulumMotion",
    "as_times",
    "check_ball",
]

_EZ = np.array([0.0, 0.0, 1.0])


def as_times(t: Any) -> np.ndarray:
    """Return times ``t`` (any shape) [s] as a new finite float64 array."""
    return as_finite_array(t, "t")


class MotionLaw(ValueObject, ABC):
    """World pose of a moving frame as a function of time. Subclasses are frozen dataclasses."""

    @abstractmethod
    def pose(self, t: Any) -> np.ndarray:
        """World pose of the moving frame at times ``t``.

        Parameters
        ----------
        t: times [s], any shape ``(...)`` (a scalar gives one (4, 4) pose).

        Returns
        -------
        (..., 4, 4) homogeneous transforms (a new array).
        """

    @property
    def is_fixed(self) -> bool:
        """True when the pose does not depend on time (False but for :class:`FixedPose`:
        a law is time-dependent by kind, even one that happens to stand still)."""
        return False

    @abstractmethod
    def swept_ball(
        self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0
    ) -> tuple[np.ndarray, float]:
        """A fixed ball containing a ball attached to the moving frame, at every time.

        Parameters
        ----------
        point: (3,) centre of the attached ball in the moving frame [m].
        radius: radius of the attached ball [m], ≥ 0.

        Returns
        -------
        ``(centre, r)``: (3,) world centre [m] and radius [m] of a ball that contains the
        attached ball for every real t (a guarantee, not a sampled estimate).
        """

    def point_velocity(self, t: Any, points: Any) -> np.ndarray:
        """World velocity (..., 3) [m/s] of the points ``points`` (..., 3) [m] (world
        coordinates at time ``t``) that move rigidly with the frame, at times ``t`` (...)
        [s] (broadcast against ``points``' leading axes).

        .. math::
            v(p, t) = \\dot o(t) + \\omega(t) \\times (p - o(t)),

        :math:`o` the frame's origin and :math:`\\omega` its angular velocity. The fixed
        pose gives 0, the pendulum its closed form; any other law central differences of
        :meth:`pose` (step 1e-6 s).
        """
        pts = as_finite_array(points, "points")
        if pts.ndim < 1 or pts.shape[-1] != 3:
            raise InvalidInputError(f"points must have shape (..., 3) [m]; got shape {pts.shape}")
        try:
            times = np.broadcast_to(as_times(t), pts.shape[:-1])
        except ValueError:
            raise InvalidInputError(f"t must broadcast to points' shape {pts.shape[:-1]}") from None
        return self._point_velocity(times, pts)

    def _point_velocity(self, t: np.ndarray, points: np.ndarray) -> np.ndarray:
        pose, h = self.pose(t), 1e-6  # by central differences of pose (a generic law)
        local = np.einsum("...ji,...j->...i", pose[..., :3, :3], points - pose[..., :3, 3])
        p, m = (
            np.einsum("...ij,...j->...i", f[..., :3, :3], local) + f[..., :3, 3]
            for f in (self.pose(t + h), self.pose(t - h))
        )
        return (p - m) / (2.0 * h)

    @property
    def jump_interval(self) -> float:
        """Shortest time [s] between two instants where the pose jumps (``inf``: the pose is
        continuous in t, as for every law but a wrapping
        :class:`~adept_traj.scene.LinearMotion`). Between jumps every point moves at most
        at :meth:`max_point_speed`; the continuous certificate bounds an interval holding
        one jump from each end separately."""
        return math.inf

    @abstractmethod
    def max_point_speed(self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0) -> float:
        """Largest speed of any point of a ball attached to the moving frame, at any time.

        Parameters
        ----------
        point, radius: the attached ball, as for :meth:`swept_ball`.

        Returns
        -------
        An upper bound [m/s] of the world speed of every point of the ball, valid for every
        real t (used by the continuous-time certificate).
        """


def check_ball(point: Any, radius: Any) -> tuple[np.ndarray, float]:
    """A ball's centre (3,) [m] and radius [m] ≥ 0, checked."""
    return as_vector(point, "point", 3, "[m]"), as_scalar(radius, "radius", "[m]", minimum=0.0)


@dataclass(frozen=True, eq=False)
class FixedPose(MotionLaw):
    """A frame that does not move.

    Attributes
    ----------
    transform: (4, 4) rigid world pose of the frame (rotation, translation [m]).
    """

    transform: np.ndarray

    def __post_init__(self) -> None:
        t = as_rigid_transform(self.transform, "transform")
        object.__setattr__(self, "transform", readonly_copy(t))

    @classmethod
    def from_xyz_rpy(cls, xyz: Any = (0.0, 0.0, 0.0), rpy: Any = (0.0, 0.0, 0.0)) -> FixedPose:
        """Fixed pose from a translation (3,) [m] and URDF roll-pitch-yaw (3,) [rad]."""
        return cls(
            transform_from_xyz_rpy(
                as_vector(xyz, "xyz", 3, "[m]"), as_vector(rpy, "rpy", 3, "[rad]")
            )
        )

    def pose(self, t: Any) -> np.ndarray:
        """The constant transform, repeated: (..., 4, 4) for times ``t`` of shape (...) [s]."""
        times = as_times(t)
        return np.broadcast_to(self.transform, (*times.shape, 4, 4)).copy()

    @property
    def is_fixed(self) -> bool:
        """Always True."""
        return True

    def swept_ball(
        self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0
    ) -> tuple[np.ndarray, float]:
        """The attached ball itself, in world coordinates: ((3,) centre [m], radius [m])."""
        p, r = check_ball(point, radius)
        return self.transform[:3, :3] @ p + self.transform[:3, 3], r

    def _point_velocity(self, t: np.ndarray, points: np.ndarray) -> np.ndarray:
        return np.zeros(points.shape)

    def max_point_speed(self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0) -> float:
        """0 [m/s]: nothing moves (the arguments are checked as for every law)."""
        check_ball(point, radius)
        return 0.0


@dataclass(frozen=True, eq=False)
class PendulumMotion(MotionLaw):
    """The paper's oscillating pendulum (Section 3), in a corrected reading.

    The paper prints ``x = l cos α; z = h; y = constant; α = arccos(1 − h/l);
    h = (v0² − v)/(2g); v = v0 sin(3.14 t)``, which is garbled. This class implements:

    * bob speed ``v(t) = v0 · sin(ω t)``;
    * height of the bob above its lowest point, by energy conservation,
      ``h(t) = (v0² − v(t)²) / (2 g)`` (the paper prints ``v`` for ``v²``);
    * swing angle from the vertical ``|φ| = arccos(1 − h / l)``, signed
      ``φ(t) = sign(cos ω t) · arccos(1 − h / l)``. Equivalently, and computed so because it
      is accurate near the bottom, ``φ(t) = 2 · arcsin(a · cos ω t)`` with
      ``a = v0 / (2 √(g l))``. The bob starts at the extreme ``+φ_max`` at t = 0, passes the
      bottom at ω t = π/2 and reaches ``−φ_max`` at ω t = π; φ is smooth (analytic) in t,
      with period ``2π / ω``;
    * bob centre ``pivot + l · (sin φ · e_swing − cos φ · e_z)``, with ``e_z`` the world
      vertical (+z) and ``e_swing`` a horizontal unit vector of the swing plane (the paper's
      "y = constant" gives ``e_swing = +x``). The paper's ``x = l cos α`` would put the bob at
      x = l at the bottom, which no pendulum hanging from a pivot does; it is not used.

    It is a prescribed (kinematic) law, not a simulation. With the paper's numbers
    (v0 = 2 m/s, g = 9.81 m/s², l = 1 m) ω = 3.14 rad/s is close to √(g/l) = 3.13 rad/s, so the
    law is close to the small-amplitude pendulum: the bob's arc speed ``l·|φ̇|`` stays within
    0.05 m/s (2.5 % of v0) of ``|v(t)|``; φ_max = 0.650 rad (37.2°), h_max = 0.204 m.

    The moving frame (what :meth:`pose` returns) has its origin at the pivot, its z axis along
    the rod pointing from the bob to the pivot, its y axis ``e_n = e_z × e_swing`` (normal to
    the swing plane) and its x axis completing the right-handed frame (``e_swing`` at φ = 0).
    The bob centre is at ``(0, 0, −l)`` and the rod's midpoint at ``(0, 0, −l/2)`` in it.

    Attributes
    ----------
    pivot: (3,) world position of the pivot [m].
    length: rod length l, pivot to bob centre [m]; positive.
    v0: bob speed amplitude [m/s]; ≥ 0 and ``v0² / (2 g) ≤ 2 l`` (the bob cannot rise
        above the pivot's top).
    omega: angular frequency ω of the speed law [rad/s]; positive.
    g: gravitational acceleration [m/s²]; positive.
    swing_axis: (3,) horizontal direction ``e_swing`` of the swing plane (any length, must
        be non-zero with zero z component); stored normalised.
    """

    pivot: np.ndarray
    length: float
    v0: float
    omega: float
    g: float = 9.81
    swing_axis: np.ndarray = field(default_factory=lambda: np.array([1.0, 0.0, 0.0]))

    def __post_init__(self) -> None:
        pivot = as_vector(self.pivot, "pivot", 3, "[m]")
        length = as_scalar(self.length, "length", "[m]", minimum=0.0, strict=True)
        omega = as_scalar(self.omega, "omega", "[rad/s]", minimum=0.0, strict=True)
        g = as_scalar(self.g, "g", "[m/s²]", minimum=0.0, strict=True)
        v0 = as_scalar(self.v0, "v0", "[m/s]", minimum=0.0)
        h_max = v0 * v0 / (2.0 * g)
        if h_max > 2.0 * length:
            raise InvalidInputError(
                f"v0 = {v0!r} m/s is too large for length = {length!r} m and g = {g!r} m/s²: "
                f"the bob would rise h = v0²/(2g) = {h_max:.6g} m above its lowest point, more "
                f"than 2·length = {2.0 * length:.6g} m (need v0² ≤ 4·g·length)"
            )
        axis = as_vector(self.swing_axis, "swing_axis", 3)
        norm = float(np.linalg.norm(axis))
        if norm == 0.0 or abs(axis[2]) > 1e-9 * norm:
            raise InvalidInputError(
                "swing_axis must be a non-zero horizontal vector (z component 0), the direction "
                f"of the swing plane; got {axis.tolist()!r}"
            )
        if abs(norm - 1.0) > 4.0 * np.finfo(float).eps:
            axis = axis / norm
        axis[2] = 0.0
        object.__setattr__(self, "pivot", readonly_copy(pivot))
        object.__setattr__(self, "length", length)
        object.__setattr__(self, "v0", v0)
        object.__setattr__(self, "omega", omega)
        object.__setattr__(self, "g", g)
        object.__setattr__(self, "swing_axis", readonly_copy(axis))
        constant = np.zeros((4, 4))  # pose()'s columns y = e_n and the pivot, its last row
        constant[:3, 1], constant[:3, 3], constant[3, 3] = np.cross(_EZ, axis), pivot, 1.0
        object.__setattr__(self, "_pose_constant", readonly_copy(constant))  # not a field

    # ------------------------------------------------------------------ derived constants
    @property
    def normal_axis(self) -> np.ndarray:
        """(3,) unit normal of the swing plane, ``e_z × e_swing`` (the frame's y axis)."""
        return np.cross(_EZ, self.swing_axis)

    @property
    def period(self) -> float:
        """Period of the motion, ``2π / ω`` [s]."""
        return 2.0 * math.pi / self.omega

    @property
    def max_height(self) -> float:
        """Largest height of the bob above its lowest point, ``v0² / (2 g)`` [m]."""
        return self.v0 * self.v0 / (2.0 * self.g)

    @property
    def max_angle(self) -> float:
        """Swing amplitude ``φ_max = arccos(1 − h_max / l)`` [rad], in [0, π]."""
        return 2.0 * math.asin(min(1.0, self._amplitude_factor))

    @property
    def _amplitude_factor(self) -> float:
        """``a = v0 / (2 √(g l))``, so that ``φ = 2 arcsin(a cos ω t)``."""
        return self.v0 / (2.0 * math.sqrt(self.g * self.length))

    @property
    def max_angular_speed(self) -> float:
        r"""Largest swing rate :math:`\max_t |\dot\varphi|` [rad/s].

        From :math:`\varphi = 2 \arcsin(a \cos \omega t)`,

        .. math::
            |\dot\varphi| = \frac{2 a \omega |\sin \omega t|}{\sqrt{1 - a^2 \cos^2 \omega t}}
            = 2 a \omega \sqrt{\frac{1 - c^2}{1 - a^2 c^2}} \le 2 a \omega,
            \qquad c = \cos \omega t,

        since :math:`a \le 1` (equality at the bottom, :math:`c = 0`).
        """
        return 2.0 * min(1.0, self._amplitude_factor) * self.omega

    # ------------------------------------------------------------------ time functions
    def angle(self, t: Any) -> np.ndarray:
        """Signed swing angle φ(t) from the downward vertical [rad].

        Positive φ moves the bob towards ``+swing_axis``.

        Parameters
        ----------
        t: times [s], any shape (...).

        Returns
        -------
        (...) angles [rad], ``φ = sign(cos ω t) · arccos(1 − h/l) = 2 arcsin(a cos ω t)``.
        """
        times = as_times(t)
        s = np.clip(self._amplitude_factor * np.cos(self.omega * times), -1.0, 1.0)
        return 2.0 * np.arcsin(s)

    def speed(self, t: Any) -> np.ndarray:
        """Prescribed bob speed ``v(t) = v0 · sin(ω t)`` [m/s] for times ``t`` (...) [s]."""
        return self.v0 * np.sin(self.omega * as_times(t))

    def height(self, t: Any) -> np.ndarray:
        """Height of the bob above its lowest point, ``(v0² − v²) / (2 g)`` [m]; (...)."""
        v = self.speed(t)
        return (self.v0 * self.v0 - v * v) / (2.0 * self.g)

    def angular_speed(self, t: Any) -> np.ndarray:
        r"""Swing rate :math:`\dot\varphi(t)` [rad/s] for times ``t`` (...) [s]:

        .. math::
            \dot\varphi = \frac{-2 a \omega \sin \omega t}{\sqrt{1 - a^2 \cos^2 \omega t}}.
        """
        wt = self.omega * as_times(t)
        a = min(1.0, self._amplitude_factor)
        c = np.cos(wt)
        root = np.sqrt(np.maximum(1.0 - a * a * c * c, np.finfo(float).tiny))
        return -2.0 * a * self.omega * np.sin(wt) / root

    def _point_velocity(self, t: np.ndarray, points: np.ndarray) -> np.ndarray:
        r"""Every point turns about the axis :math:`-e_n` through the pivot at the rate
        :math:`\dot\varphi`: :math:`v = -\dot\varphi\, e_n \times (p - \text{pivot})`."""
        omega = -self.angular_speed(t)[..., None] * self.normal_axis
        return np.cross(omega, points - self.pivot)

    def bob_position(self, t: Any) -> np.ndarray:
        """World position of the bob centre [m], (..., 3) for times ``t`` of shape (...) [s]."""
        phi = self.angle(t)[..., None]
        return self.pivot + self.length * (np.sin(phi) * self.swing_axis - np.cos(phi) * _EZ)

    def pose(self, t: Any) -> np.ndarray:
        """World pose of the pendulum frame (origin at the pivot, z along the rod upwards).

        Parameters
        ----------
        t: times [s], any shape (...).

        Returns
        -------
        (..., 4, 4) transforms; columns x = cos φ e_swing + sin φ e_z, y = e_n,
        z = −sin φ e_swing + cos φ e_z, translation = pivot.
        """
        phi = self.angle(t)
        c, s, out = np.cos(phi), np.sin(phi), np.empty((*phi.shape, 4, 4))
        out[...] = self._pose_constant  # then columns x and z row by row (a broadcast: slower)
        for i, (swing, ez) in enumerate(zip(self.swing_axis.tolist(), _EZ.tolist())):
            out[..., i, 0] = c * swing + s * ez
            out[..., i, 2] = -s * swing + c * ez
        return out

    def swept_ball(
        self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0
    ) -> tuple[np.ndarray, float]:
        """Smallest ball holding the arc swept by ``point`` (``|φ| ≤ φ_max``), grown by ``radius``.

        The point ``(a, b, c)`` of the pendulum frame turns about the normal axis through the
        pivot on a circle of radius ρ = √(a² + c²), over an arc of half-angle φ_max centred on
        its rest position ``p0`` (φ = 0). For φ_max ≤ π/2 the smallest ball containing the arc
        has its centre on the chord's midpoint, ``axis point + cos φ_max · (p0 − axis point)``,
        and radius ``ρ · sin φ_max``; beyond, the circle's centre and radius ρ are used.
        Valid for all t since ``|φ(t)| ≤ φ_max`` always.
        """
        p, r = check_ball(point, radius)
        a, b, c = p
        axis_point = self.pivot + b * self.normal_axis
        rest = a * self.swing_axis + c * _EZ  # rest position relative to axis_point
        rho = math.hypot(a, c)
        alpha = self.max_angle
        if alpha <= 0.5 * math.pi:
            return axis_point + math.cos(alpha) * rest, rho * math.sin(alpha) + r
        return axis_point, rho + r

    def max_point_speed(self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0) -> float:
        r"""Speed bound [m/s] of a ball attached to the pendulum frame.

        Every point turns about the normal axis through the pivot, so its speed is
        :math:`|\dot\varphi|` times its distance from that axis:

        .. math::
            v \le \max_t |\dot\varphi| \,\bigl(\sqrt{a^2 + c^2} + r\bigr)

        for the ball of centre ``(a, b, c)`` and radius ``r`` (:attr:`max_angular_speed`).
        """
        p, r = check_ball(point, radius)
        return self.max_angular_speed * (math.hypot(p[0], p[2]) + r)
