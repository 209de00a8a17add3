r"""Lever arms: how fast a robot solid, or the gap between two solids, can move.

A point :math:`p` of solid :math:`s` moves at
:math:`\dot p = \sum_j \dot q_j\, a_j \times (p - o_j)` (revolute joints :math:`j` moving
the solid, axis :math:`a_j` through :math:`o_j`) :math:`+ \sum_j \dot q_j a_j` (prismatic), so
:math:`\lVert \dot p \rVert \le \sum_j r_{sj} |\dot q_j|` with the configuration-free
factors of :func:`solid_lever_arms` (module docstring of
:mod:`adept_traj.certification.continuous` for the formula).

**Pairs of solids.** A joint that moves both solids of a pair moves them as one rigid body
and leaves their distance unchanged, so (:func:`pair_lever_arms`)

.. math::
    |\dot d_{ab}| \le \sum_{j \in J_a \setminus J_b} r_{aj} |\dot q_j|
                   + \sum_{j \in J_b \setminus J_a} r_{bj} |\dot q_j|,

:math:`J_s` the joints moving solid :math:`s`. Along a straight joint-space segment the
same factors bound the change of the distance:
:math:`|d_{ab}(q) - d_{ab}(q')| \le \sum_j \rho_{abj} |q_j - q'_j|`.
"""

from __future__ import annotations

import numpy as np

from adept_traj.collision.primitives import enclosing_ball
from adept_traj.robot.robot import Robot, solid_frames

__all__ = ["pair_lever_arms", "solid_lever_arms"]


def solid_lever_arms(robot: Robot) -> np.ndarray:
    r"""(n_solids, nq) factors :math:`r_{sj}`: solid ``s`` moves at most
    :math:`\sum_j r_{sj} |\dot q_j|` [m/s]; [m] for a revolute joint (bound on the distance
    of its points from the joint origin), 1 for a prismatic joint, 0 for a joint that does
    not move the solid."""
    kin, model = robot.kinematics, robot.model
    parents, local = solid_frames(robot.collision_model)
    lim = robot.limits
    out = np.zeros((len(parents), robot.nq))
    for s, geometry in enumerate(robot.collision_model.geometryObjects):
        centre, radius = enclosing_ball(geometry.geometry)
        reach = float(np.linalg.norm(local[s, :3, :3] @ centre + local[s, :3, 3])) + radius
        frame = int(parents[s])
        while frame > 0:  # walk from the solid's joint to the root, growing the reach
            k = model.joints[frame].idx_q
            if kin.revolute[frame - 1]:
                out[s, k] = reach
            else:
                out[s, k] = 1.0
                reach += max(abs(float(lim.lower[k])), abs(float(lim.upper[k])))
            reach += float(np.linalg.norm(model.jointPlacements[frame].translation))
            frame = int(kin.parents[frame - 1])
    return out


def pair_lever_arms(robot: Robot, pairs: np.ndarray) -> np.ndarray:
    r"""(n_pairs, nq) factors :math:`\rho_{abj}` for solid index pairs ``pairs``
    (n_pairs, 2): the distance of pair ``(a, b)`` changes at most at
    :math:`\sum_j \rho_{abj} |\dot q_j|` [m/s] (module docstring); a joint moving both
    solids counts 0."""
    arms = solid_lever_arms(robot)
    a, b = arms[pairs[:, 0]], arms[pairs[:, 1]]
    return np.where(b > 0, 0.0, a) + np.where(a > 0, 0.0, b)
