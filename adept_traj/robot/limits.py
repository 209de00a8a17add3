"""Joint limits of a robot (paper Table 2, constraints (7)–(11)), as a frozen dataclass."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from adept_traj.errors import JointLimitError
from adept_traj.validation import as_batch, readonly_copy

__all__ = ["JointLimits"]


@dataclass(frozen=True)
class JointLimits:
    """Per-joint limits, each an array of shape ``(nq,)`` in SI units.

    Attributes
    ----------
    names: joint names, in the order of q.
    units: ``"rad"`` (revolute) or ``"m"`` (prismatic) per joint.
    lower, upper: position limits [rad | m] (QC).
    velocity: max ``|q̇|`` [rad/s | m/s] (VC).
    acceleration: max ``|q̈|`` [rad/s² | m/s²] (WC); ``inf`` when unknown.
    jerk: max ``|q⃛|`` [rad/s³ | m/s³] (JC); ``inf`` when unknown.
    effort: max ``|u|`` [N·m | N] (UC).
    """

    names: tuple[str, ...]
    units: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray
    effort: np.ndarray

    def __post_init__(self) -> None:
        for field in ("lower", "upper", "velocity", "acceleration", "jerk", "effort"):
            object.__setattr__(self, field, readonly_copy(getattr(self, field)))

    @property
    def nq(self) -> int:
        """Number of joints."""
        return len(self.names)

    def violations(self, q: np.ndarray) -> np.ndarray:
        """Boolean mask (..., nq): where ``q`` (..., nq) lies outside [lower, upper]."""
        return (q < self.lower) | (q > self.upper)

    def check_position(self, q: object, name: str = "q") -> np.ndarray:
        """Return ``q`` (..., nq) as an array, raising :class:`JointLimitError` naming the
        joint, the value and the valid range if any entry is outside the position limits."""
        arr = as_batch(q, name, self.nq)
        bad = self.violations(arr)
        if bad.any():
            index = tuple(int(i) for i in np.argwhere(bad)[0])
            k = index[-1]
            where = f"{name}{list(index[:-1])}" if arr.ndim > 1 else name
            raise JointLimitError(
                f"{where}: joint '{self.names[k]}' = "
                f"{arr[index]:.6g} {self.units[k]} is outside its limits "
                f"[{self.lower[k]:.6g}, {self.upper[k]:.6g}] {self.units[k]}"
            )
        return arr
