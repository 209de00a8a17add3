"""The member certificates of a front (analysis.member_certificate, result.json v2)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import adept_traj as at
from adept_traj.certification import (
    FRONT_INFLUENCE_ABOVE_MARGIN,
    MemberCertificate,
    certify,
    certify_members,
)
from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.robot import LIMIT_KINDS
from adept_traj.testing.paper_moves import lift_then_lower


@pytest.fixture(scope="module")
def moves(problem: at.TrajectoryProblem) -> np.ndarray:
    """(4, n_var): two clear moves, a slow one, and a straight line through the pendulum."""
    return np.vstack(
        [
            lift_then_lower(problem),
            lift_then_lower(problem, T=2.2),
            lift_then_lower(problem, T=3.0),
            problem.trajectory.straight_line(1.5),
        ]
    )


@pytest.fixture(scope="module")
def summaries(problem, moves) -> tuple[MemberCertificate | None, ...]:
    return certify_members(problem, moves, [3, 0, 1])


def test_same_verdict_as_the_exact_certificate(problem, moves, summaries) -> None:
    """The lowered influence changes no verdict, and the smallest distance is the exact one
    where flagged exact, else a lower bound above the influence distance."""
    assert summaries[2] is None  # not asked for
    influence = problem.settings.margin + FRONT_INFLUENCE_ABOVE_MARGIN
    verdicts = []
    for k in (0, 1, 3):
        exact = certify(problem, moves[k])
        m = summaries[k]
        verdicts.append(m.feasible)
        assert m.feasible == exact.certified
        assert m.guarantee == exact.guarantee
        assert m.min_distance_exact == (exact.min_distance <= influence)
        if m.min_distance_exact:
            assert m.min_distance == pytest.approx(exact.min_distance, abs=1e-12)
            assert m.t_min_distance == exact.t_min_distance
            assert m.closest_pair == exact.closest_pair
        else:
            assert influence < m.min_distance <= exact.min_distance + 1e-12
    assert verdicts == [True, True, False]  # the straight line hits the pendulum
    assert summaries[3].violations


def test_worst_values_from_the_dense_samples(problem, moves, summaries) -> None:
    """Each worst ratio is at least the largest |value| / limit over the dense samples
    (the certificate adds the spline's exact extrema), and attained on its joint."""
    m = summaries[0]
    dense = certify(problem, moves[0], continuous=False).dense
    limits = problem.robot.limits
    for kind, series in (
        ("velocity", dense.qd),
        ("acceleration", dense.qdd),
        ("torque", dense.tau),
    ):
        ratio = np.abs(series) / limits.bound(kind)
        assert m.worst_of(kind) >= ratio.max() - 1e-9
        j = m.worst_joint[LIMIT_KINDS.index(kind)]
        assert ratio[:, j].max() == pytest.approx(ratio.max(), rel=0.05)
    assert m.worst_of("position") <= 0.0  # inside the joint ranges
    assert all(0.0 < m.worst_of(kind) <= 1.0 for kind in LIMIT_KINDS[1:])
    assert min(m.t_worst) >= 0.0
    assert max(m.t_worst) <= moves[0][0]


def test_bad_input(problem, moves, summaries) -> None:
    with pytest.raises(InputShapeError, match=r"x must have shape \(n, "):
        certify_members(problem, moves[0])
    with pytest.raises(InvalidInputError, match=r"member must be an integer in \[0, 3\]"):
        certify_members(problem, moves, [4])
    with pytest.raises(InvalidInputError, match="kind must be one of"):
        summaries[0].worst_of("speed")
    with pytest.raises(InvalidInputError, match="one value per limit kind"):
        dataclasses.replace(summaries[0], worst=(0.5,))
