"""The optimiser.

Algorithms, sampling, repair, fast-end search, the generation loop, its checkpoints, gradient-based
polishing (``polish``) and :func:`plan`.

Every public name is imported from the module that holds it on first use
(:func:`~adept_traj.lazy_names.lazy_names`): ``from adept_traj.optimise import TIME_OPTIMAL``
imports neither pymoo nor the evolutionary search, which the time-optimal mode does not use.
The package serves every name of a module's ``__all__`` (read from its source by
:func:`~adept_traj.lazy_names.public_names`: the module holds the one list), or, for a
module with names of its own internals (tuning constants, helpers of its subpackage), the
names listed here.
"""

from __future__ import annotations

from adept_traj.lazy_names import lazy_names, public_names

#: The modules every public name (``__all__``) of which the package serves.
_WHOLE_MODULES = (
    "adept_traj.optimise.local.polish_modes",
    "adept_traj.optimise.local.weighted_move",
    "adept_traj.optimise.operators.crossover",
    "adept_traj.optimise.operators.de_variant",
    "adept_traj.optimise.operators.duplicates",
    "adept_traj.optimise.operators.mating",
    "adept_traj.optimise.operators.mutation",
    "adept_traj.optimise.operators.population",
    "adept_traj.optimise.operators.survival",
    "adept_traj.optimise.operators.tournament",
    "adept_traj.optimise.parallel.early_certificates",
    "adept_traj.optimise.parallel.front_certificates",
    "adept_traj.optimise.parallel.polish_worker",
    "adept_traj.optimise.planner",
    "adept_traj.optimise.search.algorithm_names",
    "adept_traj.optimise.search.algorithms",
    "adept_traj.optimise.search.checkpoint",
    "adept_traj.optimise.search.fast_end_search",
    "adept_traj.optimise.search.loop",
    "adept_traj.optimise.search.run_records",
    "adept_traj.optimise.search.sampling",
)
#: Each public name of the other modules the package serves, and its module.
_WHERE: dict[str, str] = {
    "PlanningInterrupted": "adept_traj.errors",
    **dict.fromkeys(
        ["BASIN_THRESHOLD", "basin_labels", "basin_starts"], "adept_traj.optimise.local.basins"
    ),
    **dict.fromkeys(
        ["MAX_EVALUATIONS", "epsilon_step"], "adept_traj.optimise.local.epsilon_constraint"
    ),
    **dict.fromkeys(["PolishOutcome", "minimum_time"], "adept_traj.optimise.local.minimum_time"),
    **dict.fromkeys(
        [
            "GlobalStage",
            "MAX_BASINS",
            "RELAXED_GAP",
            "STRETCHES",
            "fastest_of_basins",
            "global_stage",
            "global_starts",
            "initial_starts",
            "relaxed_optimum",
            "time_optimal",
        ],
        "adept_traj.optimise.local.multi_start",
    ),
    **dict.fromkeys(
        ["Refinement", "refine_minimum_time", "refine_starts", "screen_starts"],
        "adept_traj.optimise.local.refinement",
    ),
    **dict.fromkeys(["edges_clear", "shortcut"], "adept_traj.optimise.local.timed_edges"),
    **dict.fromkeys(["TimedPaths", "timed_paths"], "adept_traj.optimise.local.timed_roadmap"),
    **dict.fromkeys(
        ["fit_timed_path", "timed_roadmap_starts"], "adept_traj.optimise.local.timed_starts"
    ),
    **dict.fromkeys(
        ["GLOBAL_GAP", "GLOBAL_SEED", "ViaPointSampling", "near_lower_bound", "via_point_starts"],
        "adept_traj.optimise.local.via_points",
    ),
    **dict.fromkeys(
        ["KinematicTimeRepair", "kinematic_time"], "adept_traj.optimise.operators.repair"
    ),
}
_WHERE.update({name: m for m in _WHOLE_MODULES for name in public_names(m)})

__all__ = sorted(_WHERE)

__getattr__ = lazy_names(__name__, _WHERE)


def __dir__() -> list[str]:
    return sorted({*globals(), *_WHERE})
