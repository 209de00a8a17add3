"""Mass properties of uniform solids and of rigid sets of them.

Used to derive each link's mass, centre of mass and inertia tensor from its solids
(the paper models the AdeptOne XL with 4 cylinders and 3 rectangular prisms).

All inertia tensors are ``(3, 3)`` arrays in [kg·m²]; positions in [m]; masses in [kg].
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from adept_traj.errors import InvalidInputError
from adept_traj.validation import as_scalar, as_vector

__all__ = ["MassProperties", "box_inertia", "combine", "cylinder_inertia", "sphere_inertia"]


@dataclass(frozen=True)
class MassProperties:
    """Mass [kg], centre of mass ``com`` (3,) [m] and inertia ``inertia`` (3, 3) [kg·m²]
    about the centre of mass, expressed in the frame the ``com`` is given in."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray


def box_inertia(mass: float, size: Sequence[float] | np.ndarray) -> np.ndarray:
    r"""Inertia (3, 3) [kg·m²] of a uniform box of mass ``mass`` [kg] and full side lengths
    ``size`` (3,) [m] about its centre, in its own axes (``pin.Inertia.FromBox``).

    .. math::
        I = \tfrac{m}{12}\operatorname{diag}\left(s_y^2 + s_z^2,\ s_x^2 + s_z^2,\
            s_x^2 + s_y^2\right)
    """
    m = as_scalar(mass, "mass", "[kg]", minimum=0.0, strict=True)
    sides = as_vector(size, "size", 3, "[m]")
    sx, sy, sz = (
        as_scalar(s, f"size_{axis}", "[m]", minimum=0.0, strict=True)
        for s, axis in zip(sides, "xyz")
    )
    return pin.Inertia.FromBox(m, sx, sy, sz).inertia.copy()


def cylinder_inertia(mass: float, radius: float, length: float) -> np.ndarray:
    r"""Inertia (3, 3) [kg·m²] of a uniform solid cylinder of mass ``mass`` [kg] (axis =
    local z, full ``length`` [m], ``radius`` [m]) about its centre
    (``pin.Inertia.FromCylinder``).

    .. math:: I_{zz} = \tfrac{m r^2}{2}, \quad I_{xx} = I_{yy} = \tfrac{m}{12}(3 r^2 + l^2)
    """
    m = as_scalar(mass, "mass", "[kg]", minimum=0.0, strict=True)
    r = as_scalar(radius, "radius", "[m]", minimum=0.0, strict=True)
    length = as_scalar(length, "length", "[m]", minimum=0.0, strict=True)
    return pin.Inertia.FromCylinder(m, r, length).inertia.copy()


def sphere_inertia(mass: float, radius: float) -> np.ndarray:
    r"""Inertia (3, 3) [kg·m²] of a uniform solid sphere of mass ``mass`` [kg] and radius
    ``radius`` [m] about its centre (``pin.Inertia.FromSphere``).

    .. math:: I = \tfrac{2}{5} m r^2 \mathbf{1}
    """
    m = as_scalar(mass, "mass", "[kg]", minimum=0.0, strict=True)
    r = as_scalar(radius, "radius", "[m]", minimum=0.0, strict=True)
    return pin.Inertia.FromSphere(m, r).inertia.copy()


def combine(parts: Iterable[tuple[float, np.ndarray, np.ndarray, np.ndarray]]) -> MassProperties:
    r"""Mass properties of a rigid set of solids.

    Each part is ``(mass, position (3,), rotation (3, 3), inertia (3, 3))``: the solid's
    centre and axes in the common frame and its inertia about its centre in its own axes.
    The result's inertia is about the combined centre of mass, by the parallel-axis theorem:

    .. math::
        I = \sum_k R_k I_k R_k^\top
            + m_k \left(\lVert d_k\rVert^2 \mathbf{1} - d_k d_k^\top\right),
        \quad d_k = p_k - c
    """
    items = [
        (float(m), np.asarray(p, float), np.asarray(r, float), np.asarray(i, float))
        for m, p, r, i in parts
    ]
    if not items:
        raise InvalidInputError("combine() needs at least one solid")
    total = sum(m for m, *_ in items)
    com = sum(m * p for m, p, *_ in items) / total
    inertia = np.zeros((3, 3))
    for m, p, r, i in items:
        d = p - com
        inertia += r @ i @ r.T + m * (d @ d * np.eye(3) - np.outer(d, d))
    return MassProperties(mass=total, com=com, inertia=inertia)
