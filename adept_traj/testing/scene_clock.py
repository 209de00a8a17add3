r"""An independent check of a move at a scene time: the oracle of the scene clock's tests.

:func:`clearance_by_hand` computes the smallest signed distance [m] between the robot's
collision solids and the obstacles of a scene **file's mapping** (``Scene.to_dict()``:
``[[obstacle]]`` boxes, spheres and cylinders at a fixed pose, ``[[pendulum]]`` entries) at
given **scene** times, with coal called directly on shapes built here and a pendulum pose
computed here from the scene file's numbers. It shares no code with the planner's scene
clock (:class:`~adept_traj.collision.CollisionChecker`, :class:`~adept_traj.scene.Scene`,
the motion laws): the pendulum of the scene file is placed by the closed form of
``docs/scene-files.md``, written out again,

.. math::
    \varphi(\tau) = 2 \arcsin\!\big(a \cos \omega \tau\big), \quad
    a = \frac{v_0}{2 \sqrt{g l}}, \quad
    p_{bob}(\tau) = p_{pivot} + l\,(\sin\varphi\, e_{swing} - \cos\varphi\, e_z),

the rod a cylinder from the pivot to the bob centre, the bob a sphere. The robot's solid
placements come from Pinocchio's ``updateGeometryPlacements`` and the base pose from the
file's ``[robot]`` table. It is slow (one coal call per sample and pair) and meant for a
few hundred samples.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from adept_traj.robot import Robot

__all__ = ["clearance_by_hand", "pendulum_bob_by_hand"]


def _rpy(rpy: Any) -> np.ndarray:
    """(3, 3) rotation of roll, pitch, yaw [rad] (URDF convention, Rz · Ry · Rx)."""
    r, p, y = (float(v) for v in rpy)
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    cy, sy = math.cos(y), math.sin(y)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def pendulum_bob_by_hand(entry: Mapping[str, Any], tau: float) -> np.ndarray:
    """(3,) world bob centre [m] of a scene file's ``[[pendulum]]`` entry at scene time
    ``tau`` [s] (the module's closed form)."""
    pivot = np.asarray(entry["pivot"], dtype=float)
    length, v0 = float(entry["length"]), float(entry["v0"])
    omega, g = float(entry["omega"]), float(entry.get("g", 9.81))
    swing = np.asarray(entry.get("swing_axis", [1.0, 0.0, 0.0]), dtype=float)
    swing = swing / np.linalg.norm(swing)
    a = v0 / (2.0 * math.sqrt(g * length))
    phi = 2.0 * math.asin(max(-1.0, min(1.0, a * math.cos(omega * tau))))
    return pivot + length * (math.sin(phi) * swing - math.cos(phi) * np.array([0.0, 0.0, 1.0]))


def _rod_pose(pivot: np.ndarray, bob: np.ndarray) -> coal.Transform3s:
    """The rod's cylinder frame: centre at the middle of pivot–bob, z along the rod."""
    axis = (pivot - bob) / np.linalg.norm(pivot - bob)
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, axis)
    x /= np.linalg.norm(x)
    rotation = np.column_stack([x, np.cross(axis, x), axis])
    return coal.Transform3s(rotation, 0.5 * (pivot + bob))


def _obstacles(scene: Mapping[str, Any], tau: float) -> list[tuple[str, Any, coal.Transform3s]]:
    """(name, coal shape, world pose) of every obstacle of the mapping at scene time tau."""
    out = []
    for ob in scene.get("obstacle", []):
        rotation = _rpy(ob.get("rpy", [0.0, 0.0, 0.0]))
        pose = coal.Transform3s(rotation, np.asarray(ob["xyz"], dtype=float))
        if ob["shape"] == "box":
            shape: Any = coal.Box(*(float(v) for v in ob["size"]))
        elif ob["shape"] == "sphere":
            shape = coal.Sphere(float(ob["radius"]))
        elif ob["shape"] == "cylinder":
            shape = coal.Cylinder(float(ob["radius"]), float(ob["length"]))
        else:
            raise ValueError(f"obstacle shape {ob['shape']!r} is not drawn by the reference")
        out.append((ob["name"], shape, pose))
    for pend in scene.get("pendulum", []):
        pivot = np.asarray(pend["pivot"], dtype=float)
        bob = pendulum_bob_by_hand(pend, tau)
        rod = coal.Cylinder(float(pend.get("rod_radius", 0.01)), float(pend["length"]))
        out.append((pend["name"] + ".rod", rod, _rod_pose(pivot, bob)))
        sphere = coal.Sphere(float(pend["bob_radius"]))
        out.append((pend["name"] + ".bob", sphere, coal.Transform3s(np.eye(3), bob)))
    return out


def clearance_by_hand(
    robot: Robot, scene: Mapping[str, Any], q: Any, scene_times: Any
) -> tuple[np.ndarray, list[str]]:
    """Smallest signed distance [m] of the robot's solids to the obstacles of ``scene`` at
    each sample.

    Parameters
    ----------
    robot: the robot (its Pinocchio model and collision model).
    scene: a scene file's mapping (``Scene.to_dict()``).
    q: (n, nq) joint positions [rad | m].
    scene_times: (n,) scene times [s] of the samples (a move started at t0: t0 + t).

    Returns
    -------
    ``(distance, closest)``: (n,) smallest distance [m] per sample (negative: penetration
    depth), and per sample the name of the closest obstacle.
    """
    base = scene.get("robot", {})
    base_rotation = _rpy(base.get("rpy", [0.0, 0.0, 0.0]))
    base_xyz = np.asarray(base.get("xyz", [0.0, 0.0, 0.0]), dtype=float)
    model, gm = robot.model, robot.collision_model
    data, gdata = model.createData(), gm.createData()
    request = coal.DistanceRequest()
    qa = np.asarray(q, dtype=float)
    times = np.asarray(scene_times, dtype=float)
    distance = np.full(len(qa), np.inf)
    closest = [""] * len(qa)
    for n, (qn, tau) in enumerate(zip(qa, times.tolist())):
        pin.forwardKinematics(model, data, qn)
        pin.updateGeometryPlacements(model, data, gm, gdata, qn)
        obstacles = _obstacles(scene, tau)
        for k, g in enumerate(gm.geometryObjects):
            placement = gdata.oMg[k]
            rotation = base_rotation @ placement.rotation
            xyz = base_rotation @ placement.translation + base_xyz
            tf_solid = coal.Transform3s(rotation, xyz)
            for name, shape, tf_obstacle in obstacles:
                result = coal.DistanceResult()
                d = coal.distance(g.geometry, tf_solid, shape, tf_obstacle, request, result)
                if d < distance[n]:
                    distance[n], closest[n] = d, name
    return distance, closest
