"""Exact robot-obstacle distances over time: checker, conservative broad phase, distance tables."""

from __future__ import annotations

from adept_traj.collision.broad_phase import Bounds, BroadPhase
from adept_traj.collision.checker import (
    CollisionChecker,
    MinDistances,
    PairDistances,
)
from adept_traj.collision.distance_table import DistanceTable
from adept_traj.collision.point_distance import point_signed_distance
from adept_traj.collision.primitives import DISTANCE_TOLERANCE, distance_request

__all__ = [
    "DISTANCE_TOLERANCE",
    "Bounds",
    "BroadPhase",
    "CollisionChecker",
    "DistanceTable",
    "MinDistances",
    "PairDistances",
    "distance_request",
    "point_signed_distance",
]
