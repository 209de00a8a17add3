"""Robot-obstacle distances over time.

The checker, the conservative broad phase, the branch and bound (``search_pairs``), obstacle
pruning, distance tables, closed-form point distances, the distances' derivatives in (q, t)
from coal's witness points (``distance_gradients``) and the coal primitives
(``distance_request``: the settings every distance uses).
"""

from __future__ import annotations

from adept_traj.collision.branch_and_bound import search_pairs
from adept_traj.collision.broad_phase import Bounds, BroadPhase
from adept_traj.collision.capsules import enclosing_capsule, segment_distance
from adept_traj.collision.checker import (
    CollisionChecker,
    MinDistances,
    PairDistances,
)
from adept_traj.collision.cloud_search import SearchSamples
from adept_traj.collision.collision_matrix import (
    MATRIX_SAMPLES,
    CollisionMatrix,
    SelfPairs,
    collision_matrix,
    robot_collision_matrix,
    self_collision_check,
)
from adept_traj.collision.distance_gradient import (
    WITNESS_TOLERANCES,
    DistanceGradients,
    distance_gradients,
)
from adept_traj.collision.distance_table import DistanceTable, table_bounds
from adept_traj.collision.lever_arms import pair_lever_arms, solid_lever_arms
from adept_traj.collision.point_distance import point_signed_distance
from adept_traj.collision.primitives import (
    DISTANCE_TOLERANCE,
    coal_kind,
    distance_request,
    shape_of,
)
from adept_traj.collision.pruning import (
    ObstaclePruning,
    restrict_broad_phase,
    restrict_checker,
    sweep_clearance,
)
from adept_traj.collision.self_collision import SelfCollision, SelfDistances

__all__ = [
    "DISTANCE_TOLERANCE",
    "MATRIX_SAMPLES",
    "WITNESS_TOLERANCES",
    "Bounds",
    "BroadPhase",
    "CollisionChecker",
    "CollisionMatrix",
    "DistanceGradients",
    "DistanceTable",
    "MinDistances",
    "ObstaclePruning",
    "PairDistances",
    "SearchSamples",
    "SelfCollision",
    "SelfDistances",
    "SelfPairs",
    "coal_kind",
    "collision_matrix",
    "distance_gradients",
    "distance_request",
    "enclosing_capsule",
    "pair_lever_arms",
    "point_signed_distance",
    "restrict_broad_phase",
    "restrict_checker",
    "robot_collision_matrix",
    "search_pairs",
    "segment_distance",
    "self_collision_check",
    "shape_of",
    "solid_lever_arms",
    "sweep_clearance",
    "table_bounds",
]
