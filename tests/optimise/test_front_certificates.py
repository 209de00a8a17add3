"""certify_front_members: the front members' certificates on forked processes are the
serial ones (analysis.certify_members called directly), in the members' rows."""

from __future__ import annotations

import numpy as np
import pytest

from adept_traj import TrajectoryProblem
from adept_traj.certification import certify_members
from adept_traj.errors import InvalidInputError
from adept_traj.optimise import RampSampling, certify_front_members, kinematic_time


@pytest.fixture(scope="module")
def x(problem: TrajectoryProblem) -> np.ndarray:
    """Seven random ramps at 1.2 × their kinematic minimum time (feasible or not)."""
    x = RampSampling().ramps(problem, 7, np.random.default_rng(5))
    x[:, 0] = np.clip(1.2 * kinematic_time(problem, x), problem.xl[0], problem.xu[0])
    return x


def test_two_processes_give_the_serial_certificates(
    problem: TrajectoryProblem, x: np.ndarray
) -> None:
    members = [4, 0, 6, 2, 5]  # a trade-off order, rows 1 and 3 not certified
    serial = certify_members(problem, x, members, rate_hz=400.0)
    forked = certify_front_members(problem, x, members, rate_hz=400.0, workers=2)
    assert len(forked) == len(x)
    assert forked[1] is None
    assert forked[3] is None
    assert all(forked[k] is not None for k in members)
    assert forked == serial  # every field of every summary, exactly
    one = certify_front_members(problem, x, members, rate_hz=400.0, workers=1)
    assert one == serial


def test_bad_input_is_refused_before_any_process_starts(
    problem: TrajectoryProblem, x: np.ndarray
) -> None:
    with pytest.raises(InvalidInputError, match="member"):
        certify_front_members(problem, x, [0, 7], rate_hz=400.0, workers=2)
    with pytest.raises(InvalidInputError, match="workers"):
        certify_front_members(problem, x, [0, 1], rate_hz=400.0, workers=0)
    with pytest.raises(InvalidInputError, match="rate_hz"):
        certify_front_members(problem, x, [0, 1], rate_hz=0.0, workers=2)
    assert certify_front_members(problem, x, [], rate_hz=400.0, workers=2) == (None,) * 7
