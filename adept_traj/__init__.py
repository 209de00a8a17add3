"""adept_traj — multi-objective, collision-free trajectory planning for industrial robots.

The first robot is the AdeptOne XL SCARA of "Evolutionary Trajectory Planning for an
Industrial Robot" (NSGA-II vs MODE). Units are SI throughout.
"""

from __future__ import annotations

from importlib import metadata as _metadata

from adept_traj.analysis.certificate import Certificate, certify
from adept_traj.analysis.decision import (
    PAPER_WEIGHTS,
    average_fitness,
    best_tradeoff,
    combined_objective,
)
from adept_traj.collision.checker import CollisionChecker
from adept_traj.errors import (
    AdeptTrajError,
    ConfigurationError,
    InputShapeError,
    InvalidInputError,
    JointLimitError,
    PlanningInterrupted,
    ResultFormatError,
    RobotModelError,
    SceneError,
)
from adept_traj.optimise.algorithms import ALGORITHMS, make_algorithm
from adept_traj.optimise.planner import plan
from adept_traj.problem import (
    BSplineTrajectory,
    Evaluation,
    KinematicBound,
    ProblemSettings,
    TrajectoryProblem,
    kinematic_lower_bound,
    paper_penalty,
)
from adept_traj.results.audit import audit
from adept_traj.results.record import PlanningResult
from adept_traj.robot.limits import JointLimits
from adept_traj.robot.parameter_file import RobotParameters
from adept_traj.robot.robot import ForwardKinematics, Robot
from adept_traj.scene.motion_laws import FixedPose, MotionLaw, PendulumMotion
from adept_traj.scene.scene import Obstacle, Scene
from adept_traj.scene.shapes import Box, Capsule, Cylinder, Shape, Sphere

try:  # the installed distribution's version (pyproject.toml), one source of truth
    __version__ = _metadata.version("adept-traj")
except _metadata.PackageNotFoundError:  # a source checkout that was never installed
    __version__ = "0+unknown"

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
    "audit",
    "average_fitness",
    "best_tradeoff",
    "certify",
    "combined_objective",
    "kinematic_lower_bound",
    "make_algorithm",
    "paper_penalty",
    "plan",
]
