"""The optimiser.

Algorithms, sampling, repair, fast-end search, the generation loop, its checkpoints, gradient-based
polishing (``polish``) and :func:`plan`."""

from __future__ import annotations

from adept_traj.optimise.local.basins import THRESHOLD as BASIN_THRESHOLD
from adept_traj.optimise.local.basins import basin_labels, basin_starts
from adept_traj.optimise.local.epsilon_constraint import MAX_EVALUATIONS, epsilon_step
from adept_traj.optimise.local.minimum_time import PolishOutcome, minimum_time
from adept_traj.optimise.local.multi_start import (
    MAX_BASINS,
    STRETCHES,
    GlobalStage,
    fastest_of_basins,
    global_stage,
    global_starts,
    initial_starts,
    relaxed_optimum,
    time_optimal,
)
from adept_traj.optimise.local.polish_modes import (
    GRADIENT_COST,
    POLISH_MODES,
    POLISH_SHARE,
    SPREAD_MEMBERS,
    TIME_OPTIMAL,
    polish_fastest,
    polish_members,
    polish_mode,
    polish_run,
    polish_run_with_certificates,
    time_optimal_run,
)
from adept_traj.optimise.local.refinement import (
    Refinement,
    refine_minimum_time,
    refine_starts,
    screen_starts,
)
from adept_traj.optimise.local.timed_edges import edges_clear, shortcut
from adept_traj.optimise.local.timed_roadmap import TimedPaths, timed_paths
from adept_traj.optimise.local.timed_starts import fit_timed_path, timed_roadmap_starts
from adept_traj.optimise.local.via_points import (
    GLOBAL_GAP,
    GLOBAL_SEED,
    ViaPointSampling,
    near_lower_bound,
    via_point_starts,
)
from adept_traj.optimise.local.weighted_move import (
    MAX_EVALUATIONS_PER_START,
    STEP_EVALUATIONS,
    STOP_DECREASE,
    WEIGHTED_BOX,
    weighted_descent,
    weighted_run,
)
from adept_traj.optimise.operators.crossover import (
    sbx_children,
)
from adept_traj.optimise.operators.de_variant import (
    ArrayVariant,
)
from adept_traj.optimise.operators.duplicates import (
    BLOCK_PAIRS,
    BlockedDuplicateElimination,
)
from adept_traj.optimise.operators.mating import (
    ArrayMating,
)
from adept_traj.optimise.operators.mutation import (
    mutate,
)
from adept_traj.optimise.operators.population import (
    ArrayEvaluator,
    cache_violations,
    optimum,
    population_values,
    ranked_optimum,
)
from adept_traj.optimise.operators.repair import (
    KinematicTimeRepair,
    kinematic_time,
)
from adept_traj.optimise.operators.survival import (
    RankAndCrowdingSurvival,
    crowding_distance,
)
from adept_traj.optimise.operators.tournament import (
    TournamentArrays,
    binary_tournament,
    select_parents,
)
from adept_traj.optimise.parallel.early_certificates import (
    EARLY_SHARE,
    EarlyCertificates,
    feasible_front,
    start_early_certificates,
)
from adept_traj.optimise.parallel.front_certificates import (
    certify_front_members,
)
from adept_traj.optimise.parallel.polish_worker import (
    Polisher,
    check_polisher,
    polish_with_certificates,
    start_polisher,
)
from adept_traj.optimise.planner import (
    plan,
    warn_missing_limits,
)
from adept_traj.optimise.search.algorithms import (
    ALGORITHMS,
    AlgorithmSettings,
    make_algorithm,
)
from adept_traj.optimise.search.checkpoint import (
    CHECKPOINT_VERSION,
    CapturedCheckpoint,
    capture_checkpoint,
    checkpoint_arrays,
    has_checkpoint,
    load_checkpoint,
    restore_algorithm,
    save_checkpoint,
    write_checkpoint,
)
from adept_traj.optimise.search.fast_end_search import (
    FastEndSearch,
)
from adept_traj.optimise.search.loop import (
    CHECKPOINT_INTERVAL,
    GenerationInfo,
    PlanningInterrupted,
    RunState,
    optimise,
)
from adept_traj.optimise.search.sampling import (
    RampSampling,
    SeededInitialization,
    check_population_memory,
    population_bytes,
)

__all__ = [
    "ALGORITHMS",
    "BASIN_THRESHOLD",
    "BLOCK_PAIRS",
    "CHECKPOINT_INTERVAL",
    "CHECKPOINT_VERSION",
    "EARLY_SHARE",
    "GLOBAL_GAP",
    "GLOBAL_SEED",
    "GRADIENT_COST",
    "MAX_BASINS",
    "MAX_EVALUATIONS",
    "MAX_EVALUATIONS_PER_START",
    "POLISH_MODES",
    "POLISH_SHARE",
    "SPREAD_MEMBERS",
    "STEP_EVALUATIONS",
    "STOP_DECREASE",
    "STRETCHES",
    "TIME_OPTIMAL",
    "WEIGHTED_BOX",
    "AlgorithmSettings",
    "ArrayEvaluator",
    "ArrayMating",
    "ArrayVariant",
    "BlockedDuplicateElimination",
    "CapturedCheckpoint",
    "EarlyCertificates",
    "FastEndSearch",
    "GenerationInfo",
    "GlobalStage",
    "KinematicTimeRepair",
    "PlanningInterrupted",
    "PolishOutcome",
    "Polisher",
    "RampSampling",
    "RankAndCrowdingSurvival",
    "Refinement",
    "RunState",
    "SeededInitialization",
    "TimedPaths",
    "TournamentArrays",
    "ViaPointSampling",
    "basin_labels",
    "basin_starts",
    "binary_tournament",
    "cache_violations",
    "capture_checkpoint",
    "certify_front_members",
    "check_polisher",
    "check_population_memory",
    "checkpoint_arrays",
    "crowding_distance",
    "edges_clear",
    "epsilon_step",
    "fastest_of_basins",
    "feasible_front",
    "fit_timed_path",
    "global_stage",
    "global_starts",
    "has_checkpoint",
    "initial_starts",
    "kinematic_time",
    "load_checkpoint",
    "make_algorithm",
    "minimum_time",
    "mutate",
    "near_lower_bound",
    "optimise",
    "optimum",
    "plan",
    "polish_fastest",
    "polish_members",
    "polish_mode",
    "polish_run",
    "polish_run_with_certificates",
    "polish_with_certificates",
    "population_bytes",
    "population_values",
    "ranked_optimum",
    "refine_minimum_time",
    "refine_starts",
    "relaxed_optimum",
    "restore_algorithm",
    "save_checkpoint",
    "sbx_children",
    "screen_starts",
    "select_parents",
    "shortcut",
    "start_early_certificates",
    "start_polisher",
    "time_optimal",
    "time_optimal_run",
    "timed_paths",
    "timed_roadmap_starts",
    "via_point_starts",
    "warn_missing_limits",
    "weighted_descent",
    "weighted_run",
    "write_checkpoint",
]
