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

__all__ = [
    "Bounds",
    "BroadPhase",
    "CollisionChecker",
    "DistanceTable",
    "MinDistances",
    "PairDistances",
    "point_signed_distance",
]
