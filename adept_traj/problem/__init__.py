"""The trajectory problem.

B-spline trajectory (``bspline``, ``spline_segments``), kinematic time bound
(``time_bound``), objectives (``objectives``), :class:`TrajectoryProblem`."""

from __future__ import annotations

from adept_traj.problem.bspline import BSplineTrajectory
from adept_traj.problem.objectives import (
    paper_penalty,
)
from adept_traj.problem.spline_segments import (
    TrajectoryBounds,
    TrajectoryIntegrals,
    TrajectorySamples,
)
from adept_traj.problem.time_bound import KinematicBound, kinematic_lower_bound
from adept_traj.problem.trajectory_problem import (
    OBJECTIVE_NAMES,
    Evaluation,
    ProblemSettings,
    TrajectoryProblem,
)

__all__ = [
    "OBJECTIVE_NAMES",
    "BSplineTrajectory",
    "Evaluation",
    "KinematicBound",
    "ProblemSettings",
    "TrajectoryBounds",
    "TrajectoryIntegrals",
    "TrajectoryProblem",
    "TrajectorySamples",
    "kinematic_lower_bound",
    "paper_penalty",
]
