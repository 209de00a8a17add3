"""adept_traj — multi-objective, collision-free trajectory planning for industrial robots.

The first robot is the AdeptOne XL SCARA of "Evolutionary Trajectory Planning for an
Industrial Robot" (NSGA-II vs MODE). Units are SI throughout.
"""

from __future__ import annotations

from .collision import CollisionChecker, paper_penalty
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
from .problem import Evaluation, ProblemSettings, TrajectoryProblem
from .robot import ForwardKinematics, Robot
from .scene import Obstacle, Scene
from .shapes import Box, Capsule, Cylinder, Shape, Sphere
from .trajectory import BSplineTrajectory, KinematicBound, kinematic_lower_bound

__version__ = "0.1.0"

__all__ = [
    "AdeptTrajError",
    "BSplineTrajectory",
    "Box",
    "Capsule",
    "CollisionChecker",
    "ConfigurationError",
    "Cylinder",
    "Evaluation",
    "FixedPose",
    "ForwardKinematics",
    "InputShapeError",
    "InvalidInputError",
    "JointLimitError",
    "JointLimits",
    "KinematicBound",
    "MotionLaw",
    "Obstacle",
    "PendulumMotion",
    "ProblemSettings",
    "Robot",
    "RobotModelError",
    "RobotParameters",
    "Scene",
    "SceneError",
    "Shape",
    "Sphere",
    "TrajectoryProblem",
    "__version__",
    "kinematic_lower_bound",
    "paper_penalty",
]
