"""The six objectives of the paper (eqs. 5–16): here the paper's collision penalty z3.

The penalty is an objective of the trajectory problem, not a distance query: it replaces each
obstacle by a circumscribing sphere or ellipsoid and scores how deep the tool goes into it.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.validation import as_finite_array

__all__ = ["paper_penalty"]


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
