"""The trajectory problem.

B-spline trajectory, kinematic time bound, objectives, :class:`TrajectoryProblem`."""

from __future__ import annotations

from adept_traj.problem.bspline import (
    BSplineTrajectory,
    KinematicBound,
    TrajectoryBounds,
    TrajectoryIntegrals,
    TrajectorySamples,
    kinematic_lower_bound,
)
from adept_traj.problem.objectives import (
    paper_penalty,
)
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
