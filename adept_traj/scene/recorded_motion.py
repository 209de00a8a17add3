r"""A recorded trajectory of poses (a CSV of t, x, y, z, roll, pitch, yaw), interpolated.

Between two recorded poses :math:`(t_k, o_k, R_k)` and :math:`(t_{k+1}, o_{k+1}, R_{k+1})`
the origin moves on the straight segment at a constant rate and the rotation turns at a
constant rate about one axis (spherical linear interpolation, the shortest arc):

.. math::
    \tau = \frac{t - t_k}{t_{k+1} - t_k}, \qquad
    o(t) = o_k + \tau (o_{k+1} - o_k), \qquad
    R(t) = R_k \exp\bigl(\tau \log(R_k^\top R_{k+1})\bigr).

So on segment k every point at distance at most :math:`\rho` from the origin moves at most
at :math:`|o_{k+1} - o_k| / \Delta t_k + \theta_k \rho / \Delta t_k` (:math:`\theta_k` the
segment's rotation angle): :meth:`RecordedMotion.max_point_speed` is the largest over the
segments, a bound for every t. Before the first and after the last time the pose is held
(not periodic), or the record repeats with period :math:`t_{n-1} - t_0` (periodic; the first
and last poses must then be equal, so the pose stays continuous).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from adept_traj.errors import InvalidInputError, MotionFileError
from adept_traj.files import read_bytes_bounded
from adept_traj.scene.motion_laws import MotionLaw, as_times, check_ball
from adept_traj.transforms import rotation_from_rpy
from adept_traj.validation import as_finite_array, check_increasing, readonly_copy

__all__ = ["MAX_RECORDED_POSES", "RecordedMotion", "read_pose_csv"]

#: Most rows a recorded-motion CSV may have.
MAX_RECORDED_POSES = 1_000_000

#: Largest mismatch of the first and last poses of a periodic record [m | rad].
_PERIODIC_TOL = 1e-9

_COLUMNS = ("t", "x", "y", "z", "roll", "pitch", "yaw")


@dataclass(frozen=True, eq=False)
class RecordedMotion(MotionLaw):
    """Poses recorded at increasing times, interpolated (module docstring).

    Attributes
    ----------
    times: (n,) strictly increasing times [s], n ≥ 2 (absolute scene time).
    xyz: (n, 3) positions of the frame's origin [m].
    rpy: (n, 3) orientations, URDF roll-pitch-yaw [rad].
    periodic: repeat the record with period ``times[-1] - times[0]``.
    source: the CSV file it was read from ("" if built from arrays).
    """

    times: np.ndarray
    xyz: np.ndarray
    rpy: np.ndarray
    periodic: bool = False
    source: str = ""

    def __post_init__(self) -> None:
        t = as_finite_array(self.times, "times")
        n = t.size
        if t.ndim != 1 or n < 2:
            raise InvalidInputError(f"times must have shape (n,), n ≥ 2 [s]; got shape {t.shape}")
        check_increasing(t)
        xyz, rpy = (as_finite_array(a, name) for a, name in ((self.xyz, "xyz"), (self.rpy, "rpy")))
        for a, name in ((xyz, "xyz"), (rpy, "rpy")):
            if a.shape != (n, 3):
                raise InvalidInputError(f"{name} must have shape ({n}, 3); got {a.shape}")
        rot = rotation_from_rpy(rpy)
        if self.periodic:
            gap = max(
                float(np.abs(xyz[-1] - xyz[0]).max()),
                float(np.linalg.norm(pin.log3(rot[0].T @ rot[-1]))),
            )
            if gap > _PERIODIC_TOL:
                raise InvalidInputError(
                    "a periodic record must end at the pose it starts at (else the pose "
                    f"jumps at each period); first and last poses differ by {gap:.3g} [m | rad]"
                )
        logs = np.array([pin.log3(rot[k].T @ rot[k + 1]) for k in range(n - 1)])  # (n-1, 3)
        angles = np.linalg.norm(logs, axis=1)
        axes = np.divide(logs, angles[:, None], out=np.zeros_like(logs), where=angles[:, None] > 0)
        dt = np.diff(t)
        for name, value in (("times", t), ("xyz", xyz), ("rpy", rpy)):
            object.__setattr__(self, name, readonly_copy(value))
        object.__setattr__(self, "periodic", bool(self.periodic))
        object.__setattr__(self, "source", str(self.source))
        extra = {  # not fields
            "_rot": rot,
            "_axes": axes,
            "_rates": angles / dt,  # (n-1,) angular speed of each segment [rad/s]
            "_velocities": np.diff(xyz, axis=0) / dt[:, None],  # (n-1, 3) [m/s]
        }
        for name, value in extra.items():
            object.__setattr__(self, name, value)

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str], *, periodic: bool = False) -> RecordedMotion:
        """Read a pose CSV (:func:`read_pose_csv`); errors name the file and line."""
        times, xyz, rpy = read_pose_csv(path)
        try:
            return cls(times, xyz, rpy, periodic, str(Path(path).resolve()))
        except InvalidInputError as exc:
            raise MotionFileError(f"{path}: {exc}") from None

    @property
    def period(self) -> float:
        """``times[-1] - times[0]`` [s]."""
        return float(self.times[-1] - self.times[0])

    def _segments(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Segment index (...) and the fraction τ (...) in it of times ``t`` (held or
        wrapped outside the record)."""
        t0, t1 = float(self.times[0]), float(self.times[-1])
        t = t0 + np.mod(t - t0, t1 - t0) if self.periodic else np.clip(t, t0, t1)
        k = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, len(self.times) - 2)
        tau = (t - self.times[k]) / (self.times[k + 1] - self.times[k])
        return k, np.clip(tau, 0.0, 1.0)

    def pose(self, t: Any) -> np.ndarray:
        """(..., 4, 4) interpolated poses at times ``t`` (...) [s] (module docstring)."""
        k, tau = self._segments(as_times(t))
        rot, axes = self._rot, self._axes  # type: ignore[attr-defined]
        angle = tau * self._rates[k] * (self.times[k + 1] - self.times[k])  # type: ignore[attr-defined]
        out = np.zeros((*k.shape, 4, 4))
        out[..., :3, :3] = rot[k] @ _rodrigues(axes[k], angle)
        out[..., :3, 3] = self.xyz[k] + tau[..., None] * (self.xyz[k + 1] - self.xyz[k])
        out[..., 3, 3] = 1.0
        return out

    def _point_velocity(self, t: np.ndarray, points: np.ndarray) -> np.ndarray:
        r""":math:`\dot o + \omega \times (p - o)` on each point's segment (0 where the
        pose is held)."""
        k, _ = self._segments(t)
        held = np.zeros(t.shape, dtype=bool)
        if not self.periodic:
            held = (t < self.times[0]) | (t > self.times[-1])
        rates = np.where(held, 0.0, self._rates[k])[..., None]  # type: ignore[attr-defined]
        omega = np.einsum("...ij,...j->...i", self._rot[k], self._axes[k]) * rates  # type: ignore[attr-defined]
        velocity = np.where(held[..., None], 0.0, self._velocities[k])  # type: ignore[attr-defined]
        origin = self.pose(t)[..., :3, 3]
        return velocity + np.cross(omega, points - origin)

    def swept_ball(
        self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0
    ) -> tuple[np.ndarray, float]:
        """The ball about the recorded origins' bounding box, grown by ``|point| + radius``
        (the origin stays on segments between recorded positions)."""
        p, r = check_ball(point, radius)
        lo, hi = self.xyz.min(axis=0), self.xyz.max(axis=0)
        return 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo)) + float(np.linalg.norm(p)) + r

    def max_point_speed(self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0) -> float:
        """The largest over the segments of :math:`|\\dot o_k| + \\omega_k (|p| + r)` [m/s]
        (module docstring)."""
        p, r = check_ball(point, radius)
        reach = float(np.linalg.norm(p)) + r
        speeds = np.linalg.norm(self._velocities, axis=1) + self._rates * reach  # type: ignore[attr-defined]
        return float(speeds.max())


def _rodrigues(axes: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotations (..., 3, 3) by ``angle`` (...) about the unit ``axes`` (..., 3)."""
    x, y, z = axes[..., 0], axes[..., 1], axes[..., 2]
    s, c = np.sin(angle), np.cos(angle)
    v = 1.0 - c
    out = np.empty((*angle.shape, 3, 3))
    out[..., 0, 0], out[..., 0, 1], out[..., 0, 2] = (
        c + x * x * v,
        x * y * v - z * s,
        x * z * v + y * s,
    )
    out[..., 1, 0], out[..., 1, 1], out[..., 1, 2] = (
        y * x * v + z * s,
        c + y * y * v,
        y * z * v - x * s,
    )
    out[..., 2, 0], out[..., 2, 1], out[..., 2, 2] = (
        z * x * v - y * s,
        z * y * v + x * s,
        c + z * z * v,
    )
    return out


def read_pose_csv(path: str | os.PathLike[str]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Times (n,) [s], positions (n, 3) [m] and roll-pitch-yaw (n, 3) [rad] of a CSV with
    the columns ``t, x, y, z, roll, pitch, yaw`` (an optional header line with exactly
    these names; ``#`` comment lines and blank lines skipped).

    Raises
    ------
    MotionFileError
        missing or unreadable file, a row without 7 finite numbers, fewer
        than 2 rows, more than :data:`MAX_RECORDED_POSES`, or a time not greater than
        the one before (the message names the file and the line).
    """
    p = Path(path)
    raw = read_bytes_bounded(p, MotionFileError, what="recorded-motion CSV")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise MotionFileError(f"{p}: not UTF-8 text") from None
    rows, lines = [], []
    for number, line in enumerate(text.splitlines(), start=1):
        cells = [c.strip() for c in line.split(",")]
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        if not rows and tuple(c.lower() for c in cells) == _COLUMNS:
            continue
        if len(cells) != 7:
            raise MotionFileError(
                f"{p}: line {number}: expected 7 values ({', '.join(_COLUMNS)}); got {len(cells)}"
            )
        try:
            values = [float(c) for c in cells]
        except ValueError:
            raise MotionFileError(f"{p}: line {number}: not a number in {line.strip()!r}") from None
        if not all(math.isfinite(v) for v in values):
            raise MotionFileError(f"{p}: line {number}: a value is not finite: {line.strip()!r}")
        if rows and values[0] <= rows[-1][0]:
            raise MotionFileError(
                f"{p}: line {number}: time column not increasing: t = {values[0]!r} s after "
                f"t = {rows[-1][0]!r} s (line {lines[-1]}); the times must strictly increase"
            )
        rows.append(values)
        lines.append(number)
        if len(rows) > MAX_RECORDED_POSES:
            raise MotionFileError(f"{p}: more than MAX_RECORDED_POSES = {MAX_RECORDED_POSES} rows")
    if len(rows) < 2:
        raise MotionFileError(f"{p}: needs at least 2 poses; got {len(rows)}")
    a = np.array(rows)
    return a[:, 0], a[:, 1:4], a[:, 4:7]
