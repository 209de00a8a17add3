"""Analysis of moves and fronts: certificate, decision making, indicators, the paper's measures."""

from __future__ import annotations

from adept_traj.analysis.decision import (
    PAPER_WEIGHTS,
    BestTradeoff,
    average_fitness,
    best_tradeoff,
    combined_objective,
    normalise,
    objective_weights,
)
from adept_traj.analysis.indicators import (
    DEFAULT_HV_REFERENCE,
    hypervolume,
    igd,
    non_dominated,
    normalised_hypervolume,
    objective_bounds,
    to_unit_minimisation,
)
from adept_traj.analysis.paper_measures import (
    algorithm_effort,
    optimizer_overhead,
    ratio_non_dominated,
    spread,
)
from adept_traj.analysis.plausibility import REACH_FACTOR, robot_reach, unit_warnings
from adept_traj.analysis.weighted_sum import WEIGHTED_SUM_REFERENCE, WeightedSum, weighted_sum
from adept_traj.certification.certificate import (
    DEFAULT_RATE_HZ,
    Certificate,
    certificate_bytes,
    certify,
    check_certificate_memory,
)
from adept_traj.certification.continuous import (
    CONTINUOUS,
    DEFAULT_MAX_DEPTH,
    DistanceGuarantee,
    continuous_distance,
    continuous_self_distance,
    obstacle_jump_intervals,
    obstacle_speeds,
    solid_lever_arms,
)
from adept_traj.certification.dense_trajectory import (
    BATCH_SAMPLES,
    BATCH_VALUES,
    DenseStates,
    DenseTrajectory,
    batch_samples,
    dense_samples,
)
from adept_traj.certification.limit_check import DEFAULT_TOLERANCE, LimitCheck
from adept_traj.certification.member_certificate import (
    FRONT_INFLUENCE_ABOVE_MARGIN,
    MemberCertificate,
    certify_member,
    certify_members,
    certifying_problem,
    problem_parts,
    same_parts,
)
from adept_traj.certification.rest_poses import check_rest_poses, rest_pose_contacts
from adept_traj.certification.self_distance import SelfDistance, self_distance
from adept_traj.robot.limits import LIMIT_KINDS  # the one vocabulary, re-exported

__all__ = [
    "BATCH_SAMPLES",
    "BATCH_VALUES",
    "CONTINUOUS",
    "DEFAULT_HV_REFERENCE",
    "DEFAULT_MAX_DEPTH",
    "DEFAULT_RATE_HZ",
    "DEFAULT_TOLERANCE",
    "FRONT_INFLUENCE_ABOVE_MARGIN",
    "LIMIT_KINDS",
    "PAPER_WEIGHTS",
    "REACH_FACTOR",
    "WEIGHTED_SUM_REFERENCE",
    "BestTradeoff",
    "Certificate",
    "DenseStates",
    "DenseTrajectory",
    "DistanceGuarantee",
    "LimitCheck",
    "MemberCertificate",
    "SelfDistance",
    "WeightedSum",
    "algorithm_effort",
    "average_fitness",
    "batch_samples",
    "best_tradeoff",
    "certificate_bytes",
    "certify",
    "certify_member",
    "certify_members",
    "certifying_problem",
    "check_certificate_memory",
    "check_rest_poses",
    "combined_objective",
    "continuous_distance",
    "continuous_self_distance",
    "dense_samples",
    "hypervolume",
    "igd",
    "non_dominated",
    "normalise",
    "normalised_hypervolume",
    "objective_bounds",
    "objective_weights",
    "obstacle_jump_intervals",
    "obstacle_speeds",
    "optimizer_overhead",
    "problem_parts",
    "ratio_non_dominated",
    "rest_pose_contacts",
    "robot_reach",
    "same_parts",
    "self_distance",
    "solid_lever_arms",
    "spread",
    "to_unit_minimisation",
    "unit_warnings",
    "weighted_sum",
]
