"""The optimiser.

algorithms, sampling, repair, fast-end search, the loop, checkpoints, :func:`plan`."""

from __future__ import annotations

from adept_traj.optimise.algorithms import (
    ALGORITHMS,
    AlgorithmSettings,
    make_algorithm,
)
from adept_traj.optimise.fast_end import (
    FastEndSearch,
)
from adept_traj.optimise.loop import (
    GenerationInfo,
    PlanningInterrupted,
    RunState,
    optimise,
)
from adept_traj.optimise.planner import (
    plan,
)
from adept_traj.optimise.repair import (
    KinematicTimeRepair,
    kinematic_time,
)
from adept_traj.optimise.sampling import (
    RampSampling,
)

__all__ = [
    "ALGORITHMS",
    "AlgorithmSettings",
    "FastEndSearch",
    "GenerationInfo",
    "KinematicTimeRepair",
    "PlanningInterrupted",
    "RampSampling",
    "RunState",
    "kinematic_time",
    "make_algorithm",
    "optimise",
    "plan",
]
