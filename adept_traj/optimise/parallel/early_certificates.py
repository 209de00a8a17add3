"""The front's certificates started before the polish: :func:`start_early_certificates`,
:class:`EarlyCertificates`.

After the search :func:`~adept_traj.plan` polishes a few members in the main process (one
core; the other idles), then certifies the front. The polish only adds moves to the
population, so every member of the front after the polish that the polish did not make
was already a member before it: its certificate can be made while the polish runs.
:func:`start_early_certificates` forks one worker process
(:class:`~adept_traj.process_pool.Worker`) that certifies the members of the front before
the polish, in shares of :data:`EARLY_SHARE` members, the first share first
(:func:`~adept_traj.analysis.certify_members` on each share, in the trade-off order).
:meth:`EarlyCertificates.finish`, called once the polish is done, certifies shares in
the caller (the members still wanted only) from the last share down while the worker goes
on from the first up: before each share the caller claims it over the pipe, and the
worker, which reads the claims before each of its shares, stops where the caller's begin
(where both reach the same share at once, both certify it: the same summary). Then the
caller collects the worker's summaries. Every certificate depends on its member alone, so
the summaries are those :func:`~adept_traj.analysis.certify_members` makes in the caller,
field for field.
With one worker (``fork=False``) no process starts: the caller certifies every share in
:meth:`EarlyCertificates.finish` (while the helper of
:mod:`adept_traj.optimise.parallel.polish_worker` polishes, when there is one).

The worker never outlives the caller (:mod:`adept_traj.process_pool`): it ignores Ctrl-C
(the caller stops it), :meth:`EarlyCertificates.cancel` (or leaving the ``with`` block)
kills and reaps it, and it ends with the caller. A worker that fails or dies leaves its
shares to the caller, which certifies them again: an error it met is then raised in the
caller by the caller's own attempt (with the worker's error as a note), the same exception
as without the worker — or kept for later when the caller does not know yet whether the
member stays on the front (``failed``).
"""

from __future__ import annotations

import contextlib
from collections.abc import Collection, Sequence
from typing import Any

import numpy as np

from adept_traj.analysis.decision import best_tradeoff
from adept_traj.analysis.indicators import non_dominated
from adept_traj.certification.member_certificate import (
    MemberCertificate,
    certify_members,
    checked_members,
)
from adept_traj.errors import WorkerDiedError
from adept_traj.problem import TrajectoryProblem, from_pymoo
from adept_traj.process_helper import Helper
from adept_traj.process_pool import Channel, Worker, can_fork

__all__ = ["EARLY_SHARE", "EarlyCertificates", "feasible_front", "start_early_certificates"]

#: Members certified together, by the worker or by the caller (the caller waits at most
#: one share's time for a share under way).
EARLY_SHARE = 8


def start_early_certificates(
    problem: TrajectoryProblem,
    x: Any,
    members: Sequence[int],
    *,
    rate_hz: float,
    fork: bool = True,
) -> EarlyCertificates:
    """Fork a process that certifies ``members`` of ``x`` while the caller goes on.

    Parameters
    ----------
    problem: the problem the members were planned on.
    x: (n, n_var) decision vectors ``[T [s], free control points]``.
    members: the rows of ``x`` to certify, in the order of their shares (e.g. the
        trade-off order).
    rate_hz: the dense grid's minimum rate [Hz] (> 0).
    fork: start the process (``False``, e.g. for one worker: ``finish`` certifies every
        share in the caller).

    Returns
    -------
    EarlyCertificates
        The certificates under way; :meth:`EarlyCertificates.finish` gives them. With
        ``fork=False``, without ``fork`` on the platform or with no member no process
        starts and ``finish`` certifies in the caller.
    """
    xs, rows, rate = checked_members(problem, x, members, rate_hz)
    return EarlyCertificates(problem, np.array(xs), rows, rate, fork=bool(fork))


def feasible_front(F: Any, G: Any, weights: Any) -> np.ndarray:
    """Rows of a population's feasible non-dominated members in the trade-off order
    (:func:`~adept_traj.analysis.best_tradeoff` with ``weights``): the members
    :func:`~adept_traj.plan` certifies when nothing limits their number.

    Parameters
    ----------
    F: (n, 6) objectives in pymoo's signs (z4 negated), as in a run's state.
    G: (n, m) constraint values (≤ 0: satisfied).
    weights: the six weights of f_c.
    """
    objectives = from_pymoo(np.asarray(F, dtype=float))  # as plan reads them
    feasible = np.flatnonzero(np.all(np.asarray(G, dtype=float) <= 0.0, axis=1))
    if len(feasible) == 0:
        return feasible
    rows = np.unique(feasible[non_dominated(objectives[feasible])])
    return rows[best_tradeoff(objectives[rows], weights).order]


class EarlyCertificates(Helper):
    """The certificates started by :func:`start_early_certificates`; a context manager
    that stops its worker when the block is left.

    Attributes
    ----------
    pid : int or None
        The worker's process id (``None`` without one, or once it is reaped).
    """

    def __init__(
        self,
        problem: TrajectoryProblem,
        x: np.ndarray,
        rows: list[int],
        rate_hz: float,
        *,
        fork: bool = True,
    ) -> None:
        self._problem, self._x, self._rate = problem, x, rate_hz
        self._shares = [rows[i : i + EARLY_SHARE] for i in range(0, len(rows), EARLY_SHARE)]
        self._worker: Worker | None = None
        if fork and self._shares and can_fork():
            self._worker = Worker(_work, self, note="raised in the early certificates' worker")

    def finish(
        self, wanted: Collection[int] | None = None, *, failed: list[int] | None = None
    ) -> dict[int, MemberCertificate]:
        """Certify the shares the worker has not taken (only the members whose row of ``x``
        is in ``wanted``; ``None``: all), collect the worker's summaries
        and reap it (once: a second call certifies every share again, in the caller).

        With a list ``failed``, a share whose certificates raise in the caller is not
        raised: its members (rows of ``x``) are appended to ``failed``, for a caller that
        does not know yet which members it wants (:meth:`certify_again` later, for those
        still wanted).

        Returns
        -------
        dict
            The summary of each certified member by its row of ``x``.

        Raises
        ------
        Exception
            What :func:`~adept_traj.analysis.certify_members` raised in the caller for a
            share (the worker's error as a note when it failed on it first).
        """
        worker, self._worker = self._worker, None
        progress = _Progress(worker)
        mine: dict[int, MemberCertificate] = {}
        taken: set[int] = set()
        try:
            # the caller's shares: from the last down, until the worker's (the worker's
            # first up; without a worker, the caller's from the first)
            order = range(len(self._shares))
            for i in reversed(order) if worker is not None else order:
                progress.read(block=False)
                if i <= progress.started:
                    break
                progress.claim(i)
                taken.add(i)
                mine.update(self._certify(self._shares[i], wanted, failed))
            progress.read(block=True)
            for i, share in enumerate(self._shares):
                if i in progress.received:
                    mine.update(zip(share, progress.received[i]))
                elif i not in taken:  # the worker's share it did not send (failed or died)
                    mine.update(self._certify(share, wanted, failed))
        except Exception as exc:
            progress.close()
            if progress.note:
                exc.add_note(f"the early certificates' worker failed first:\n{progress.note}")
            raise
        except BaseException:  # Ctrl-C included: stop the worker at once
            progress.close()
            raise
        progress.close()
        return mine

    def certify_again(
        self, rows: list[int], wanted: Collection[int]
    ) -> dict[int, MemberCertificate]:
        """The certificates of the members ``rows`` (from :meth:`finish`'s ``failed``) that
        are in ``wanted`` (rows of ``x``), made in the caller, by row; an error is raised."""
        return self._certify(rows, wanted)

    def _certify(
        self,
        share: list[int],
        wanted: Collection[int] | None,
        failed: list[int] | None = None,
    ) -> dict[int, MemberCertificate]:
        rows = [k for k in share if wanted is None or k in wanted]
        try:
            out = certify_members(self._problem, self._x, rows, rate_hz=self._rate)
        except Exception:
            if failed is None:
                raise
            failed.extend(rows)  # raised later if one of them is still wanted
            return {}
        return {k: out[k] for k in rows}


class _Progress:
    """The caller's view of the worker: the shares it has started and sent, its error."""

    def __init__(self, worker: Worker | None) -> None:
        self.worker = worker
        self.started = -1  # the last share the worker has started
        self.received: dict[int, list[MemberCertificate]] = {}
        self.note = ""  # the worker's error, when it failed

    def claim(self, i: int) -> None:
        """Tell the worker that the caller certifies share ``i`` (and every later one)."""
        if self.worker is not None:
            # an ended worker's messages are still read; its shares not sent: the caller's
            with contextlib.suppress(WorkerDiedError):
                self.worker.send(i)

    def read(self, *, block: bool) -> None:
        """Read the worker's messages: those waiting, or (``block``) all until it ends."""
        while self.worker is not None and (block or self.worker.poll()):
            try:
                message = self.worker.recv()
            except WorkerDiedError:  # killed: its shares not sent are the caller's
                self.close()
                return
            except Exception as exc:  # failed on a share: that share is the caller's
                self.note = "".join([str(exc), *getattr(exc, "__notes__", [])])
                self.close()
                return
            if message[0] == "start":
                self.started = message[1]
            elif message[0] == "done":
                self.received[message[1]] = message[2]
            else:  # "end": no more shares
                self.close()

    def close(self) -> None:
        if self.worker is not None:
            self.worker.close()
            self.worker = None


def _work(channel: Channel, job: EarlyCertificates) -> None:
    """The worker: certify the shares from the first up until one the caller has claimed
    (its claims read before each share), sending ``("start", i)`` before and ``("done", i,
    summaries)`` after each share, then ``("end",)``; an error is carried to the caller."""
    limit = len(job._shares)
    for i in range(len(job._shares)):
        while channel.poll():  # the caller's claims, from the last share down
            limit = min(limit, channel.recv()[0])
        if i >= limit:
            break
        channel.send(("start", i))
        summaries = job._certify(job._shares[i], None)
        channel.send(("done", i, [summaries[k] for k in job._shares[i]]))
    channel.send(("end",))
