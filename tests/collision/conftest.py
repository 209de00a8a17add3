"""Fixtures shared by the collision tests."""

from __future__ import annotations

import numpy as np
import pytest

from adept_traj.scene import PointCloud


@pytest.fixture(scope="module")
def fence() -> PointCloud:
    """A scanned fence: 40 000 points on a cylinder of radius 1 m, 0–0.6 m high."""
    rng = np.random.default_rng(28)
    a = rng.uniform(0.0, 2.0 * np.pi, 40_000)
    points = np.column_stack([np.cos(a), np.sin(a), rng.uniform(0.0, 0.6, len(a))])
    return PointCloud(points, 0.01)
