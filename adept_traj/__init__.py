"""adept_traj — multi-objective, collision-free trajectory planning for industrial robots.

The first robot is the AdeptOne XL SCARA of "Evolutionary Trajectory Planning for an
Industrial Robot" (NSGA-II vs MODE). Units are SI throughout.
"""

from __future__ import annotations

from .errors import (
    AdeptTrajError,
    ConfigurationError,
    InputShapeError,
    InvalidInputError,
    JointLimitError,
    RobotModelError,
    SceneError,
)
from .limits import JointLimits
from .motion import FixedPose, MotionLaw, PendulumMotion
from .parameters import RobotParameters
from .robot import Robot
from .scene import Obstacle, Scene
from .shapes import Box, Capsule, Cylinder, Shape, Sphere
from .trajectory import BSplineTrajectory, KinematicBound, kinematic_lower_bound

__version__ = "0.1.0"

__all__ = [
    "AdeptTrajError",
    "BSplineTrajectory",
    "Box",
    "Capsule",
    "ConfigurationError",
    "Cylinder",
    "FixedPose",
    "InputShapeError",
    "InvalidInputError",
    "JointLimitError",
    "JointLimits",
    "KinematicBound",
    "MotionLaw",
    "Obstacle",
    "PendulumMotion",
    "Robot",
    "RobotModelError",
    "RobotParameters",
    "Scene",
    "SceneError",
    "Shape",
    "Sphere",
    "__version__",
    "kinematic_lower_bound",
]
