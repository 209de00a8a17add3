"""The front members' certificates on the problem's worker processes.

:func:`~adept_traj.analysis.certify_members` certifies one batch of members after the
other (``benchmarks/bench_certify.py`` times it; ``docs/performance.md``).
:func:`certify_front_members` gives each of ``workers`` forked processes every
``workers``-th member (the trade-off order interleaved, so that each gets as many of the
costly and the cheap ones), each process calls
:func:`~adept_traj.analysis.certify_members` once on its share, and the summaries come
back in the members' rows. Every certificate depends on its member alone, so the result is
the serial one, field for field (tested). Fork hands the problem and the decision vectors
to the processes (nothing is pickled but the lists of rows and the summaries).
"""

from __future__ import annotations

import multiprocessing
import signal
from collections.abc import Sequence
from typing import Any

import numpy as np

from adept_traj.analysis.member_certificate import (
    MemberCertificate,
    certify_members,
    certifying_problem,
)
from adept_traj.errors import ConfigurationError, InputShapeError
from adept_traj.problem import TrajectoryProblem
from adept_traj.validation import as_batch, as_integer, as_scalar, check_type

__all__ = ["certify_front_members"]

#: (problem, x, rate_hz) of the certifying process, set once by the pool's initializer;
#: ``None`` in every other process.
_JOB: tuple[TrajectoryProblem, np.ndarray, float] | None = None


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
    xs, rows, rate = _checked(problem, x, members, rate_hz)
    n_proc = problem.settings.workers if workers is None else workers
    n_proc = min(as_integer(n_proc, "workers", minimum=1), len(rows))
    if n_proc <= 1 or "fork" not in multiprocessing.get_all_start_methods():
        return certify_members(problem, xs, rows, rate_hz=rate)
    certifying_problem(problem)  # made once here: the forked processes inherit it
    shares = [rows[i::n_proc] for i in range(n_proc)]
    pool = multiprocessing.get_context("fork").Pool(
        n_proc, initializer=_start, initargs=(problem, xs, rate)
    )
    try:
        parts = pool.map(_certify_share, shares, chunksize=1)
        pool.close()
    except BaseException:  # Ctrl-C included: stop the processes at once
        pool.terminate()
        raise
    finally:
        pool.join()
    out: list[MemberCertificate | None] = [None] * len(xs)
    for share, part in zip(shares, parts):
        for k, certificate in zip(share, part):
            out[k] = certificate
    return tuple(out)


def _checked(
    problem: Any, x: Any, members: Sequence[int], rate_hz: Any
) -> tuple[np.ndarray, list[int], float]:
    """The members' checked input: (n, n_var) ``x``, the rows, the rate [Hz] (> 0)."""
    check_type(problem, TrajectoryProblem, "problem")
    xs = as_batch(x, "x", problem.n_var)
    if xs.ndim != 2:
        raise InputShapeError(f"x must have shape (n, {problem.n_var}); got {xs.shape}")
    rate = as_scalar(rate_hz, "rate_hz", "[Hz]", minimum=0.0, strict=True)
    rows = [as_integer(k, "member", minimum=0, maximum=len(xs) - 1) for k in members]
    return xs, rows, rate


def _start(problem: TrajectoryProblem, x: np.ndarray, rate_hz: float) -> None:
    """Pool initializer, once per forked process: keep the job; Ctrl-C is the parent's."""
    global _JOB
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _JOB = (problem, x, rate_hz)


def _certify_share(rows: list[int]) -> list[MemberCertificate]:
    """Run in a certifying process: the summaries of ``rows``, in that order."""
    if _JOB is None:  # only a pool started by certify_front_members calls this
        raise ConfigurationError("_certify_share runs in a certify_front_members process only")
    problem, x, rate_hz = _JOB
    out = certify_members(problem, x, rows, rate_hz=rate_hz)
    return [out[k] for k in rows]
