"""plan() certifies every front member once (but the local solver's starts, issue #24):
the polish's certificates of the moves it keeps are the front's (issue #15), the same
summaries as certifying the front afresh."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from adept_traj import TrajectoryProblem, plan
from adept_traj.certification import MemberCertificate, certify_members
from adept_traj.optimise import MAX_BASINS


@pytest.fixture(scope="module")
def counted_run(problem: TrajectoryProblem):
    """A small NSGA-II run with the polish of its fastest member (one process), and how
    often each move's certificate was summarised (``MemberCertificate.of``: every member
    certificate, the polish's and the front's; the reported solution's exact certificate
    is not summarised)."""
    calls: Counter[bytes] = Counter()
    real = MemberCertificate.of

    def counting(cls, certificate, *args, **kwargs):
        calls[certificate.x.tobytes()] += 1
        return real(certificate, *args, **kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(MemberCertificate, "of", classmethod(counting))
        result = plan(problem, "nsga2", seed=1, pop_size=16, n_gen=4, polish="fastest")
    return result, calls


def test_no_move_is_certified_twice(counted_run) -> None:
    result, calls = counted_run
    polished = result.front.x[np.argmin(result.front.x[:, 0])]
    assert result.metrics.t_best_source == "polish"  # the polish kept its move: it is in the front
    assert calls[polished.tobytes()] == 1
    # the local solver certifies its start (a search member, also certified with the
    # front meanwhile): the only moves certified twice are such starts, one per basin
    twice = [x for x, n in calls.items() if n > 1]
    assert max(calls.values()) <= 2
    assert len(twice) <= MAX_BASINS
    assert polished.tobytes() not in twice
    certified = [k for k, c in enumerate(result.front.certificates) if c is not None]
    # every front member's summary was made (once); the others made are of the local
    # solver's starts and of its rounds (issue #24), none of them a second time
    assert {result.front.x[k].tobytes() for k in certified} <= set(calls)


def test_front_summaries_are_those_of_a_fresh_certification(problem, counted_run) -> None:
    result, _ = counted_run
    rows = [k for k, c in enumerate(result.front.certificates) if c is not None]
    fresh = certify_members(problem, result.front.x, rows, rate_hz=1000.0)
    assert fresh == result.front.certificates  # every field of every summary, exactly
