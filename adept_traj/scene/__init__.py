"""The scene: obstacle shapes, obstacle motion laws, :class:`Scene` and scene files."""

from __future__ import annotations

from adept_traj.scene.motion_laws import (
    FixedPose,
    MotionLaw,
    PendulumMotion,
)
from adept_traj.scene.scene import (
    Obstacle,
    Scene,
    SceneFileNotFoundError,
    pendulum_obstacles,
)
from adept_traj.scene.shapes import (
    Box,
    Capsule,
    Cylinder,
    Shape,
    Sphere,
    coal_transform,
)

__all__ = [
    "Box",
    "Capsule",
    "Cylinder",
    "FixedPose",
    "MotionLaw",
    "Obstacle",
    "PendulumMotion",
    "Scene",
    "SceneFileNotFoundError",
    "Shape",
    "Sphere",
    "coal_transform",
    "pendulum_obstacles",
]
