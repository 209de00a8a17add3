"""The front members' certificates on the problem's worker processes.

:func:`~adept_traj.analysis.certify_members` certifies one batch of members after the
other (its cost per member: docs/performance.md).
:func:`certify_front_members` gives each of ``workers`` processes (this one and
``workers - 1`` worker processes, :func:`~adept_traj.process_pool.map_forked`) every
``workers``-th member (the trade-off order interleaved, so that each gets as many of the
costly and the cheap ones), each process calls
:func:`~adept_traj.analysis.certify_members` once on its share, and the summaries come
back in the members' rows. Every certificate depends on its member alone, so the result is
the serial one, field for field (tested). The fork hands the problem and the decision
vectors to the workers (nothing is pickled but the summaries).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from adept_traj.certification.member_certificate import (
    MemberCertificate,
    certify_members,
    certifying_problem,
    checked_members,
)
from adept_traj.problem import TrajectoryProblem
from adept_traj.process_pool import can_fork, map_forked
from adept_traj.validation import as_integer

__all__ = ["certify_front_members"]


def certify_front_members(
    problem: TrajectoryProblem,
    x: Any,
    members: Sequence[int],
    *,
    rate_hz: float,
    workers: int | None = None,
) -> tuple[MemberCertificate | None, ...]:
    """:func:`~adept_traj.analysis.certify_members` of ``members`` on ``workers`` processes.

    Parameters
    ----------
    problem: the problem the members were planned on.
    x: (n, n_var) decision vectors ``[T [s], free control points]``.
    members: the rows of ``x`` to certify; the others get ``None``.
    rate_hz: the dense grid's minimum rate [Hz] (> 0).
    workers: processes certifying at once, ≥ 1 (default: the problem's ``workers``); 1,
        one member, or a platform without ``fork`` certifies in this process.

    Returns
    -------
    tuple
        (n,) a :class:`~adept_traj.analysis.MemberCertificate` per certified row, ``None``
        for the others — the same as :func:`~adept_traj.analysis.certify_members`.
    """
    xs, rows, rate = checked_members(problem, x, members, rate_hz)
    n_proc = problem.settings.workers if workers is None else workers
    n_proc = min(as_integer(n_proc, "workers", minimum=1), len(rows))
    if n_proc <= 1 or not can_fork():
        return certify_members(problem, xs, rows, rate_hz=rate)
    certifying_problem(problem)  # made once here: the workers inherit it
    shares = [rows[i::n_proc] for i in range(n_proc)]

    def certify_share(share: list[int]) -> list[MemberCertificate | None]:
        out = certify_members(problem, xs, share, rate_hz=rate)
        return [out[k] for k in share]

    note = "raised while certifying front members in a worker process"
    parts = map_forked(certify_share, shares, n_proc, note=note)
    out: list[MemberCertificate | None] = [None] * len(xs)
    for share, part in zip(shares, parts):
        for k, certificate in zip(share, part):
            out[k] = certificate
    return tuple(out)
