r"""Single-joint distance tables: a broad-phase level for solids moved by one joint only.

A solid whose parent joint hangs directly from the fixed base (the SCARA's inner arm, on
joint 1) has a pose that depends on that one joint value :math:`q_j`; against a fixed
obstacle its signed distance is a function :math:`d(q_j)` of one variable. It is
tabulated once, exactly (coal), on a grid :math:`q_i = q_0 + i h` over the joint's range,
and bounded between grid points by its Lipschitz constant:

.. math::
    d(q) \ge \max\big(d(q_i) - L\,(q - q_i),\ d(q_{i+1}) - L\,(q_{i+1} - q)\big) - \epsilon,
    \qquad q_i \le q \le q_{i+1},

with :math:`L = \rho + R` for a revolute joint (ρ the distance of the solid's enclosing-ball
centre from the joint axis, R the ball's radius: no point of the solid moves faster than
:math:`L\,|\dot q|`) and :math:`L = 1` for a prismatic one, and ε = 5e-6 m for the
accuracy of coal's distances (they understate a penetration depth by up to 3.4 µm, see
:mod:`adept_traj.collision.primitives`). A signed distance changes by at most the largest
displacement of the moving convex solid (for separation and for penetration depth alike),
so the bound is valid everywhere; with h = 1 mrad it is at most :math:`L h` below the
exact distance (≈ 0.6 mm for the AdeptOne's inner arm; about :math:`L h / 2` typically).
Outside the grid the bound is :math:`-\infty` (no information), so the other levels
decide there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["DistanceTable", "table_bounds"]

#: Subtracted from every bound [m]: coal's distances between primitives exceed the true
#: distance by at most 3.4 µm (penetration; 2 nm beyond 1 mm of separation, measured in
#: collision.primitives), so a tabulated value minus this never exceeds the true distance.
_SLACK = 5e-6


@dataclass(frozen=True)
class DistanceTable:
    """Exact signed distances [m] of one solid–obstacle pair over one joint's range.

    Attributes
    ----------
    joint: index in q of the joint that moves the solid.
    start: joint value [rad | m] of the first grid point.
    step: grid step h [rad | m] (> 0).
    values: (G,) exact signed distances [m] at the G ≥ 2 grid points.
    lipschitz: L [m/rad | m/m], a bound on how fast the distance changes with the joint.
    """

    joint: int
    start: float
    step: float
    values: np.ndarray
    lipschitz: float

    def lower_bound(self, q: np.ndarray) -> np.ndarray:
        """(N,) lower bound [m] of the signed distance at joint values ``q`` (N,)
        [rad | m] (see the module docstring); ``-inf`` outside the grid."""
        return self.bound_at(self.grid_position(q))

    def grid_position(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Where the joint values ``q`` (N,) [rad | m] fall on the grid: (within the grid
        (N,) bool, the grid interval's index i (N,), the position within it (N,) in
        [0, 1]); the same for every table of the same :attr:`grid`."""
        u = (q - self.start) / self.step
        last = len(self.values) - 1
        inside = (u >= 0.0) & (u <= last)
        i = np.clip(np.floor(u), 0, last - 1).astype(np.intp)
        return inside, i, np.clip(u - i, 0.0, 1.0)

    def bound_at(self, at: tuple[np.ndarray, np.ndarray, np.ndarray]) -> np.ndarray:
        """:meth:`lower_bound` at a :meth:`grid_position` ``at`` on this table's grid."""
        inside, i, frac = at
        slope = self.lipschitz * self.step
        bound = np.maximum(self.values[i] - slope * frac, self.values[i + 1] - slope * (1.0 - frac))
        return np.where(inside, bound - _SLACK, -np.inf)

    @property
    def grid(self) -> tuple[int, float, float, int]:
        """(joint, start, step, number of grid points)."""
        return self.joint, self.start, self.step, len(self.values)


def table_bounds(
    tables: dict[tuple[int, int], DistanceTable], q: np.ndarray
) -> dict[tuple[int, int], np.ndarray]:
    """:meth:`DistanceTable.lower_bound` (N,) [m] of every table (by its key) at the
    configurations ``q`` (N, nq) [rad | m]; tables on the same grid (e.g. one solid against
    several obstacles) share one :meth:`~DistanceTable.grid_position`."""
    grids: dict[tuple[int, float, float, int], tuple[np.ndarray, ...]] = {}
    out = {}
    for key, table in tables.items():
        at = grids.get(table.grid)
        if at is None:
            at = grids[table.grid] = table.grid_position(q[:, table.joint])
        out[key] = table.bound_at(at)
    return out
