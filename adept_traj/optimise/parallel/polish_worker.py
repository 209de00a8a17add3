"""The polish after the search run by a helper process prepared while the search goes on:
:func:`start_polisher`, :class:`Polisher`.

The polish inside :func:`~adept_traj.plan` first imports ``scipy.optimize``, after the
search, on the command's critical path. :func:`start_polisher` forks a helper process (a
:class:`~adept_traj.process_pool.Worker`) from the caller once the problem exists; a
thread of the helper imports ``scipy.optimize`` and ``threadpoolctl`` and makes the
problem's certifying problem at the lowest priority (nice 19: it runs while a core idles
and never takes one from the search), and the helper then waits.
:meth:`Polisher.start` hands it the search's final population (its arrays and counts,
pickled: about 0.1 MB for the paper run); the helper polishes it as
:func:`~adept_traj.optimise.polish_run_with_certificates` does, on the problem it
inherited, while the caller certifies the front
(:mod:`adept_traj.optimise.parallel.early_certificates`), and
:meth:`Polisher.result` collects the polished population and the polish's certificates.
The same code on the same numbers: the population is the one the caller would make, bit
for bit (only the measured times differ).

The helper never outlives the caller (:mod:`adept_traj.process_pool`): it ignores Ctrl-C
(the caller stops it), :meth:`Polisher.cancel` (or leaving the ``with`` block) kills and
reaps it, and it ends with the caller. A helper that has not finished its imports when the
search ends (a machine too busy to lend it a core) is not used: :meth:`Polisher.start`
stops it and returns ``False``, and the caller polishes itself. An error of the helper is
raised in the caller by :meth:`Polisher.result` (the same exception, with the helper's
traceback as a note); a helper that dies without a word has its polish done again by the
caller (:meth:`Polisher.result` returns ``None``).
"""

from __future__ import annotations

import dataclasses
from functools import partial
from typing import Any

from adept_traj.certification import MemberCertificate, certifying_problem
from adept_traj.errors import ConfigurationError, WorkerDiedError
from adept_traj.optimise.local.multi_start import made_relaxed_optima
from adept_traj.optimise.local.polish_modes import polish_mode, polish_run_with_certificates
from adept_traj.optimise.parallel.early_certificates import EarlyCertificates, feasible_front
from adept_traj.optimise.search.run_records import RunState
from adept_traj.problem import TrajectoryProblem
from adept_traj.process_helper import Helper
from adept_traj.process_pool import Channel, Worker, can_fork
from adept_traj.validation import as_scalar, check_type

__all__ = [
    "Polisher",
    "check_polisher",
    "polish_with_certificates",
    "start_polisher",
]


def start_polisher(problem: TrajectoryProblem) -> Polisher:
    """Fork the helper that will polish ``problem``'s search result (see the module).

    Call it once the problem exists; pass it to :func:`~adept_traj.plan` as
    ``polisher``. Without ``fork`` (not Linux) no helper starts: the caller polishes.

    Raises
    ------
    InvalidInputError
        ``problem`` is not a :class:`~adept_traj.problem.TrajectoryProblem`.
    """
    check_type(problem, TrajectoryProblem, "problem")
    return Polisher(problem)


def check_polisher(polisher: Any, problem: TrajectoryProblem) -> None:
    """Refuse a ``polisher`` that is neither ``None`` nor a :class:`Polisher` started for
    ``problem`` (the same object: the problem is frozen, so its helper polishes the problem
    as it is). A polisher already used, or stopped, is accepted: it is not ready, and the
    caller polishes itself (a helper serves one search).

    Raises
    ------
    InvalidInputError
        ``polisher`` of another type.
    ConfigurationError
        A polisher started for another problem.
    """
    if polisher is None:
        return
    check_type(polisher, Polisher, "polisher")
    if polisher.problem is not problem:
        raise ConfigurationError(
            "the polisher was started for another problem (start_polisher(problem) with "
            "the problem given to plan)"
        )


def polish_with_certificates(
    problem: TrajectoryProblem,
    state: RunState,
    rate_hz: float,
    mode: str,
    weights: Any,
    *,
    early: EarlyCertificates,
    polisher: Polisher | None = None,
) -> tuple[RunState, dict[int, MemberCertificate]]:
    """:func:`~adept_traj.optimise.polish_run` of the search's final ``state`` and the
    front's certificates made meanwhile.

    The polish runs in ``polisher``'s helper when it is given and ready (the caller then
    certifies ``early``'s members with its process), else in the caller (``early``'s
    process certifying meanwhile; the caller then certifies the shares left of the
    members still in the front).

    Parameters
    ----------
    problem: the problem of the search (``polisher``'s problem, if given).
    state: the search's final population.
    rate_hz, mode, weights: the certificates' rate [Hz], the polish mode and the six
        weights of f_c, as for :func:`~adept_traj.optimise.polish_run`.
    early: the certificates started before the polish
        (:func:`~adept_traj.optimise.start_early_certificates`).
    polisher: the helper of :func:`start_polisher` (``None``: the caller polishes).

    Returns
    -------
    tuple
        (the polished state, the summaries of the certificates made by the polish and by
        ``early`` by the move's row in the polished population): the same with or without
        the helper.
    """
    check_polisher(polisher, problem)
    handed = polisher is not None and polish_mode(mode) != "off"
    if handed and polisher.start(state, rate_hz, mode, weights):
        # meanwhile, on this process and early's: every member of the front before the
        # polish; one whose certificate fails is raised only if it is still on the front
        failed: list[int] = []
        ahead = early.finish(failed=failed)
        done = polisher.result()
        if done is None:  # the helper died without a word: polished here
            done = polish_run_with_certificates(problem, state, rate_hz, mode, weights)
        if failed:
            polished = done[0]
            front = feasible_front(polished.F, polished.G, weights)
            ahead.update(early.certify_again(failed, {int(k) for k in front}))
        return done[0], {**ahead, **done[1]}
    polished, certified = polish_run_with_certificates(problem, state, rate_hz, mode, weights)
    front = feasible_front(polished.F, polished.G, weights)
    return polished, {**early.finish({int(k) for k in front}), **certified}


class Polisher(Helper):
    """The helper process forked by :func:`start_polisher`; a context manager that stops
    it when the block is left.

    Attributes
    ----------
    problem : TrajectoryProblem
        The problem it polishes for (the caller's object).
    pid : int or None
        The helper's process id (``None`` without one, or once it is reaped).
    """

    def __init__(self, problem: TrajectoryProblem) -> None:
        self.problem = problem
        self._order: dict[str, Any] | None = None
        self._worker: Worker | None = None
        if can_fork():
            self._worker = Worker(
                _helper,
                problem,
                prepare=partial(_prepare, problem),
                note="raised while polishing in the polisher's worker process",
            )

    def start(self, state: RunState, rate_hz: float, mode: str, weights: Any) -> bool:
        """Hand the search's final ``state`` to the helper, if it is ready, and return at
        once; the arguments are those of
        :func:`~adept_traj.optimise.polish_run_with_certificates` (``rate_hz`` [Hz] of the
        certificates, the polish ``mode``, the six ``weights`` of f_c).

        Returns
        -------
        ``True`` if the helper polishes (collect with :meth:`result`); ``False`` if it was
        not ready (it is then stopped) or is gone: the caller polishes itself.
        """
        check_type(state, RunState, "state")
        rate = as_scalar(rate_hz, "rate_hz", "[Hz]", minimum=0.0, strict=True)
        mode = polish_mode(mode)
        if self._order is not None:
            raise ConfigurationError("the polisher polishes one population; it has one already")
        if self._worker is None or not self.ready():
            if self._worker is not None:
                self._worker.kill()  # reaped by cancel: a helper at nice 19 may end slowly
            return False
        arrays = dataclasses.replace(state, history=[], fronts=[])  # what the polish reads
        try:
            # what the caller made since the fork and the polish reuses: the relaxed optima
            made = made_relaxed_optima(self.problem)
            self._worker.send(arrays, rate, mode, weights, made)
        except WorkerDiedError:  # died meanwhile: the caller polishes
            self.cancel()
            return False
        self._order = {"history": state.history, "fronts": state.fronts}
        return True

    def result(self) -> tuple[RunState, dict[int, MemberCertificate]] | None:
        """Wait for the polish handed over by :meth:`start` and reap the helper.

        Returns
        -------
        tuple or None
            (the polished state, the polish's certificates by the move's row in the
            polished population), as the polish in the caller makes them; ``None`` if the
            helper died without a word: the caller polishes itself.

        Raises
        ------
        Exception
            The helper's error, with its traceback as a note.
        """
        if self._order is None or self._worker is None:
            raise ConfigurationError("Polisher.result needs a successful Polisher.start first")
        order, self._order = self._order, None
        try:
            state, certified = self._worker.recv()
        except WorkerDiedError:  # the helper ended without a word (killed)
            return None
        finally:
            self._worker.close()
        return dataclasses.replace(state, **order), certified


def _prepare(problem: TrajectoryProblem) -> None:
    """What the polish needs before its first solve (run at the lowest priority)."""
    import scipy.optimize  # noqa: F401  (the polish's SLSQP)
    import threadpoolctl  # noqa: F401  (its BLAS limit)

    certifying_problem(problem)


def _helper(channel: Channel, problem: TrajectoryProblem) -> None:
    """The helper process, once prepared: wait for the order, polish, send the result."""
    state, rate_hz, mode, weights, made = channel.recv()
    for key, value in made.items():  # kept on the helper's copy of the problem, as made
        problem.derived(key, lambda _problem, value=value: value)
    channel.send(polish_run_with_certificates(problem, state, rate_hz, mode, weights))
