r"""The six objectives of the paper (eqs. 1–6): their table, pymoo's sign convention, z3.

:data:`OBJECTIVES` is the one table of the objectives z1…z6 (name, quantity, unit, paper
equation, sense); :data:`OBJECTIVE_NAMES` and :data:`MAXIMISED` are its columns.

====  ========================================  =======  =====  =========
name  quantity                                  unit     paper  sense
====  ========================================  =======  =====  =========
z1    travel time :math:`T`                     s        eq. 1  minimised
z2    :math:`\int_0^T \sum_i \tau_i^2\,dt`      N²·m²·s  eq. 2  minimised
z3    clearance penalty                         \-       eq. 3  minimised
z4    :math:`\min_t |\det J(q(t))|`             m²       eq. 4  maximised
z5    :math:`\sum_i \int_0^T \dddot q_i^2\,dt`  rad²/s⁵  eq. 5  minimised
z6    :math:`\sum_i \int_0^T \ddot q_i^2\,dt`   rad²/s³  eq. 6  minimised
====  ========================================  =======  =====  =========

(z5, z6: m²/s⁵, m²/s³ for a prismatic joint; z3 is dimensionless by default, m⁻² with
``z3="paper-sphere"``.)

**Sign convention.** Objectives are reported as the quantities above, z4 positive
(:class:`~adept_traj.problem.Evaluation`, results, front files). pymoo minimises every
column, so the problem hands it :func:`to_pymoo` of them, where each maximised column is
negated; :func:`from_pymoo` turns pymoo's ``F`` back:

.. math::
    F_{:,k} = \sigma_k z_{:,k}, \qquad
    \sigma_k = \begin{cases} -1 & \text{objective } k \text{ maximised (z4)} \\
                             +1 & \text{otherwise.} \end{cases}

:func:`paper_penalty` is the paper's own collision penalty (eqs. 13–16), a variant of z3: it
replaces each obstacle by a circumscribing sphere or ellipsoid and scores how deep the tool
goes into it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.scene.shapes import Box
from adept_traj.validation import as_finite_array

__all__ = [
    "MAXIMISED",
    "OBJECTIVES",
    "OBJECTIVE_NAMES",
    "Objective",
    "from_pymoo",
    "paper_penalty",
    "paper_semi_axes",
    "to_pymoo",
]


@dataclass(frozen=True)
class Objective:
    """One objective of the trajectory problem (a row of :data:`OBJECTIVES`).

    Attributes
    ----------
    name:
        ``"z1"`` … ``"z6"``: the key in results, front files and plots.
    quantity:
        What it measures, short (``"time"``, ``"min|det J|"``, …).
    unit:
        SI unit of the reported value, ``"-"`` when dimensionless.
    equation:
        The paper's equation number.
    maximised:
        True when larger is better (z4); pymoo sees it negated (:func:`to_pymoo`).
    """

    name: str
    quantity: str
    unit: str
    equation: int
    maximised: bool = False

    @property
    def label(self) -> str:
        """Axis label with the unit, e.g. ``"z1 time [s]"``, ``"z4 min|det J| [m²] (max)"``."""
        return f"{self.name} {self.quantity} [{self.unit}]" + (" (max)" if self.maximised else "")


#: The objectives z1…z6, in the order of every objective array ``(..., 6)``.
OBJECTIVES: tuple[Objective, ...] = (
    Objective("z1", "time", "s", 1),
    Objective("z2", "∫Στ²", "N²·m²·s", 2),
    Objective("z3", "clearance penalty", "-", 3),
    Objective("z4", "min|det J|", "m²", 4, maximised=True),
    Objective("z5", "∫Σq⃛²", "rad²/s⁵", 5),
    Objective("z6", "∫Σq̈²", "rad²/s³", 6),
)

#: Names of the objectives in order, ``("z1", …, "z6")``.
OBJECTIVE_NAMES: tuple[str, ...] = tuple(o.name for o in OBJECTIVES)

#: Sense of each objective in order, True where maximised (only z4, the manipulability).
MAXIMISED: tuple[bool, ...] = tuple(o.maximised for o in OBJECTIVES)

#: Columns that pymoo sees negated (σ = −1 of the sign convention).
_NEGATED = np.flatnonzero(MAXIMISED)


def to_pymoo(objectives: Any) -> np.ndarray:
    """pymoo's ``F`` (every column minimised) of reported objectives: maximised columns
    negated.

    Parameters
    ----------
    objectives:
        (..., 6) z1…z6 as reported (z4 positive), units as in :data:`OBJECTIVES`.

    Returns
    -------
    numpy.ndarray
        (..., 6) new array: z4 negated, the other columns unchanged (bit for bit).
    """
    return _flip_maximised(objectives, "objectives")


def from_pymoo(F: Any) -> np.ndarray:
    """Reported objectives (z4 positive) of pymoo's ``F``: the inverse of :func:`to_pymoo`.

    Parameters
    ----------
    F:
        (..., 6) objectives as pymoo sees them (z4 negated).

    Returns
    -------
    numpy.ndarray
        (..., 6) new array: z4 positive again, the other columns unchanged (bit for bit).
    """
    return _flip_maximised(F, "F")


def _flip_maximised(values: Any, name: str) -> np.ndarray:
    """``values`` (..., 6) with the maximised columns negated (the map is its own inverse)."""
    try:
        arr = np.array(values, dtype=np.float64)  # a copy: the caller's array is not changed
    except (TypeError, ValueError):
        raise InvalidInputError(
            f"{name} must be a numeric array (..., 6); got {values!r}"
        ) from None
    if arr.ndim == 0 or arr.shape[-1] != len(OBJECTIVES):
        raise InputShapeError(
            f"{name} must have shape (..., {len(OBJECTIVES)}) (objectives "
            f"{', '.join(OBJECTIVE_NAMES)}); got {arr.shape}"
        )
    arr[..., _NEGATED] = -arr[..., _NEGATED]
    return arr


def paper_semi_axes(obstacles: Any, z3: str) -> np.ndarray:
    """Semi-axes (n_obs, 3) [m] of the paper's circumscribing volumes (eqs. 13, 15) of
    ``obstacles`` (a scene's :class:`~adept_traj.scene.Obstacle` tuple): a sphere of the
    shape's bounding radius, or, with ``z3 == "paper-ellipsoid"``, for a box the smallest
    ellipsoid with the box's axes containing it, √3 × its half sides (axis-aligned in the
    obstacle frame; the paper's cubes are axis-aligned)."""
    axes = []
    for ob in obstacles:
        if z3 == "paper-ellipsoid" and isinstance(ob.shape, Box):
            axes.append(np.sqrt(3.0) * 0.5 * np.asarray(ob.shape.size))
        else:
            axes.append(np.full(3, ob.shape.bounding_radius))
    return np.array(axes).reshape(-1, 3)


def paper_penalty(
    points: Any,
    centres: Any,
    semi_axes: Any,
    *,
    rotations: Any = None,
    equation: int = 16,
) -> np.ndarray:
    r"""The paper's collision penalty :math:`f_{dis}` (eqs. 13–16), batched.

    Each obstacle is replaced by a circumscribing sphere of radius :math:`r_0` or an
    ellipsoid with semi-axes a, b, c (in the obstacle's own axes); a trajectory point inside
    it penalises the motion. Eq. 14 (spheres, ``equation=14``; the semi-axes must be equal):

    .. math::
        r_t = \lVert x - x_0 \rVert, \qquad
        f_{dis} = \sum_{o:\ \min_t r_{t,o} \le r_{0,o}} \frac{1}{(\min_t r_{t,o})^2}

    Eq. 16 (ellipsoids, ``equation=16``), with :math:`u = R_o^\top (x - x_0)` the point in
    the obstacle's axes:

    .. math::
        r_e = \sum_k \frac{u_k^2}{a_k^2}, \qquad
        f_{dis} = \sum_{o:\ \min_t r_{e,o} \le 1} \frac{1}{(\min_t r_{e,o})^2}

    Parameters
    ----------
    points:
        (..., n_t, 3) trajectory points (the tool) [m].
    centres:
        (n_obs, ..., n_t, 3) obstacle centres at the same times [m] (broadcastable).
    semi_axes:
        (n_obs, 3) semi-axes [m] (:math:`r_0` three times for a sphere).
    rotations:
        (n_obs, ..., n_t, 3, 3) obstacle orientations (columns: the obstacle's axes in the
        points' frame), aligned like ``centres``; ``None``: axis-aligned.
    equation:
        14 or 16 (see above).

    Returns
    -------
    numpy.ndarray
        (...) penalty [m⁻² for eq. 14, dimensionless for eq. 16], 0 when no point enters any
        circumscribing volume.
    """
    p = as_finite_array(points, "points")
    c = as_finite_array(centres, "centres")
    ax = as_finite_array(semi_axes, "semi_axes")
    if equation not in (14, 16):
        raise InvalidInputError(f"equation must be 14 (spheres) or 16 (ellipsoids); got {equation}")
    if ax.ndim != 2 or ax.shape[1] != 3 or (ax <= 0).any():
        raise InvalidInputError(f"semi_axes must be (n_obs, 3) positive [m]; got {ax.shape}")
    if equation == 14 and not np.allclose(ax, ax[:, :1]):
        raise InvalidInputError("equation 14 needs spheres: equal semi-axes per obstacle")
    if p.ndim < 2 or p.shape[-1] != 3 or c.ndim < 2 or c.shape[-1] != 3:
        raise InputShapeError(
            f"points must be (..., n_t, 3) and centres (n_obs, ..., n_t, 3) [m]; got "
            f"{p.shape} and {c.shape}"
        )
    if c.shape[0] != ax.shape[0]:
        raise InputShapeError(f"centres has {c.shape[0]} obstacles but semi_axes has {ax.shape[0]}")
    # Align the centres' (..., n_t) with the points' from the right, after the obstacle axis.
    missing = p.ndim - (c.ndim - 1)
    if missing < 0:
        raise InputShapeError(
            f"centres {c.shape} has more batch axes than points {p.shape} (n_obs first)"
        )
    c = c.reshape(c.shape[0], *([1] * missing), *c.shape[1:])
    try:
        np.broadcast_shapes(p.shape, c.shape[1:])
    except ValueError:
        raise InputShapeError(
            f"centres (n_obs, ..., n_t, 3) must broadcast with points (..., n_t, 3); got "
            f"{c.shape} and {p.shape}"
        ) from None
    d = p[None] - c  # (n_obs, ..., n_t, 3)
    if rotations is not None:
        rot = as_finite_array(rotations, "rotations")
        if rot.shape[:1] != c.shape[:1] or rot.shape[-2:] != (3, 3):
            raise InputShapeError(
                f"rotations must be (n_obs, ..., n_t, 3, 3) like centres; got {rot.shape}"
            )
        rot = rot.reshape(rot.shape[0], *([1] * missing), *rot.shape[1:])
        d = (d[..., None, :] @ rot)[..., 0, :]  # R^T d as a row vector
    if equation == 14:
        r_t = np.min(np.linalg.norm(d, axis=-1), axis=-1)  # (n_obs, ...)
        inside = r_t <= ax[:, 0].reshape(-1, *([1] * (r_t.ndim - 1)))
        return np.sum(np.where(inside, 1.0 / np.maximum(r_t, 1e-12) ** 2, 0.0), axis=0)
    scaled = d / ax.reshape(ax.shape[0], *([1] * (c.ndim - 2)), 3)
    r_e = np.min(np.sum(scaled**2, axis=-1), axis=-1)  # (n_obs, ...)
    inside = r_e <= 1.0
    return np.sum(np.where(inside, 1.0 / np.maximum(r_e, 1e-12) ** 2, 0.0), axis=0)
