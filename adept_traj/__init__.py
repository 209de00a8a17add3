"""adept_traj — multi-objective, collision-free trajectory planning for industrial robots.

The first robot is the AdeptOne XL SCARA of "Evolutionary Trajectory Planning for an
Industrial Robot" (NSGA-II vs MODE). Units are SI throughout.
"""

from __future__ import annotations

from typing import Any as _Any

from adept_traj.lazy_names import lazy_names as _lazy_names

#: Where each public name lives: imported on first use (PEP 562), so that ``import
#: adept_traj`` (and ``adept-traj --help``) loads none of pinocchio, coal, pymoo or scipy
#: before a name that needs them is used.
_PUBLIC = {
    "Certificate": "adept_traj.certification.certificate",
    "certify": "adept_traj.certification.certificate",
    "PAPER_WEIGHTS": "adept_traj.analysis.decision",
    "average_fitness": "adept_traj.analysis.decision",
    "best_tradeoff": "adept_traj.analysis.decision",
    "combined_objective": "adept_traj.analysis.decision",
    "CollisionChecker": "adept_traj.collision.checker",
    "AdeptTrajError": "adept_traj.errors",
    "ConfigurationError": "adept_traj.errors",
    "InputShapeError": "adept_traj.errors",
    "InvalidInputError": "adept_traj.errors",
    "JointLimitError": "adept_traj.errors",
    "PlanningInterrupted": "adept_traj.errors",
    "ResultFormatError": "adept_traj.errors",
    "RobotModelError": "adept_traj.errors",
    "SceneError": "adept_traj.errors",
    "ALGORITHMS": "adept_traj.optimise.search.algorithms",
    "make_algorithm": "adept_traj.optimise.search.algorithms",
    "plan": "adept_traj.optimise.planner",
    "BSplineTrajectory": "adept_traj.problem",
    "Evaluation": "adept_traj.problem",
    "KinematicBound": "adept_traj.problem",
    "ProblemSettings": "adept_traj.problem",
    "TrajectoryProblem": "adept_traj.problem",
    "kinematic_lower_bound": "adept_traj.problem",
    "paper_penalty": "adept_traj.problem",
    "audit": "adept_traj.certification.audit",
    "PlanningResult": "adept_traj.results.record",
    "JointLimits": "adept_traj.robot.limits",
    "RobotParameters": "adept_traj.robot.parameter_file",
    "ForwardKinematics": "adept_traj.robot.forward_kinematics",
    "Robot": "adept_traj.robot.robot",
    "FixedPose": "adept_traj.scene.motion_laws",
    "MotionLaw": "adept_traj.scene.motion_laws",
    "PendulumMotion": "adept_traj.scene.motion_laws",
    "LinearMotion": "adept_traj.scene.machine_motions",
    "RotationMotion": "adept_traj.scene.machine_motions",
    "RecordedMotion": "adept_traj.scene.recorded_motion",
    "Mesh": "adept_traj.scene.meshes",
    "Obstacle": "adept_traj.scene.scene",
    "Scene": "adept_traj.scene.scene",
    "Box": "adept_traj.scene.shapes",
    "Capsule": "adept_traj.scene.shapes",
    "Cylinder": "adept_traj.scene.shapes",
    "Shape": "adept_traj.scene.shapes",
    "Sphere": "adept_traj.scene.shapes",
}

_public = _lazy_names(__name__, _PUBLIC)

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
    "LinearMotion",
    "Mesh",
    "MotionLaw",
    "Obstacle",
    "PendulumMotion",
    "PlanningInterrupted",
    "PlanningResult",
    "ProblemSettings",
    "RecordedMotion",
    "ResultFormatError",
    "Robot",
    "RobotModelError",
    "RobotParameters",
    "RotationMotion",
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


def _version() -> str:
    """The installed distribution's version (pyproject.toml), one source of truth."""
    from importlib import metadata

    try:
        return metadata.version("adept-traj")
    except metadata.PackageNotFoundError:  # a source checkout that was never installed
        return "0+unknown"


def __getattr__(name: str) -> _Any:
    """The public name ``name`` (or ``__version__``), imported from its module on first use
    (then cached)."""
    if name != "__version__":
        return _public(name)
    globals()[name] = value = _version()
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_PUBLIC) | {"__version__"})
