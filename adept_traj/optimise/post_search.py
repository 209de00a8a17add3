"""The phases of :func:`~adept_traj.plan` after the search — the polish's local solves, the
front's certificates and the reported solution's exact certificate — on the problem's
worker count of processes (:class:`~adept_traj.optimise.forks.ProblemTasks`).

Every piece depends on its own arguments alone (a solve on its start, a certificate on its
member), so the order in which they run changes nothing: the results are those of the
serial phases, bit for bit (with one process they run in the serial order, in this
process). Before the first fork the main process makes the certifying problem
(:func:`~adept_traj.analysis.certifying_problem`) and, for a polish, imports
``scipy.optimize``, so that the processes inherit both. :class:`PostSearch` orders the
work so that both cores stay busy:

1. the polish (:meth:`PostSearch.polish`): the fastest member's solve first; each ε-step
   when it is sure to run (the budget rule of ``_PolishPlan.runs`` in
   :mod:`adept_traj.optimise.polish_solves`, once the evaluations of the solves before it
   are known), or before that when it would run even if every solve not yet finished spent
   twice :data:`~adept_traj.optimise.member_polish.MAX_EVALUATIONS` (a step that then does
   not run is discarded); meanwhile, the certificates of the members of the
   front before the polish (the polish's starts left out: a kept move dominates its
   start), in tasks of whole batches of dense samples, fewer as fewer are left
   (:func:`chunk_size`);
2. the front's certificates (:meth:`PostSearch.certificates`): the summaries already made
   (the polish's and those of step 1) are reused, the others made; the reported
   solution's exact certificate (:func:`~adept_traj.analysis.certify`) is started first,
   for the first member in the trade-off order whose summary is not known to fail, and
   made again at the end only if that member's certificate failed after all.

No member is certified twice; a summary made in step 1 for a member that the polish then
replaced is not used.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from adept_traj.analysis import (
    Certificate,
    MemberCertificate,
    batch_samples,
    certify,
    certify_members,
    certifying_problem,
    dense_samples,
    non_dominated,
)
from adept_traj.errors import InputShapeError
from adept_traj.optimise.forks import ProblemTasks
from adept_traj.optimise.loop import RunState
from adept_traj.optimise.member_polish import MAX_EVALUATIONS
from adept_traj.optimise.polish_solves import _polished, _solve, _Solved
from adept_traj.optimise.polish_step import _polish_plan, polish_mode
from adept_traj.problem import TrajectoryProblem, from_pymoo
from adept_traj.validation import as_batch, as_integer, as_scalar, check_type

__all__ = ["PostSearch", "chunk_size"]

#: Evaluations assumed of a solve not finished yet when deciding whether to start a step
#: before it is sure to run: twice a step's stopping point
#: (:data:`~adept_traj.optimise.member_polish.MAX_EVALUATIONS`; measured on paper fronts,
#: the fastest member's solve took 6, a step 9–33). A step started so that then does not
#: run is discarded (its process' time lost).
_LIKELY = 2 * MAX_EVALUATIONS

#: Most batches of dense samples per certificate task (:func:`chunk_size`).
_MOST_BATCHES = 16


def chunk_size(samples: Any, most: int, processes: int) -> int:
    """Members of the next certificate task, the head of a queue of members whose dense
    samples are ``samples`` (k,): all of them on one process; else whole batches of at most
    ``most`` samples, cut as :func:`~adept_traj.analysis.certify_members` cuts them (a
    member that does not fit starts a new batch), a quarter of each process' share of the
    batches left, from 1 to :data:`_MOST_BATCHES` batches. Whole batches waste less
    (200 MODE-front members in one process, CPU time against one call, 3 runs: tasks of 8
    members cut anywhere +9 to +19 %, tasks of whole batches −0.4 to +11 %: each batch's
    samples are computed together); small tasks at the end let the processes end
    together (a member is 6–9 ms of CPU)."""
    if processes <= 1:
        return len(samples)
    starts, total = [], most + 1
    for i, n in enumerate(samples):
        if total + n > most:
            starts.append(i)
            total = 0
        total += n
    take = min(max(-(-len(starts) // (4 * processes)), 1), _MOST_BATCHES)
    return starts[take] if take < len(starts) else len(samples)


class _Queue:
    """Members waiting for their certificate: (k, n_var) vectors and their dense samples."""

    def __init__(self, x: np.ndarray, rate_hz: float) -> None:
        self.x = x
        self.samples = [dense_samples(float(t), rate_hz) for t in x[:, 0]]

    def __len__(self) -> int:
        return len(self.x)

    def take(self, most: int, processes: int) -> np.ndarray:
        """The members of the next task (:func:`chunk_size`), out of the queue."""
        k = chunk_size(self.samples, most, processes)
        head, self.x, self.samples = self.x[:k], self.x[k:], self.samples[k:]
        return head


class PostSearch:
    """The phases of ``plan`` after the search on ``processes`` processes (module docstring).

    Parameters
    ----------
    problem: the :class:`~adept_traj.problem.TrajectoryProblem` of the run.
    rate_hz: the certificates' rate [Hz] (> 0).
    processes: processes at once (≥ 1; 1: everything in this process, in the serial order).
    speculate: certify the front's members while the polish runs (``plan`` does when every
        member is certified, ``max_certify=None``).
    """

    def __init__(self, problem: Any, rate_hz: float, processes: int, speculate: bool) -> None:
        check_type(problem, TrajectoryProblem, "problem")
        self.problem = problem
        self.rate_hz = as_scalar(rate_hz, "rate_hz", "[Hz]", minimum=0.0, strict=True)
        certifying_problem(problem)  # made here: the forked processes inherit it
        self._tasks = ProblemTasks(problem, processes)
        self._parallel = self._tasks.processes > 1
        self._speculate = speculate and self._parallel
        self._known: dict[bytes, MemberCertificate] = {}
        self._exact: dict[bytes, Certificate] = {}
        self._flight: dict[int, tuple[str, Any]] = {}  # ticket → (kind, what)
        self._most = batch_samples(certifying_problem(problem)[0])
        self._spare = _Queue(np.empty((0, problem.n_var)), rate_hz)  # certified meanwhile
        self._solved: dict[Any, _Solved] = {}  # "fastest" or a step's index → its solve

    # ------------------------------------------------------------------ the polish
    def polish(
        self, state: RunState, mode: str, weights: Any
    ) -> tuple[RunState, dict[bytes, MemberCertificate]]:
        """``state`` after the polish ``mode`` with the f_c ``weights`` (6,), and the
        summaries of the certificates it made by move (``x.tobytes()``): those of
        :func:`~adept_traj.optimise.polish_run`."""
        chosen = _polish_plan(self.problem, state, mode, weights)
        if polish_mode(mode) == "off":
            return state, {}
        if self._parallel:
            import scipy.optimize  # noqa: F401 (imported once here, not in each process)
        X = np.asarray(state.X, dtype=float)
        starts = set(chosen.members.tolist()) | {chosen.fastest}
        if self._speculate:
            rows = [k for k in _front_rows(state) if k not in starts]
            self._spare = _Queue(X[rows], self.rate_hz)
        n_run = None  # steps that run, once known
        while True:
            used = self._used(chosen)
            if chosen.fastest is None or "fastest" in self._solved:
                n_run = _steps_run(chosen, used)
            if n_run is not None and all(i in self._solved for i in range(n_run)):
                break
            self._fill_polish(chosen, X, used)
            self._record(*self._tasks.wait())
        certified: dict[bytes, MemberCertificate] = {}
        fastest = self._solved.get("fastest")
        steps = [self._solved[i] for i in range(n_run)]
        state = _polished(state, fastest, steps, certified)
        self._known.update(certified)
        return state, certified

    def _used(self, chosen: Any) -> list[int | None]:
        """The evaluations of the fastest member's solve (0: none), then of each step in
        order (``None``: not finished)."""
        fastest = self._solved.get("fastest")
        used: list[int | None] = [0 if chosen.fastest is None else None]
        if fastest is not None:
            used[0] = fastest.outcome.n_evaluations
        for i in range(len(chosen.members)):
            solved = self._solved.get(i)
            used.append(None if solved is None else solved.outcome.n_evaluations)
        return used

    def _fill_polish(self, chosen: Any, X: np.ndarray, used: list[int | None]) -> None:
        """Start tasks while a process is free: the fastest member's solve, the next step
        if it runs (or likely runs, module docstring), else a speculative certificate."""
        started = {what for kind, what in self._flight.values() if kind == "solve"}
        started |= set(self._solved)
        while self._tasks.running < self._tasks.processes:
            if chosen.fastest is not None and "fastest" not in started:
                self._submit("solve", "fastest", _solve, "fastest", X[chosen.fastest], None)
                started.add("fastest")
                continue
            i = len([k for k in started if k != "fastest"])
            sure = chosen.runs(used[: i + 1])
            likely = [_LIKELY if u is None else u for u in used[: i + 1]]
            if sure or (sure is None and self._parallel and chosen.runs(likely)):
                row = X[chosen.members[i]]
                self._submit("solve", i, _solve, "step", row, chosen.scale)
                started.add(i)
            elif len(self._spare):
                chunk = self._spare.take(self._most, self._tasks.processes)
                self._submit("certify", [r.tobytes() for r in chunk], _certify_task, chunk)
            else:
                return

    # ------------------------------------------------------------------ the certificates
    def certificates(
        self, x: np.ndarray, feasible: np.ndarray, order: np.ndarray, max_certify: int | None
    ) -> tuple[tuple[MemberCertificate | None, ...], Certificate, int]:
        """The front's summaries, the reported solution's exact certificate and its row.

        Parameters
        ----------
        x: (n, n_var) the front's decision vectors.
        feasible: (n,) the members the optimiser marked feasible (only those are
            certified).
        order: (n,) the trade-off order: the members are certified in it, at most
            ``max_certify`` of them (``None``: all); the reported solution is the first
            certified member in it, else ``order[0]``.

        Returns
        -------
        tuple
            ((n,) a :class:`~adept_traj.analysis.MemberCertificate` per certified member,
            ``None`` for the others; the exact :class:`~adept_traj.analysis.Certificate`
            of the reported solution; its row).
        """
        x = as_batch(x, "x", self.problem.n_var)
        if x.ndim != 2:
            raise InputShapeError(f"x must have shape (n, {self.problem.n_var}); got {x.shape}")
        feasible = np.asarray(feasible, dtype=bool)
        order = np.asarray(order)
        if feasible.shape != (len(x),) or sorted(order.tolist()) != list(range(len(x))):
            raise InputShapeError(
                f"feasible must have shape ({len(x)},) and order must be a permutation of "
                f"0…{len(x) - 1}; got shapes {feasible.shape} and {order.shape}"
            )
        if max_certify is not None:
            max_certify = as_integer(max_certify, "max_certify", minimum=1)
        candidates = [int(k) for k in order if feasible[k]][:max_certify]
        keys = [row.tobytes() for row in x]
        self._spare = _Queue(x[:0], self.rate_hz)
        flying = {key for kind, what in self._flight.values() if kind == "certify" for key in what}
        todo, seen = [], set()
        for k in candidates:
            if keys[k] not in self._known and keys[k] not in flying and keys[k] not in seen:
                todo.append(k)
                seen.add(keys[k])
        queue = _Queue(x[todo], self.rate_hz)
        guess = None
        while True:
            if guess is None and self._parallel:
                guess = self._guess(candidates, keys, order)
                self._submit("exact", keys[guess], _exact_task, x[guess])
            while len(queue) and self._tasks.running < self._tasks.processes:
                rows = queue.take(self._most, self._tasks.processes)
                self._submit("certify", [r.tobytes() for r in rows], _certify_task, rows)
            if not len(queue) and all(keys[k] in self._known for k in candidates):
                break
            self._record(*self._tasks.wait())
        passed = [k for k in candidates if self._known[keys[k]].feasible]
        index = passed[0] if passed else int(order[0])
        while keys[index] not in self._exact:
            if not any(
                kind == "exact" and what == keys[index] for kind, what in self._flight.values()
            ):
                self._submit("exact", keys[index], _exact_task, x[index])
            self._record(*self._tasks.wait())
        chosen = set(candidates)
        summaries = tuple(self._known[keys[k]] if k in chosen else None for k in range(len(x)))
        return summaries, self._exact[keys[index]], index

    def _guess(self, candidates: list[int], keys: list[bytes], order: np.ndarray) -> int:
        """The row likely reported: the first candidate whose summary is not known to fail
        (``order[0]`` when none is left)."""
        for k in candidates:
            summary = self._known.get(keys[k])
            if summary is None or summary.feasible:
                return k
        return int(order[0])

    # ------------------------------------------------------------------ tasks
    def _submit(self, kind: str, what: Any, fn: Any, *args: Any) -> None:
        """Start ``fn(problem, *args, rate_hz)``; ``(kind, what)`` says what it makes."""
        if kind == "solve":
            name = f"the polish's solve {what!r}"
        elif kind == "certify":
            name = f"the certificates of {len(what)} front member(s)"
        else:
            name = "the reported solution's exact certificate"
        ticket = self._tasks.submit(fn, *args, self.rate_hz, name=name)
        self._flight[ticket] = (kind, what)

    def _record(self, ticket: int, result: Any) -> None:
        """Keep what the task ``ticket`` made."""
        kind, what = self._flight.pop(ticket)
        if kind == "solve":
            self._solved[what] = result
        elif kind == "certify":
            self._known.update(zip(what, result))
        else:
            self._exact[what] = result

    def close(self) -> None:
        """Stop the processes (tasks still running, none of them needed, are dropped)."""
        self._tasks.close()

    def __enter__(self) -> PostSearch:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _steps_run(chosen: Any, used: list[int | None]) -> int | None:
    """How many steps run (``None``: not known yet)."""
    for i in range(len(chosen.members) + 1):
        runs = chosen.runs(used[: i + 1])
        if runs is None:
            return None
        if not runs:
            return i
    return len(chosen.members)


def _front_rows(state: RunState) -> list[int]:
    """The rows of the state's feasible non-dominated members (as ``plan`` takes them)."""
    feasible = np.flatnonzero(np.all(np.asarray(state.G) <= 0.0, axis=1))
    if len(feasible) == 0:
        return []
    objectives = from_pymoo(state.F)
    return sorted(int(k) for k in feasible[non_dominated(objectives[feasible])])


def _certify_task(problem: Any, x: np.ndarray, rate_hz: float) -> tuple[MemberCertificate, ...]:
    """Task: the summaries of the members ``x`` (k, n_var)."""
    return certify_members(problem, x, rate_hz=rate_hz)


def _exact_task(problem: Any, x: np.ndarray, rate_hz: float) -> Certificate:
    """Task: the exact certificate of ``x`` (n_var,)."""
    return certify(problem, x, rate_hz=rate_hz)
