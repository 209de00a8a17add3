"""adept_traj — multi-objective, collision-free trajectory planning for industrial robots.

The first robot is the AdeptOne XL SCARA of "Evolutionary Trajectory Planning for an
Industrial Robot" (NSGA-II vs MODE). Units are SI throughout.
"""

from __future__ import annotations

from .algorithms import ALGORITHMS, make_algorithm
from .collision import CollisionChecker, paper_penalty
from .decision import PAPER_WEIGHTS, average_fitness, best_tradeoff, combined_objective
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
from .planner import plan
from .problem import Evaluation, ProblemSettings, TrajectoryProblem
from .results import PlanningResult, ResultFormatError
from .robot import ForwardKinematics, Robot
from .run import PlanningInterrupted
from .scene import Obstacle, Scene
from .shapes import Box, Capsule, Cylinder, Shape, Sphere
from .trajectory import BSplineTrajectory, KinematicBound, kinematic_lower_bound
from .verification import Certificate, certify

__version__ = "0.1.0"

__all__ = [
    "ALGORITHMS",
    "PAPER_WEIGHTS",
    "AdeptTrajError",
    "BSplineTrajectory",
    "Box",
    "Capsule",
    "Certificate",
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
    "PlanningInterrupted",
    "PlanningResult",
    "ProblemSettings",
    "ResultFormatError",
    "Robot",
    "RobotModelError",
    "RobotParameters",
    "Scene",
    "SceneError",
    "Shape",
    "Sphere",
    "TrajectoryProblem",
    "__version__",
    "average_fitness",
    "best_tradeoff",
    "certify",
    "combined_objective",
    "kinematic_lower_bound",
    "make_algorithm",
    "paper_penalty",
    "plan",
]
