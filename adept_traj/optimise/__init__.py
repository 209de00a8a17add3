"""The optimiser.

Algorithms, sampling, repair, fast-end search, the generation loop, its checkpoints, gradient-based
polishing (``polish``) and :func:`plan`.

Every public name is imported from the module that holds it on first use
(:func:`~adept_traj.lazy_names.lazy_names`): ``from adept_traj.optimise import TIME_OPTIMAL``
imports neither pymoo nor the evolutionary search, which the time-optimal mode does not use.
"""

from __future__ import annotations

from adept_traj.lazy_names import lazy_names

#: Each public name and the module that holds it.
_WHERE: dict[str, str] = {
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
        [
            "GRADIENT_COST",
            "POLISH_MODES",
            "POLISH_SHARE",
            "SPREAD_MEMBERS",
            "TIME_OPTIMAL",
            "polish_fastest",
            "polish_members",
            "polish_mode",
            "polish_run",
            "polish_run_with_certificates",
            "time_optimal_run",
        ],
        "adept_traj.optimise.local.polish_modes",
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
        [
            "MAX_EVALUATIONS_PER_START",
            "STEP_EVALUATIONS",
            "STOP_DECREASE",
            "WEIGHTED_BOX",
            "weighted_descent",
            "weighted_run",
        ],
        "adept_traj.optimise.local.weighted_move",
    ),
    **dict.fromkeys(["sbx_children"], "adept_traj.optimise.operators.crossover"),
    **dict.fromkeys(["ArrayVariant"], "adept_traj.optimise.operators.de_variant"),
    **dict.fromkeys(
        ["BLOCK_PAIRS", "BlockedDuplicateElimination"], "adept_traj.optimise.operators.duplicates"
    ),
    **dict.fromkeys(["ArrayMating"], "adept_traj.optimise.operators.mating"),
    **dict.fromkeys(["mutate"], "adept_traj.optimise.operators.mutation"),
    **dict.fromkeys(
        ["ArrayEvaluator", "cache_violations", "optimum", "population_values", "ranked_optimum"],
        "adept_traj.optimise.operators.population",
    ),
    **dict.fromkeys(
        ["KinematicTimeRepair", "kinematic_time"], "adept_traj.optimise.operators.repair"
    ),
    **dict.fromkeys(
        ["RankAndCrowdingSurvival", "crowding_distance"], "adept_traj.optimise.operators.survival"
    ),
    **dict.fromkeys(
        ["TournamentArrays", "binary_tournament", "select_parents"],
        "adept_traj.optimise.operators.tournament",
    ),
    **dict.fromkeys(
        ["EARLY_SHARE", "EarlyCertificates", "feasible_front", "start_early_certificates"],
        "adept_traj.optimise.parallel.early_certificates",
    ),
    **dict.fromkeys(["certify_front_members"], "adept_traj.optimise.parallel.front_certificates"),
    **dict.fromkeys(
        ["Polisher", "check_polisher", "polish_with_certificates", "start_polisher"],
        "adept_traj.optimise.parallel.polish_worker",
    ),
    **dict.fromkeys(["plan", "warn_missing_limits"], "adept_traj.optimise.planner"),
    **dict.fromkeys(
        ["ALGORITHMS", "OTHER_ALGORITHMS", "PAPER_SETTINGS"],
        "adept_traj.optimise.search.algorithm_names",
    ),
    **dict.fromkeys(
        ["AlgorithmSettings", "make_algorithm"], "adept_traj.optimise.search.algorithms"
    ),
    **dict.fromkeys(
        [
            "CHECKPOINT_VERSION",
            "CapturedCheckpoint",
            "capture_checkpoint",
            "checkpoint_arrays",
            "has_checkpoint",
            "load_checkpoint",
            "restore_algorithm",
            "save_checkpoint",
            "write_checkpoint",
        ],
        "adept_traj.optimise.search.checkpoint",
    ),
    **dict.fromkeys(["FastEndSearch"], "adept_traj.optimise.search.fast_end_search"),
    **dict.fromkeys(["CHECKPOINT_INTERVAL", "optimise"], "adept_traj.optimise.search.loop"),
    **dict.fromkeys(["GenerationInfo", "RunState"], "adept_traj.optimise.search.run_records"),
    "PlanningInterrupted": "adept_traj.errors",
    **dict.fromkeys(
        ["RampSampling", "SeededInitialization", "check_population_memory", "population_bytes"],
        "adept_traj.optimise.search.sampling",
    ),
}

__all__ = sorted(_WHERE)

__getattr__ = lazy_names(__name__, _WHERE)


def __dir__() -> list[str]:
    return sorted({*globals(), *_WHERE})
