"""The front's certificates started before the polish: :func:`start_early_certificates`,
:class:`EarlyCertificates`.

After the search :func:`~adept_traj.plan` polishes a few members in the main process (one
core; the other idles), then certifies the front. The polish only adds moves to the
population, so every member of the front after the polish that the polish did not make
was already a member before it: its certificate can be made while the polish runs.
:func:`start_early_certificates` forks one process that certifies the members of the
front before the polish, in shares of :data:`EARLY_SHARE` members taken one after the other
from a shared counter (:func:`~adept_traj.analysis.certify_members` on each share, in the
trade-off order). :meth:`EarlyCertificates.finish`, called once the polish is done, takes
the shares that are left from the same counter and certifies them in the caller (the
members still wanted only) while the process goes on with its own, then collects the
process' summaries. Every certificate depends on its member alone, so the summaries are
those :func:`~adept_traj.analysis.certify_members` makes in the caller, field for field.
With one worker (``fork=False``) no process starts: the caller certifies every share in
:meth:`EarlyCertificates.finish` (while the helper of
:mod:`adept_traj.optimise.polisher` polishes, when there is one).

The process never outlives the caller: it ignores Ctrl-C (the caller stops it),
:meth:`EarlyCertificates.cancel` (or leaving the ``with`` block) terminates and reaps it,
and it ends by itself between two shares when its parent is gone. A process that fails
or dies leaves its shares to the caller, which certifies them again: an error it met
is then raised in the caller by the caller's own attempt (with the process' traceback as
a note), the same exception as without the process.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import traceback
from collections.abc import Collection, Sequence
from typing import Any

import numpy as np

from adept_traj.analysis.decision import best_tradeoff
from adept_traj.analysis.indicators import non_dominated
from adept_traj.analysis.member_certificate import MemberCertificate, certify_members
from adept_traj.optimise.front_certificates import _checked
from adept_traj.problem import TrajectoryProblem, from_pymoo
from adept_traj.processes import ForkedHelper

__all__ = ["EARLY_SHARE", "EarlyCertificates", "feasible_front", "start_early_certificates"]

#: Members certified together, by the process or by the caller (≈ 60 ms of CPU on the
#: paper scene: the caller waits at most about that long for a share under way).
EARLY_SHARE = 8
#: Longest wait for the shares' counter [s]; longer, its holder died holding it.
LOCK_TIMEOUT = 5.0
_DONE = "done"


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
    xs, rows, rate = _checked(problem, x, members, rate_hz)
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


class EarlyCertificates(ForkedHelper):
    """The certificates started by :func:`start_early_certificates`; a context manager
    that stops its process when the block is left
    (:class:`~adept_traj.processes.ForkedHelper`: ``cancel``, ``pid``).
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
        fork = fork and bool(self._shares) and "fork" in multiprocessing.get_all_start_methods()
        self._next: Any = multiprocessing.get_context("fork").Value("i", 0) if fork else _Counter()
        super().__init__(_work if fork else None, (self,))

    def finish(
        self, wanted: Collection[bytes] | None = None, *, failed: list[int] | None = None
    ) -> dict[bytes, MemberCertificate]:
        """Certify the shares no process has taken (only the members whose
        ``x[k].tobytes()`` is in ``wanted``; ``None``: all), collect the process' summaries
        and reap it (once: a second call certifies every share again, in the caller).

        With a list ``failed``, a share whose certificates raise in the caller is not
        raised: its members (rows of ``x``) are appended to ``failed``, for a caller that
        does not know yet which members it wants (:meth:`certify_again` later, for those
        still wanted).

        Returns
        -------
        dict
            The summary of each certified member by its ``x[k].tobytes()``.

        Raises
        ------
        Exception
            What :func:`~adept_traj.analysis.certify_members` raised in the caller for a
            share (the process' traceback as a note when it failed on it first).
        """
        mine: dict[int, MemberCertificate] = {}
        taken: set[int] = set()
        received: dict[int, list[MemberCertificate]] = {}
        note = ""
        try:
            while (i := _take(self._next, len(self._shares))) is not None:
                taken.add(i)
                note = self._drain(received, block=False) or note
                mine.update(self._certify(self._shares[i], wanted, failed))
            note = self._drain(received, block=True) or note
            self._reap()
            for i, share in enumerate(self._shares):
                if i in received:
                    mine.update(zip(share, received[i]))
                elif i not in taken:  # the process' share it did not send (failed or died)
                    mine.update(self._certify(share, wanted, failed))
        except Exception as exc:
            self.cancel()
            if note:
                exc.add_note(f"the early certificates' process failed first:\n{note}")
            raise
        except BaseException:  # Ctrl-C included: stop the process at once
            self.cancel()
            raise
        return {self._x[k].tobytes(): summary for k, summary in mine.items()}

    def certify_again(
        self, rows: list[int], wanted: Collection[bytes]
    ) -> dict[bytes, MemberCertificate]:
        """The certificates of the members ``rows`` (from :meth:`finish`'s ``failed``) whose
        ``x[k].tobytes()`` is in ``wanted``, made in the caller; an error is raised."""
        return {self._x[k].tobytes(): c for k, c in self._certify(rows, wanted).items()}

    def _certify(
        self,
        share: list[int],
        wanted: Collection[bytes] | None,
        failed: list[int] | None = None,
    ) -> dict[int, MemberCertificate]:
        rows = [k for k in share if wanted is None or self._x[k].tobytes() in wanted]
        try:
            out = certify_members(self._problem, self._x, rows, rate_hz=self._rate)
        except Exception:
            if failed is None:
                raise
            failed.extend(rows)  # raised later if one of them is still wanted
            return {}
        return {k: out[k] for k in rows}

    def _drain(self, received: dict[int, list[MemberCertificate]], *, block: bool) -> str:
        """Receive the process' messages (all of them until it ends if ``block``, else
        those waiting); return its traceback if it failed."""
        if self._conn is None:
            return ""
        while block or self._conn.poll():
            try:
                message = self._conn.recv()
            except (EOFError, OSError):  # ended without a word (killed)
                return ""
            if message == _DONE:
                return ""
            i, summaries, text = message
            if text:
                return text
            received[i] = summaries
        return ""


class _Counter:
    """The shares' counter of a run without a process (the ``value`` of a shared int)."""

    def __init__(self) -> None:
        self.value = 0

    def get_lock(self) -> Any:
        return self

    def acquire(self, timeout: float | None = None) -> bool:
        return True

    def release(self) -> None:
        return None


def _take(counter: Any, n: int) -> int | None:
    """The next share nobody has taken (``None``: none is left, or the lock stayed taken
    for :data:`LOCK_TIMEOUT` seconds: its holder was killed holding it)."""
    lock = counter.get_lock()
    if not lock.acquire(timeout=LOCK_TIMEOUT):
        return None
    try:
        i = counter.value
        if i >= n:
            return None
        counter.value = i + 1
    finally:
        lock.release()
    return i


def _work(conn: Any, callers_end: Any, parent: int, job: EarlyCertificates) -> None:
    """The process: take shares until none is left or the parent is gone, send
    ``(share, summaries, "")`` for each, ``(share, None, traceback)`` on an error, then
    ``"done"``; end at once (``os._exit``: none of the parent's exit handlers runs)."""
    code = 0
    try:
        callers_end.close()
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C: the caller stops it
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        while os.getppid() == parent and (i := _take(job._next, len(job._shares))) is not None:
            try:
                summaries = job._certify(job._shares[i], None)
            except Exception:  # the caller certifies this share again and raises
                conn.send((i, None, traceback.format_exc()))
                code = 1
                return
            conn.send((i, [summaries[k] for k in job._shares[i]], ""))
        conn.send(_DONE)
    except BaseException:  # a broken pipe (the caller is gone)
        code = code or 1
    finally:
        os._exit(code)
