"""The closest points between the robot and the obstacles, per frame of a playback.

For every frame, the pair (robot collision solid, obstacle) nearest to each other and its
two witness points, in the world frame [m]:

* a **sphere obstacle** (the pendulum's bob, centre :math:`c`, radius :math:`r`) and a
  primitive solid :math:`A` in closed form, with the library's exact point distance
  :func:`~adept_traj.collision.point_signed_distance` (the one the collision checker uses):

  .. math::
      d = d_A(c) - r, \\qquad n = \\nabla d_A(c), \\qquad
      p_A = c - d_A(c)\\, n, \\qquad p_B = c - r\\, n

  (:math:`n` the unit outward normal of :math:`A`'s distance field at :math:`c`, by central
  differences; :math:`\\lVert p_A - p_B \\rVert = |d|` holds exactly). This is also right
  under penetration, where coal 3.0.3's sphere–cylinder depth is wrong near a cap.
* every other pair by coal (``DistanceResult.getNearestPoint1/2``), one call per frame.
"""

from __future__ import annotations

import coal
import numpy as np

from adept_traj.collision import coal_kind, distance_request, point_signed_distance, shape_of
from adept_traj.robot import Robot
from adept_traj.scene import Scene, Shape, Sphere

__all__ = ["closest_points"]

#: Step [m] of the central differences giving the normal of a solid's distance field.
NORMAL_STEP = 1e-6


def closest_points(
    robot: Robot, scene: Scene, q: np.ndarray, times: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Witness points and signed distance of the nearest solid–obstacle pair per frame.

    Parameters
    ----------
    robot: the robot (its collision model gives the solids).
    scene: the obstacles and the robot base pose in the world.
    q: (n, nq) joint positions [rad | m].
    times: (n,) scene times of the frames [s] (moving obstacles' poses: a move started
        at scene time t0 passes t0 + t).

    Returns
    -------
    points: (n, 2, 3) world points on the robot and on the obstacle [m].
    distance: (n,) their signed distance [m] (negative: penetration depth).
    """
    solids = scene.robot_base @ robot.geometry_poses(q)  # (n, n_solids, 4, 4), world
    obstacles = scene.obstacle_poses(times)  # (n_obs, n, 4, 4), world
    n = solids.shape[0]
    distance = np.full(n, np.inf)
    points = np.zeros((n, 2, 3))
    for s, gobj in enumerate(robot.collision_model.geometryObjects):
        shape = shape_of(coal_kind(gobj.geometry))
        for o, ob in enumerate(scene.obstacles):
            if shape is not None and isinstance(ob.shape, Sphere):
                d, p = _sphere_pair(shape, solids[:, s], obstacles[o, :, :3, 3], ob.shape.radius)
            else:
                d, p = _coal_pair(gobj.geometry, solids[:, s], ob.shape.to_coal(), obstacles[o])
            closer = d < distance
            distance[closer] = d[closer]
            points[closer] = p[closer]
    return points, distance


def _sphere_pair(
    shape: Shape, solid: np.ndarray, centre: np.ndarray, radius: float
) -> tuple[np.ndarray, np.ndarray]:
    """Signed distance (n,) and witness points (n, 2, 3) [m] of a primitive solid at poses
    ``solid`` (n, 4, 4) and a sphere of centres ``centre`` (n, 3) and ``radius``."""
    rot = solid[:, :3, :3]
    local = np.einsum("nji,nj->ni", rot, centre - solid[:, :3, 3])  # R^T (c - t)
    d_centre = point_signed_distance(shape, local)
    step = NORMAL_STEP * np.eye(3)
    ahead = point_signed_distance(shape, local[:, None, :] + step)  # (n, 3)
    behind = point_signed_distance(shape, local[:, None, :] - step)
    grad = (ahead - behind) / (2.0 * NORMAL_STEP)
    length = np.linalg.norm(grad, axis=-1, keepdims=True)
    # a centre on the solid's medial axis has no unique normal: any unit vector will do
    normal = np.where(length > 0.5, grad / np.maximum(length, 1e-300), [0.0, 0.0, 1.0])
    normal = np.einsum("nij,nj->ni", rot, normal)  # world
    robot_point = centre - d_centre[:, None] * normal
    obstacle_point = centre - radius * normal
    return d_centre - radius, np.stack([robot_point, obstacle_point], axis=1)


def _coal_pair(
    geometry: coal.CollisionGeometry,
    solid: np.ndarray,
    obstacle: coal.CollisionGeometry,
    obstacle_poses: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """Signed distance (n,) and witness points (n, 2, 3) [m] by coal, for the solid at
    poses ``solid`` (n, 4, 4) and the obstacle at ``obstacle_poses`` (n, 4, 4)."""
    n = solid.shape[0]
    distance, points = np.empty(n), np.empty((n, 2, 3))
    request, result = distance_request(), coal.DistanceResult()  # the checker's settings
    tf_solid, tf_obstacle = coal.Transform3s(), coal.Transform3s()
    for k in range(n):
        tf_solid.setRotation(solid[k, :3, :3])
        tf_solid.setTranslation(solid[k, :3, 3])
        tf_obstacle.setRotation(obstacle_poses[k, :3, :3])
        tf_obstacle.setTranslation(obstacle_poses[k, :3, 3])
        result.clear()
        distance[k] = coal.distance(geometry, tf_solid, obstacle, tf_obstacle, request, result)
        points[k, 0] = result.getNearestPoint1()
        points[k, 1] = result.getNearestPoint2()
    return distance, points
