"""The cached certifying problem follows the problem's settings (review finding: a margin
changed after the first certificate was ignored by ``certify_members``; the problem is now
frozen, a margin changes in a copy), and the continuous bounds take no caller-given
acceleration bound."""

from __future__ import annotations

import dataclasses
import inspect

import pytest

from adept_traj.certification import (
    certify,
    certify_members,
    certifying_problem,
    continuous_distance,
    continuous_self_distance,
    self_distance,
)
from adept_traj.errors import FrozenObjectError
from adept_traj.problem import TrajectoryProblem
from adept_traj.robot import Robot
from adept_traj.scene import Scene
from adept_traj.testing.paper_moves import lift_then_lower


def _problem() -> TrajectoryProblem:
    scene = Scene.paper()
    return TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal, workers=1)


def test_a_copy_with_another_margin_is_certified_with_it():
    """The problem is frozen (issue #27): a margin changes in a copy, which certifies with
    it; the original and its cached certifying problem are unchanged."""
    problem = _problem()
    x = lift_then_lower(problem)
    first = certify_members(problem, x[None])[0]
    clearance = certify(problem, x).min_distance
    assert first.feasible == (clearance >= problem.settings.margin)
    # A margin above the move's clearance: both certificates of the copy must say "no".
    stricter = problem.replace(margin=float(clearance) + 0.005)
    assert stricter.settings == dataclasses.replace(problem.settings, margin=clearance + 0.005)
    assert not certify(stricter, x).feasible
    assert not certify_members(stricter, x[None])[0].feasible
    assert certifying_problem(stricter)[0].settings.margin == stricter.settings.margin
    again = certify_members(problem, x[None])[0]
    assert (again.feasible, again.min_distance) == (first.feasible, first.min_distance)
    with pytest.raises(FrozenObjectError):
        problem.settings = stricter.settings


def test_the_certifying_problem_is_made_once_while_nothing_changes():
    problem = _problem()
    assert certifying_problem(problem)[0] is certifying_problem(problem)[0]


def test_no_public_acceleration_bound():
    for f in (continuous_distance, continuous_self_distance, self_distance):
        assert "acceleration_bound" not in inspect.signature(f).parameters
