r"""Robot–obstacle distances per sample with their exact derivatives in the state (q, t).

:func:`distance_gradients` gives, for configurations ``q`` (..., n_t, nq) at times ``t``
(..., n_t) [s], the smallest signed distance :math:`d_o` [m] between the robot's solids and
each obstacle o (as :meth:`CollisionChecker.distances` minimised over the solids) and its
derivatives :math:`\partial d_o / \partial q` and :math:`\partial d_o / \partial t`, from
coal's witness points and normal instead of finite differences.

For the closest solid and obstacle coal returns the nearest points :math:`p_1` (on the
solid) and :math:`p_2` (on the obstacle) and the unit normal :math:`n` from the solid
towards the obstacle, all in the robot base frame; moving the obstacle by :math:`\delta`
along :math:`n` increases the distance by :math:`\delta`, moving the solid does the
opposite. Hence, with :math:`J_p(q)` (3, nq) the translational Jacobian of the point
:math:`p_1` rigidly attached to the solid's joint (for a revolute joint k the column
:math:`z_k \times (p_1 - o_k)`, prismatic :math:`z_k`;
:meth:`~adept_traj.robot.BatchKinematics.frame_jacobian`) and :math:`v_o(p_2, t)` the
velocity of the obstacle's point :math:`p_2` (:meth:`~adept_traj.scene.MotionLaw.point_velocity`,
0 for a fixed obstacle, the closed form for the pendulum's rod and bob):

.. math::
    \frac{\partial d_o}{\partial q} = -\,n^\top J_{p_1}(q), \qquad
    \frac{\partial d_o}{\partial t} = n^\top v_o(p_2, t).

The rotation part needs no separate term: :math:`p_2 - p_1` is parallel to :math:`n`, so
any point of the segment gives the same :math:`n^\top (\omega \times (p - o))`.

**Where it is exact.** Where the smallest distance is unique and the witness points vary
smoothly (separated convex solids, almost everywhere), the formulas are the derivatives of
the distance. Where two solids tie for the minimum the closest one's gradient is taken (a
subgradient of the minimum). Where the broad phase settles every solid of an obstacle as
farther than ``influence``, the derivatives are 0: exact for the clipped
:math:`\min(d_o, \delta)` the constraints use. **Penetration** (:math:`d_o < 0`): coal's
EPA normal and witness points give the derivative of the penetration depth along that
normal; it is the gradient where the contact feature is unique (a face, a sphere), and a
subgradient at a switch of features. EPA is accurate to about 3 µm (see
:mod:`adept_traj.collision.primitives`), so the gradient there is good enough to push out,
not a certificate.

One coal call per sample and obstacle closer than ``influence`` (the only Python loop, over
close pairs); the Jacobians and velocities are batched.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import coal
import numpy as np

from adept_traj.collision.checker import CollisionChecker
from adept_traj.collision.primitives import DISTANCE_TOLERANCE, distance_request

__all__ = ["WITNESS_TOLERANCES", "DistanceGradients", "distance_gradients"]

#: GJK tolerances of the witness calls, tried in turn. GJK stops when the distance is within
#: its tolerance, and on curved solids (cylinders, capsules) a distance error ε leaves the
#: witness points off by about :math:`\\sqrt{\\varepsilon r}` and the normal by
#: :math:`\\sqrt{\\varepsilon / r}`: with the distances' 1e-9 m the gradient of the
#: AdeptOne's outer arm against the pendulum rod (r = 1 cm) was 1e-4 off (relative), with
#: 1e-14 m 2e-6, for a little more time per call. At 1e-14 GJK fails now and then (coal 3.0.3
#: returned −1.8e308 and NaN points for a cylinder 3 cm from a box): the next one is used.
WITNESS_TOLERANCES: tuple[float, ...] = (1e-14, 1e-12, DISTANCE_TOLERANCE)

#: Largest difference [m] between a witness call's distance and the checker's for the
#: witness to be used (EPA's depths from different GJK simplices differ by a few µm).
_AGREE = 1e-5


@dataclass(frozen=True)
class DistanceGradients:
    """Smallest robot–obstacle distances per sample and their derivatives in the state.

    Attributes
    ----------
    distance:
        (..., n_t, n_obstacles) smallest signed distance over the solids [m]: exact where
        below the checker's ``influence``, else a lower bound at least ``influence``.
    dq:
        (..., n_t, n_obstacles, nq) :math:`\\partial d / \\partial q` [m/rad | m/m];
        0 where ``distance`` ≥ ``influence``.
    dt:
        (..., n_t, n_obstacles) :math:`\\partial d / \\partial t` [m/s] (obstacle motion);
        0 for fixed obstacles and where ``distance`` ≥ ``influence``.
    solid:
        (..., n_t, n_obstacles) int, index of the closest solid where the derivatives were
        computed, -1 elsewhere.
    n_narrow:
        Number of coal distance calls (of the distances and of the witnesses).
    """

    distance: np.ndarray
    dq: np.ndarray
    dt: np.ndarray
    solid: np.ndarray
    n_narrow: int


def distance_gradients(checker: CollisionChecker, q: Any, t: Any) -> DistanceGradients:
    """Smallest distances to every obstacle of configurations ``q`` (..., n_t, nq)
    [rad | m] at times ``t`` (..., n_t) [s] and their derivatives (see the module
    docstring).

    Parameters
    ----------
    checker:
        The :class:`~adept_traj.collision.CollisionChecker` (robot, scene, influence).
    q, t:
        Configurations and times, as for :meth:`CollisionChecker.distances`.
    """
    qa, ta = checker.checked_motion(q, t)
    return _distance_gradients(checker, qa, ta)


def _distance_gradients(checker: CollisionChecker, q: np.ndarray, t: np.ndarray):
    nq, n_obs = q.shape[-1], checker.n_obstacles
    pairs = checker.distances(q, t)
    n_samples = int(np.prod(q.shape[:-1]))
    flat = pairs.distance.reshape(n_samples, checker.n_solids, n_obs)
    distance = flat.min(axis=1)  # (N, n_obs)
    closest = flat.argmin(axis=1)
    rows, obstacles = np.nonzero(distance < checker.influence)
    solids = closest[rows, obstacles]
    dq = np.zeros((n_samples, n_obs, nq))
    dt = np.zeros((n_samples, n_obs))
    solid = np.full((n_samples, n_obs), -1)
    solid[rows, obstacles] = solids
    if len(rows):
        frames = checker.robot.kinematics.joint_frames(q)
        p1, p2, normal = _witnesses(
            checker, frames, t.reshape(-1), rows, solids, obstacles, distance[rows, obstacles]
        )
        dq[rows, obstacles] = _solid_term(checker, frames, rows, solids, p1, normal)
        dt[rows, obstacles] = _obstacle_term(checker, t.reshape(-1), rows, obstacles, p2, normal)
    shape = (*q.shape[:-1], n_obs)
    return DistanceGradients(
        distance=distance.reshape(shape),
        dq=dq.reshape(*shape, nq),
        dt=dt.reshape(shape),
        solid=solid.reshape(shape),
        n_narrow=pairs.n_narrow + len(rows),
    )


def _witnesses(
    checker: CollisionChecker,
    frames: np.ndarray,
    t: np.ndarray,
    rows: np.ndarray,
    solids: np.ndarray,
    obstacles: np.ndarray,
    distance: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Coal's nearest points on the solid and on the obstacle and the normal (m, 3) each,
    base frame, of the pairs (``rows``, ``solids``, ``obstacles``) (m,) whose distances
    [m] are ``distance`` (m,): the first of :data:`WITNESS_TOLERANCES` whose distance
    agrees with it to :data:`_AGREE` (all zero, a zero gradient, if none does: not met on
    the shipped scenes)."""
    poses = checker.broad_phase.solid_poses(frames, rows, solids)
    obstacle_poses = checker.obstacle_poses(t)
    out = np.zeros((3, len(rows), 3))
    requests, result = _witness_requests(), coal.DistanceResult()
    tf_solid, tf_obstacle = coal.Transform3s(), coal.Transform3s()
    for i, (n, k, o) in enumerate(zip(rows.tolist(), solids.tolist(), obstacles.tolist())):
        pose = checker.pose_at(obstacle_poses[o], n)
        tf_solid.setRotation(poses[i, :3, :3])
        tf_solid.setTranslation(poses[i, :3, 3])
        tf_obstacle.setRotation(pose[:3, :3])
        tf_obstacle.setTranslation(pose[:3, 3])
        for request in requests:  # GJK may fail at the tightest tolerance: loosen
            result.clear()
            d = checker.functors[k][o](tf_solid, tf_obstacle, request, result)
            if abs(d - distance[i]) <= _AGREE:
                out[:, i] = result.getNearestPoint1(), result.getNearestPoint2(), result.normal
                break
    return out[0], out[1], out[2]


def _witness_requests() -> list[coal.DistanceRequest]:
    """The package's distance request (EPA as for the distances) with GJK's tolerance set
    to each of :data:`WITNESS_TOLERANCES`."""
    requests = []
    for tolerance in WITNESS_TOLERANCES:
        request = distance_request()
        request.gjk_tolerance = tolerance
        requests.append(request)
    return requests


def _solid_term(
    checker: CollisionChecker,
    frames: np.ndarray,
    rows: np.ndarray,
    solids: np.ndarray,
    p1: np.ndarray,
    normal: np.ndarray,
) -> np.ndarray:
    """(m, nq) :math:`-n^\\top J_{p_1}`, batched per joint carrying the solids."""
    kinematics, parents = checker.robot.kinematics, checker.broad_phase.parents
    out = np.empty((len(rows), checker.robot.nq))
    joint = np.asarray(parents)[solids]
    for j in np.unique(joint).tolist():
        sel = np.flatnonzero(joint == j)
        jac = kinematics.frame_jacobian(frames[..., rows[sel]], j, p1[sel].T)  # (6, nq, m)
        out[sel] = -np.einsum("mi,ijm->mj", normal[sel], jac[:3])
    return out


def _obstacle_term(
    checker: CollisionChecker,
    t: np.ndarray,
    rows: np.ndarray,
    obstacles: np.ndarray,
    p2: np.ndarray,
    normal: np.ndarray,
) -> np.ndarray:
    """(m,) :math:`n^\\top v_o(p_2, t)` (base frame), batched per moving obstacle."""
    out = np.zeros(len(rows))
    to_base = checker.scene.base_from_world
    to_world = np.linalg.inv(to_base)
    for o, ob in enumerate(checker.scene.obstacles):
        sel = np.flatnonzero(obstacles == o)
        if not ob.is_moving or len(sel) == 0:
            continue
        world = p2[sel] @ to_world[:3, :3].T + to_world[:3, 3]
        times = checker.scene_time(t[rows[sel]])  # the scene's clock, t0 + t
        velocity = ob.motion.point_velocity(times, world) @ to_base[:3, :3].T
        out[sel] = np.einsum("mi,mi->m", normal[sel], velocity)
    return out
