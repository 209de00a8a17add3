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
from .parameters import RobotParameters
from .robot import Robot

__version__ = "0.1.0"

__all__ = [
    "AdeptTrajError",
    "ConfigurationError",
    "InputShapeError",
    "InvalidInputError",
    "JointLimitError",
    "JointLimits",
    "Robot",
    "RobotModelError",
    "RobotParameters",
    "SceneError",
    "__version__",
]
