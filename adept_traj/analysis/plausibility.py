r"""Warnings (not errors) where a scene's numbers look like millimetres or degrees:
:func:`unit_warnings`.

Scene files are in SI units, lengths in metres and angles in radians
(``docs/scene-files.md``). A scene written in millimetres and degrees loads without any
error — ``size = [200, 200, 200]`` is a 200 m box, ``rpy = [0, 0, 180]`` a turn of 180 rad
— and plans "FEASIBLE (min distance 999.67 m)". The checks, against the robot's reach
:math:`R` (the largest distance from the base of a point of its collision solids over
configurations sampled within the limits, :func:`robot_reach`):

- every obstacle is farther than ``10 R`` from the robot at the start (millimetres?);
- an obstacle larger than ``10 R`` across (its enclosing ball);
- an angle of the file (an ``rpy`` of the robot's base or of an obstacle, a pendulum's
  ``omega`` is not an angle) above :math:`2\pi` in magnitude (degrees?).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from adept_traj.collision.primitives import enclosing_ball
from adept_traj.problem.trajectory_problem import TrajectoryProblem
from adept_traj.robot import Robot

__all__ = ["REACH_FACTOR", "robot_reach", "unit_warnings"]

#: An obstacle farther than (or larger than) this many reaches of the robot is suspect.
REACH_FACTOR = 10.0
#: Configurations sampled (fixed seed) for :func:`robot_reach`.
_REACH_SAMPLES = 256


def robot_reach(robot: Robot) -> float:
    """The robot's reach [m]: the largest distance from the base frame's origin of the
    enclosing balls of its collision solids over :data:`_REACH_SAMPLES` configurations
    sampled uniformly within the limits (seed 0; infinite limits clipped to ±2π), and the
    start of the model (its neutral configuration clipped into the limits)."""
    lo = np.clip(robot.limits.lower, -2 * math.pi, 2 * math.pi)
    hi = np.clip(robot.limits.upper, -2 * math.pi, 2 * math.pi)
    q = np.random.default_rng(0).uniform(lo, hi, (_REACH_SAMPLES, robot.nq))
    q = np.vstack([q, np.clip(np.zeros(robot.nq), lo, hi)])
    objects = robot.collision_model.geometryObjects
    if not len(objects):
        return 0.0
    balls = [enclosing_ball(g.geometry) for g in objects]
    centres = np.array([c for c, _ in balls])  # (n_solids, 3) in the solids' frames
    radii = np.array([r for _, r in balls])
    poses = robot.geometry_poses(q)  # (n, n_solids, 4, 4)
    world = np.einsum("nkij,kj->nki", poses[..., :3, :3], centres) + poses[..., :3, 3]
    return float((np.linalg.norm(world, axis=-1) + radii).max())


def unit_warnings(
    problem: TrajectoryProblem, raw: Mapping[str, Any] | None = None
) -> tuple[str, ...]:
    """The plausibility warnings of the module doc for ``problem``'s robot and scene;
    ``raw`` is the scene file's parsed TOML (its angles as written; ``None``: a shipped
    scene, not checked for angles). ``()`` when nothing looks wrong."""
    out = []
    reach = robot_reach(problem.robot)
    checker = problem.checker
    far = REACH_FACTOR * reach
    if checker.n_obstacles and reach > 0:
        d = checker.distances(problem.start[None, None], np.zeros((1, 1))).distance[0, 0]
        nearest = float(d.min())
        if nearest > far:
            out.append(
                f"every obstacle is farther than {REACH_FACTOR:g} × the robot's reach "
                f"({reach:.3g} m) from it (the nearest {nearest:.4g} m): are the scene's "
                "lengths in millimetres? Scene files are in metres"
            )
        for ob in problem.scene.obstacles:
            size = 2.0 * float(ob.shape.bounding_radius)
            if size > far:
                out.append(
                    f"obstacle {ob.name!r} is {size:.4g} m across, more than {REACH_FACTOR:g} "
                    f"× the robot's reach ({reach:.3g} m): are its lengths in millimetres?"
                )
    for where, values in _angles(raw or {}):
        big = [v for v in values if isinstance(v, (int, float)) and abs(v) > 2 * math.pi]
        if big:
            out.append(
                f"{where} = {list(values)} has an angle above 2π in magnitude: are its "
                "angles in degrees? Scene files are in radians"
            )
    return tuple(out)


def _angles(raw: Mapping[str, Any]) -> list[tuple[str, list[Any]]]:
    """``(field, values)`` of the ``rpy`` fields of a parsed scene file."""
    found = []
    robot = raw.get("robot")
    if isinstance(robot, Mapping) and isinstance(robot.get("rpy"), list):
        found.append(("robot.rpy", robot["rpy"]))
    for table in ("obstacle", "pendulum"):
        entries = raw.get(table)
        for k, entry in enumerate(entries if isinstance(entries, list) else []):
            if isinstance(entry, Mapping) and isinstance(entry.get("rpy"), list):
                found.append((f"{table}[{k}].rpy", entry["rpy"]))
    return found
