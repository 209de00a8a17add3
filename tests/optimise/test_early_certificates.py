"""start_early_certificates: the front's certificates made on a forked process while the
caller works are the serial ones (analysis.certify_members called directly); a failing or
killed process leaves its shares to the caller; no process outlives the call."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest

import adept_traj.optimise.parallel.early_certificates as early_module
from adept_traj import TrajectoryProblem
from adept_traj.certification import certify_members
from adept_traj.errors import InvalidInputError
from adept_traj.optimise import (
    RampSampling,
    feasible_front,
    kinematic_time,
    start_early_certificates,
)

MEMBERS = [4, 0, 6, 2, 5]  # a trade-off order, rows 1 and 3 not certified


@pytest.fixture(scope="module")
def x(problem: TrajectoryProblem) -> np.ndarray:
    """Seven random ramps at 1.2 × their kinematic minimum time (feasible or not)."""
    x = RampSampling().ramps(problem, 7, np.random.default_rng(5))
    x[:, 0] = np.clip(1.2 * kinematic_time(problem, x), problem.xl[0], problem.xu[0])
    return x


@pytest.fixture(scope="module")
def serial(problem: TrajectoryProblem, x: np.ndarray) -> dict[int, object]:
    out = certify_members(problem, x, MEMBERS, rate_hz=400.0)
    return {k: out[k] for k in MEMBERS}


@pytest.fixture
def shares_of_two(monkeypatch: pytest.MonkeyPatch) -> None:
    """Shares of two members: the process and the caller each take some."""
    monkeypatch.setattr(early_module, "EARLY_SHARE", 2)


def _ended(pid: int) -> bool:
    """Whether the process has ended (a zombie not yet reaped, or gone)."""
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return stat.read().rsplit(")", 1)[1].split()[0] == "Z"
    except FileNotFoundError:
        return True


def test_the_summaries_are_the_serial_ones(problem, x, serial, shares_of_two, process_gone) -> None:
    with start_early_certificates(problem, x, MEMBERS, rate_hz=400.0) as early:
        pid = early.pid
        assert pid is not None
        out = early.finish()
    assert out == serial  # every field of every summary, exactly
    assert early.pid is None
    assert process_gone(pid)


def test_the_caller_certifies_only_the_members_still_wanted(problem, x, serial) -> None:
    early = start_early_certificates(problem, x, MEMBERS, rate_hz=400.0)
    early.cancel()  # the process did nothing: the caller takes every share
    wanted = {4, 2}
    assert early.finish(wanted) == {k: serial[k] for k in wanted}


def test_without_fork_the_caller_certifies_every_share(problem, x, serial) -> None:
    early = start_early_certificates(problem, x, MEMBERS, rate_hz=400.0, fork=False)
    assert early.pid is None
    assert early.finish() == serial


@pytest.mark.parametrize("fault", ["raises", "killed"])
def test_a_failing_or_killed_process_leaves_its_shares_to_the_caller(
    problem, x, serial, shares_of_two, monkeypatch, child_fault, fault
) -> None:
    faulty = child_fault(early_module.certify_members, fault)
    monkeypatch.setattr(early_module, "certify_members", faulty)
    with start_early_certificates(problem, x, MEMBERS, rate_hz=400.0) as early:
        assert early.finish() == serial


def test_an_error_is_raised_in_the_caller_with_the_process_traceback(
    problem, x, shares_of_two, monkeypatch, process_gone
) -> None:
    def fails(*args, **kwargs):
        raise RuntimeError(f"certificate broken in {os.getpid()}")

    monkeypatch.setattr(early_module, "certify_members", fails)
    with start_early_certificates(problem, x, MEMBERS, rate_hz=400.0) as early:
        pid = early.pid
        deadline = time.monotonic() + 30.0
        while not _ended(pid) and time.monotonic() < deadline:  # it fails on its first share
            time.sleep(0.01)
        with pytest.raises(RuntimeError, match=f"broken in {os.getpid()}") as caught:
            early.finish()
    assert any(f"broken in {pid}" in note for note in caught.value.__notes__)
    assert process_gone(pid)


def test_failed_shares_are_kept_for_later_and_raised_only_if_still_wanted(
    problem, x, serial, shares_of_two, monkeypatch
) -> None:
    """With the polish in another process the caller does not know yet which members stay
    on the front: a member whose certificate fails is raised only if it is still wanted."""
    real = early_module.certify_members

    def fails_on_six(problem, x, rows, **kwargs):
        if 6 in list(rows):
            raise RuntimeError("member 6 cannot be certified")
        return real(problem, x, rows, **kwargs)

    monkeypatch.setattr(early_module, "certify_members", fails_on_six)
    with start_early_certificates(problem, x, MEMBERS, rate_hz=400.0) as early:
        failed: list[int] = []
        out = early.finish(failed=failed)
        assert failed == [6, 2]  # the share of members 6 and 2 (shares of two)
        assert out == {k: v for k, v in serial.items() if k not in (2, 6)}
        assert early.certify_again(failed, {2}) == {2: serial[2]}
        with pytest.raises(RuntimeError, match="member 6"):
            early.certify_again(failed, {2, 6})


def test_bad_input_is_refused_before_any_process_starts(problem, x) -> None:
    with pytest.raises(InvalidInputError, match="member"):
        start_early_certificates(problem, x, [0, 7], rate_hz=400.0)
    with pytest.raises(InvalidInputError, match="rate_hz"):
        start_early_certificates(problem, x, [0, 1], rate_hz=0.0)
    nothing = start_early_certificates(problem, x, [], rate_hz=400.0)
    assert nothing.pid is None
    assert nothing.finish() == {}


def test_feasible_front_holds_the_feasible_non_dominated_rows() -> None:
    z = np.array([[1, 2, 1, 2, 1, 1], [2, 3, 2, 1, 2, 2], [2, 1, 1, 2, 1, 1], [0, 0, 0, 9, 0, 0]])
    F = z * np.array([1, 1, 1, -1, 1, 1])  # pymoo's signs: z4 negated
    G = np.array([[0.0], [-1.0], [-0.5], [0.1]])  # row 3 infeasible, row 1 dominated by row 0
    assert sorted(feasible_front(F, G, np.ones(6)).tolist()) == [0, 2]
    assert len(feasible_front(F, np.ones((4, 1)), np.ones(6))) == 0
