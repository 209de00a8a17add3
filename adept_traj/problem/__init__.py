"""The trajectory problem.

The B-spline trajectory (``bspline``; its per-segment arithmetic in ``spline_segments``),
the kinematic lower bound of the travel time (``time_bound``), the objective table, pymoo's
sign convention and the paper's penalty (``objectives``), smooth per-sample constraints
with their Jacobians for local solvers (``gradients``), the objectives' gradients
(``objective_gradients``), :class:`TrajectoryProblem`
(``trajectory_problem``) with its :class:`Evaluation` (``evaluation``), its parallel
evaluator (``evaluator``), the heap it keeps between blocks (``_heap``) and its plain-loop
reference (``reference``).
"""

from __future__ import annotations

from adept_traj.problem._heap import heap_environment, keep_heap
from adept_traj.problem.bspline import BSplineTrajectory
from adept_traj.problem.evaluation import Evaluation
from adept_traj.problem.evaluator import ParallelEvaluator, available_cores
from adept_traj.problem.gradients import CONSTRAINT_KINDS, LocalConstraints, local_constraints
from adept_traj.problem.objective_gradients import (
    ObjectiveGradients,
    check_differentiable,
    objective_gradients,
)
from adept_traj.problem.objectives import (
    MAXIMISED,
    OBJECTIVE_NAMES,
    OBJECTIVES,
    Objective,
    from_pymoo,
    paper_penalty,
    paper_semi_axes,
    to_pymoo,
)
from adept_traj.problem.problem_settings import ProblemSettings
from adept_traj.problem.spline_segments import (
    TrajectoryBounds,
    TrajectoryIntegrals,
    TrajectorySamples,
    derivative_abs_max,
)
from adept_traj.problem.time_bound import KinematicBound, kinematic_lower_bound
from adept_traj.problem.trajectory_problem import TrajectoryProblem

__all__ = [
    "CONSTRAINT_KINDS",
    "MAXIMISED",
    "OBJECTIVES",
    "OBJECTIVE_NAMES",
    "BSplineTrajectory",
    "Evaluation",
    "KinematicBound",
    "LocalConstraints",
    "Objective",
    "ObjectiveGradients",
    "ParallelEvaluator",
    "ProblemSettings",
    "TrajectoryBounds",
    "TrajectoryIntegrals",
    "TrajectoryProblem",
    "TrajectorySamples",
    "available_cores",
    "check_differentiable",
    "derivative_abs_max",
    "from_pymoo",
    "heap_environment",
    "keep_heap",
    "kinematic_lower_bound",
    "local_constraints",
    "objective_gradients",
    "paper_penalty",
    "paper_semi_axes",
    "to_pymoo",
]
