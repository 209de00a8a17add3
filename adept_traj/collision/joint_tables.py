"""The broad phase's single-joint distance tables (its level 0 for a solid moved by one
joint hanging from the base and a fixed obstacle, :mod:`adept_traj.collision.broad_phase`):
which pairs get one (:func:`table_joint`, :func:`sweep_reaches`) and their exact distances
over the joint's range (:func:`tabulate`, coal); :func:`joint_tables` makes them all,
taking over those already made (:func:`kept_tables`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import coal
import numpy as np

from adept_traj.collision.distance_table import DistanceTable
from adept_traj.collision.primitives import distance_request
from adept_traj.collision.pruning import sweep_clearance
from adept_traj.robot.robot import Robot
from adept_traj.scene.scene import Scene

if TYPE_CHECKING:  # the broad phase imports this module
    from adept_traj.collision.broad_phase import BroadPhase

__all__ = ["MAX_POINTS", "TABLE_REACH", "TABLE_STEP", "joint_tables", "kept_tables",
           "sweep_reaches", "table_joint", "tabulate"]  # fmt: skip

#: Grid step [rad | m] of the single-joint distance tables (level 0).
TABLE_STEP = 1e-3
#: A solid that stays farther than ``influence`` + this [m] from an obstacle over a full turn
#: of its joint gets no table against it: its level-1 bound exceeds that distance anyway
#: (the paper's cube 2, 0.37 m from the inner arm's sweep, keeps its tables).
TABLE_REACH = 0.4
#: Joints with a longer range (e.g. unlimited) get no table.
MAX_POINTS = 20_000


def joint_tables(
    broad: BroadPhase,
    robot: Robot,
    scene: Scene,
    geometries: Sequence[coal.CollisionGeometry],
    known: Mapping[tuple[int, int], DistanceTable],
) -> dict[tuple[int, int], DistanceTable]:
    """The tables of ``broad`` by (solid, obstacle): every pair :func:`table_joint` and
    :func:`sweep_reaches` admit, taken from ``known`` where it holds one over the same joint
    (its values depend on the solid, the obstacle and the base pose alone), else
    tabulated (``geometries``: the solids' coal geometries)."""
    tables = {}
    for k in range(broad.n_solids):
        for o in range(broad.n_obstacles):
            j = table_joint(broad, robot, k, o)
            if j is not None and sweep_reaches(broad, robot, scene, k, o):
                given = known.get((k, o))
                if given is None or given.joint != j:
                    given = tabulate(broad, robot, scene, k, o, j, geometries[k])
                tables[k, o] = given
    return tables


def table_joint(broad: BroadPhase, robot: Robot, k: int, o: int) -> int | None:
    """The joint (index in q) to tabulate solid ``k`` and obstacle ``o`` over, or None:
    a table needs a primitive solid moved by one joint hanging from the base (with a
    finite range), a fixed obstacle, and no other exact level for the pair."""
    p = int(broad.parents[k])
    if p == 0 or robot.kinematics.parents[p - 1] != 0:
        return None
    j = int(np.flatnonzero(robot.kinematics.support[p])[0])  # the only joint moving p
    span = robot.limits.upper[j] - robot.limits.lower[j]
    kinds = (broad.solid_kind[k], broad.obstacle_kind[o])
    tabulable = (
        bool(np.isfinite(span))
        and span / TABLE_STEP <= MAX_POINTS
        and not broad.moving[o]
        and not broad.closed_form[k, o]
        and None not in kinds
        and all(kind[0] != "sphere" for kind in kinds)  # coal's sphere depths (level 2)
    )
    return j if tabulable else None


def sweep_reaches(broad: BroadPhase, robot: Robot, scene: Scene, k: int, o: int) -> bool:
    """Whether solid ``k``, turned through a full revolution of its parent joint (from
    :func:`table_joint`), may come within ``influence`` + :data:`TABLE_REACH` of
    fixed obstacle ``o``
    (:func:`~adept_traj.collision.pruning.sweep_clearance`); a prismatic joint: yes."""
    p, kin = int(broad.parents[k]), robot.kinematics
    if not kin.revolute[p - 1]:
        return True
    frames = kin.joint_frames(np.zeros((1, robot.nq)))
    origin, rot = frames[p, :, 3, 0], frames[p, :, :3, 0]
    centre = rot @ broad.ball_in_joint[k] + origin
    obstacle = scene.obstacles[o]
    where = (scene.base_from_world @ obstacle.pose(0.0))[:3, 3]
    clearance = sweep_clearance(
        origin, rot @ kin.axes[p - 1], centre, broad.ball_radius[k],
        where, obstacle.shape.bounding_radius,
    )  # fmt: skip
    return clearance <= broad.influence + TABLE_REACH


def tabulate(
    broad: BroadPhase,
    robot: Robot,
    scene: Scene,
    k: int,
    o: int,
    j: int,
    geometry: coal.CollisionGeometry,
) -> DistanceTable:
    """Exact distances of solid ``k`` and obstacle ``o`` over the range of joint ``j``
    (from :func:`table_joint`; its limits, one step beyond each end)."""
    p = int(broad.parents[k])
    kin = robot.kinematics
    lo = robot.limits.lower[j] - TABLE_STEP
    count = int(np.ceil((robot.limits.upper[j] - robot.limits.lower[j]) / TABLE_STEP)) + 3
    q = np.zeros((count, robot.nq))
    q[:, j] = lo + TABLE_STEP * np.arange(count)
    frames = kin.joint_frames(q)
    poses = broad.solid_poses(frames, np.arange(count), k)
    pose_o = scene.base_from_world @ scene.obstacles[o].pose(0.0)
    functor = coal.ComputeDistance(geometry, broad.obstacle_geometry[o])
    request, result = distance_request(), coal.DistanceResult()
    tf_o = coal.Transform3s(pose_o[:3, :3], pose_o[:3, 3])
    tf_s = coal.Transform3s()
    values = np.empty(count)
    rotations = np.ascontiguousarray(poses[:, :3, :3])  # sliced once, not per point
    translations = np.ascontiguousarray(poses[:, :3, 3])
    for i, (rotation, translation) in enumerate(zip(rotations, translations)):
        tf_s.setTransform(rotation, translation)
        result.clear()
        values[i] = functor(tf_s, tf_o, request, result)
    if kin.revolute[p - 1]:
        origin, rot = frames[p, :, 3, 0], frames[p, :, :3, 0]
        axis = rot @ kin.axes[p - 1]
        centre = rot @ broad.ball_in_joint[k] + origin
        rho = np.linalg.norm(np.cross(centre - origin, axis))
        lipschitz = float(rho + broad.ball_radius[k])
    else:
        lipschitz = 1.0
    return DistanceTable(j, float(lo), TABLE_STEP, values, lipschitz)


def kept_tables(checker: Any, robot: Robot, scene: Scene) -> dict[tuple[int, int], DistanceTable]:
    """The tables of ``checker`` (a :class:`~adept_traj.collision.CollisionChecker`) that
    hold for ``robot`` and ``scene``, by (solid, obstacle index in ``scene``), to give a
    new checker (``tables=``): those of the obstacles of ``scene`` that are the checker's
    obstacles (the same objects) with the same base pose, for the checker's robot (the
    same object); ``{}`` otherwise."""
    same_base = np.array_equal(scene.base_from_world, checker.scene.base_from_world)
    if robot is not checker.robot or not same_base:
        return {}
    mine = checker.scene.obstacles
    index = {o: next((i for i, m in enumerate(mine) if m is ob), -1)
             for o, ob in enumerate(scene.obstacles)}  # fmt: skip
    return {
        (k, o): table
        for o, old in index.items()
        for (k, kept), table in checker.broad_phase.tables.items()
        if kept == old
    }
