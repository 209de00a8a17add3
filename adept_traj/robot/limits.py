"""Joint limits of a robot (paper Table 2, constraints (7)–(11)) and the one vocabulary of
limit kinds used across the package.

A *limit kind* is one of ``position``, ``velocity``, ``acceleration``, ``jerk``, ``torque``
(:data:`LIMIT_KINDS`). Each kind bounds one quantity along a trajectory, whose values are held
in arrays named by its quantity — ``q``, ``qd``, ``qdd``, ``qddd``, ``tau`` (the fields of
sampled trajectories, the CSV columns and result.json) — and has the paper's symbol QC, VC,
WC, JC, UC. :data:`LIMITS` is the single table that links the three; no other module spells
these lists out. External formats keep their own words at their boundary only: URDF and ROS
say ``effort`` for the torque limit and the torques.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import InvalidInputError, JointLimitError
from adept_traj.validation import DeepEqual, as_batch, readonly_copy

__all__ = ["LIMITS", "LIMIT_KINDS", "JointLimits", "LimitKind"]


@dataclass(frozen=True)
class LimitKind:
    """One kind of joint limit.

    Attributes
    ----------
    name: the kind (``"position"``, ``"velocity"``, ``"acceleration"``, ``"jerk"``,
        ``"torque"``); also the :class:`JointLimits` field holding its bound, except
        ``position``, bounded by ``lower`` and ``upper``.
    quantity: the name of the bounded quantity's arrays (``"q"``, ``"qd"``, ``"qdd"``,
        ``"qddd"``, ``"tau"``).
    order: the derivative order of q it bounds (0–3), ``None`` for the torque.
    symbol: the paper's symbol (Table 2): ``"QC"``, ``"VC"``, ``"WC"``, ``"JC"``, ``"UC"``.
    units: the unit of the bound for a revolute and for a prismatic joint.
    """

    name: str
    quantity: str
    order: int | None
    symbol: str
    units: tuple[str, str]


#: The limit kinds in the order of the paper's constraints (7)–(11).
LIMITS: tuple[LimitKind, ...] = (
    LimitKind("position", "q", 0, "QC", ("rad", "m")),
    LimitKind("velocity", "qd", 1, "VC", ("rad/s", "m/s")),
    LimitKind("acceleration", "qdd", 2, "WC", ("rad/s²", "m/s²")),
    LimitKind("jerk", "qddd", 3, "JC", ("rad/s³", "m/s³")),
    LimitKind("torque", "tau", None, "UC", ("N·m", "N")),
)
#: The names of :data:`LIMITS`, in order.
LIMIT_KINDS: tuple[str, ...] = tuple(kind.name for kind in LIMITS)


@dataclass(frozen=True, init=False, eq=False)
class JointLimits(DeepEqual):
    """Per-joint limits, each an array of shape ``(nq,)`` in SI units.

    Attributes
    ----------
    names: joint names, in the order of q.
    units: ``"rad"`` (revolute) or ``"m"`` (prismatic) per joint.
    lower, upper: position limits [rad | m] (QC).
    velocity: max ``|q̇|`` [rad/s | m/s] (VC).
    acceleration: max ``|q̈|`` [rad/s² | m/s²] (WC); ``inf`` when unknown.
    jerk: max ``|q⃛|`` [rad/s³ | m/s³] (JC); ``inf`` when unknown.
    torque: max ``|τ|`` [N·m | N] (UC); URDF calls it ``effort``. The keyword ``effort=``
        is still accepted (deprecated, with a :class:`DeprecationWarning`).
    """

    names: tuple[str, ...]
    units: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    jerk: np.ndarray
    torque: np.ndarray

    def __init__(
        self,
        names: tuple[str, ...],
        units: tuple[str, ...],
        lower: Any,
        upper: Any,
        velocity: Any,
        acceleration: Any,
        jerk: Any,
        torque: Any = None,
        *,
        effort: Any = None,
    ) -> None:
        if effort is not None:
            if torque is not None:
                raise InvalidInputError("give torque (or the deprecated effort), not both")
            warnings.warn(
                "JointLimits(effort=...) is deprecated; use torque=...",
                DeprecationWarning,
                stacklevel=2,
            )
            torque = effort
        if torque is None:
            raise InvalidInputError("torque limits [N·m | N] are required (one per joint)")
        object.__setattr__(self, "names", tuple(names))
        object.__setattr__(self, "units", tuple(units))
        values = (lower, upper, velocity, acceleration, jerk, torque)
        for field, value in zip(
            ("lower", "upper", "velocity", "acceleration", "jerk", "torque"), values
        ):
            object.__setattr__(self, field, readonly_copy(value))

    @property
    def effort(self) -> np.ndarray:
        """Deprecated name of :attr:`torque` (URDF's word); use ``torque``."""
        warnings.warn(
            "JointLimits.effort is deprecated; use JointLimits.torque",
            DeprecationWarning,
            stacklevel=2,
        )
        return self.torque

    def bound(self, kind: str) -> np.ndarray:
        """The (nq,) bound on ``|value|`` of a limit kind other than ``position``
        [unit of the kind]; ``inf`` where a joint has none."""
        if kind not in LIMIT_KINDS or kind == "position":
            raise InvalidInputError(
                f"kind must be one of {LIMIT_KINDS[1:]} (position has lower and upper); "
                f"got {kind!r}"
            )
        return getattr(self, kind)

    @property
    def nq(self) -> int:
        """Number of joints."""
        return len(self.names)

    def violations(self, q: np.ndarray) -> np.ndarray:
        """Boolean mask (..., nq): where ``q`` (..., nq) lies outside [lower, upper]."""
        return (q < self.lower) | (q > self.upper)

    def check_position(self, q: object, name: str = "q") -> np.ndarray:
        """Return ``q`` (..., nq) as an array, raising :class:`JointLimitError` naming
        every joint outside its position limits (of the first configuration with one), its
        value and its valid range."""
        arr = as_batch(q, name, self.nq)
        bad = self.violations(arr)
        if bad.any():
            first = tuple(int(i) for i in np.argwhere(bad)[0][:-1])
            where = f"{name}{list(first)}" if arr.ndim > 1 else name
            row = arr[first]
            parts = [
                f"joint '{self.names[k]}' = {row[k]:.6g} {self.units[k]} is outside its limits "
                f"[{self.lower[k]:.6g}, {self.upper[k]:.6g}] {self.units[k]}"
                for k in np.flatnonzero(bad[first])
            ]
            raise JointLimitError(f"{where}: " + "; ".join(parts))
        return arr
