"""Planned moves certified again at the scene times they really run, in batches on Dask.

A plan of a cycle's move is certified at the start time it was planned for; run at another
scene time (a back-to-back pass, a later pass of a periodic cycle) it must be certified
again there (:func:`~adept_traj.certification.certify` with
``TrajectoryProblem(..., start_time=s)``). :class:`MoveCertifier` keeps every answer
(``(move, plan, start)`` → certified), takes a plan's own certificate where the start is
the one it was planned at (the task certified it there), and computes the others in
batches: :meth:`MoveCertifier.prefetch` splits the queries into Dask tasks
(:func:`certify_batch`) on the cycle's cluster, so that the command itself does not
certify one move after the other. :class:`RestCertifier` keeps the rest certificates
(:func:`~adept_traj.cycle.certify_rest`).

``adept-traj verify CYCLE_DIR`` re-certifies saved moves the same way
(:func:`check_moves`): each :class:`MoveCheck` a move at its start time with its own
problem settings and the robot's rests around it, in batches of Dask tasks
(:func:`check_batch`) when given a client, else one after the other in this process.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.certification import certify
from adept_traj.cycle.rest import RestCheck, certify_rest
from adept_traj.cycle.runner import run_tasks
from adept_traj.problem import ProblemSettings, TrajectoryProblem
from adept_traj.robot import Robot, RobotSource
from adept_traj.scene import Scene
from adept_traj.scene.robot_motion import load_robot

__all__ = [
    "BATCHES_PER_WORKER",
    "CHECKS_PER_TASK",
    "CertifyBatch",
    "CheckBatch",
    "MoveCertifier",
    "MoveCheck",
    "MoveVerdict",
    "PlannedMove",
    "RestCertifier",
    "certify_batch",
    "check_batch",
    "check_moves",
]

#: Dask tasks per worker a batch of queries is split into (unequal certificates balance).
BATCHES_PER_WORKER = 2

#: Moves per Dask task of :func:`check_moves` (small: the tasks balance over the workers).
CHECKS_PER_TASK = 8

#: A query: (move k, plan i, scene start time [s]).
Query = tuple[int, int, float]


@dataclass(frozen=True)
class PlannedMove:
    """A plan of a move: its ends ``start``, ``goal`` (nq,) [rad | m], the decision vector
    ``x`` (n,) of the member the cycle runs, the scene time ``planned_at`` [s] it was
    planned and certified at and whether it is ``certified`` there."""

    start: np.ndarray
    goal: np.ndarray
    x: np.ndarray
    planned_at: float
    certified: bool


@dataclass(frozen=True)
class CertifyBatch:
    """What a worker needs to certify moves at scene times (pickled to it): the robot,
    the scene, the certificate rate [Hz] and ``(start, goal, x, start_time)`` per move."""

    robot: RobotSource
    scene: Scene
    rate_hz: float
    moves: tuple[tuple[np.ndarray, np.ndarray, np.ndarray, float], ...]


def certify_batch(batch: CertifyBatch) -> list[bool]:
    """Whether each move of ``batch`` is certified started at its scene time (the body of
    a Dask task; also callable directly)."""
    robot = load_robot(batch.robot)
    out = []
    for start, goal, x, t0 in batch.moves:
        problem = TrajectoryProblem(robot, batch.scene, start, goal, workers=1, start_time=t0)
        try:
            out.append(bool(certify(problem, x, rate_hz=batch.rate_hz).certified))
        finally:
            problem.close()
    return out


class MoveCertifier:
    """``certifier(k, i, start)``: whether plan ``i`` of move ``k`` is certified started
    at the scene time ``start`` [s] (module doc).

    Parameters
    ----------
    robot, scene, rate_hz: the cycle's robot source, scene and certificate rate [Hz].
    plans: per move, its :class:`PlannedMove` plans.
    client: a ``distributed.Client`` the batches run on; ``None``: in this process.
    """

    def __init__(
        self,
        robot: RobotSource,
        scene: Scene,
        rate_hz: float,
        plans: Sequence[Sequence[PlannedMove]],
        client: Any = None,
    ) -> None:
        self._robot, self._scene, self._rate = robot, scene, float(rate_hz)
        self._plans = [list(row) for row in plans]
        self._client = client
        self._known: dict[Query, bool] = {}
        self.computed = 0  #: certificates computed (not taken from a plan's own)

    def add(self, k: int, plans: Sequence[PlannedMove]) -> None:
        """Append ``plans`` to move ``k``'s (their indices follow the plans it has): the
        answers known so far are kept."""
        self._plans[k].extend(plans)

    def __call__(self, k: int, i: int, start: float) -> bool:
        key = (k, i, start)
        if key not in self._known:
            self.prefetch([key])
        return self._known[key]

    def prefetch(self, queries: Iterable[Query]) -> None:
        """Certify every query not known yet, all at once (Dask tasks when a client is
        given: :data:`BATCHES_PER_WORKER` per worker)."""
        todo: list[Query] = []
        for key in dict.fromkeys(queries):
            if key in self._known:
                continue
            plan = self._plans[key[0]][key[1]]
            if key[2] == plan.planned_at:  # the task's own certificate, at that very time
                self._known[key] = plan.certified
            else:
                todo.append(key)
        if not todo:
            return
        moves = [self._move(key) for key in todo]
        if self._client is None:
            found = certify_batch(self._batch(moves))
        else:
            n = max(1, len(self._client.nthreads())) * BATCHES_PER_WORKER
            bounds = np.linspace(0, len(moves), min(n, len(moves)) + 1).astype(int)
            parts = [self._batch(moves[a:b]) for a, b in itertools.pairwise(bounds)]
            found = [ok for part in run_tasks(parts, certify_batch, client=self._client)
                     for ok in part]  # fmt: skip
        self.computed += len(todo)
        self._known.update(zip(todo, found))

    def _move(self, key: Query) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        plan = self._plans[key[0]][key[1]]
        return plan.start, plan.goal, plan.x, float(key[2])

    def _batch(self, moves: list[tuple[np.ndarray, np.ndarray, np.ndarray, float]]) -> Any:
        return CertifyBatch(self._robot, self._scene, self._rate, tuple(moves))


class RestCertifier:
    """``rests(k, start, duration)``: the :class:`~adept_traj.cycle.RestCheck` of the
    robot at rest at site ``k`` (``sites[k]``, (nq,) [rad | m]) over the scene times
    ``[start, start + duration]`` [s], each computed once
    (:func:`~adept_traj.cycle.certify_rest`)."""

    def __init__(
        self,
        robot: Any,
        scene: Scene,
        sites: Sequence[np.ndarray],
        *,
        settings: ProblemSettings,
        rate_hz: float,
    ) -> None:
        self._robot, self._scene, self._sites = robot, scene, list(sites)
        self._settings, self._rate = settings, float(rate_hz)
        self._known: dict[tuple[int, float, float], RestCheck] = {}

    def __call__(self, k: int, start: float, duration: float) -> RestCheck:
        key = (k, start, duration)
        if key not in self._known:
            self._known[key] = certify_rest(
                self._robot,
                self._scene,
                self._sites[k],
                start,
                duration,
                settings=self._settings,
                rate_hz=self._rate,
            )
        return self._known[key]


@dataclass(frozen=True)
class MoveCheck:
    """A saved move to certify again: the problem ``settings`` it runs with (its scene
    start time included), its ends ``start``, ``goal`` (nq,) [rad | m], the decision
    vector ``x`` (n,), the certificate rate [Hz], and the robot's rests to certify with
    it, ``(scene start [s], duration [s])``: ``before`` at ``start`` (its dwell) and
    ``after`` at ``goal`` (a final dwell; ``None``: none)."""

    settings: ProblemSettings
    start: np.ndarray
    goal: np.ndarray
    x: np.ndarray
    rate_hz: float
    before: tuple[float, float]
    after: tuple[float, float] | None = None


@dataclass(frozen=True)
class MoveVerdict:
    """What :func:`check_moves` found for a :class:`MoveCheck`: the move's certificate
    ``feasible`` and its ``min_distance`` [m], and whether each rest is ``certified``
    (``after``: ``None`` when not asked)."""

    feasible: bool
    min_distance: float
    before: bool
    after: bool | None


@dataclass(frozen=True)
class CheckBatch:
    """What a worker needs to run :class:`MoveCheck` s (pickled to it): the robot's
    source, the scene and the checks."""

    robot: RobotSource
    scene: Scene
    checks: tuple[MoveCheck, ...]


def _check(robot: Robot, scene: Scene, check: MoveCheck) -> MoveVerdict:
    problem = TrajectoryProblem(robot, scene, check.start, check.goal, check.settings)
    try:
        c = certify(problem, check.x, rate_hz=check.rate_hz)
    finally:
        problem.close()
    rest = {"settings": check.settings, "rate_hz": check.rate_hz}
    before = certify_rest(robot, scene, check.start, *check.before, **rest)
    after = None
    if check.after is not None:
        after = certify_rest(robot, scene, check.goal, *check.after, **rest).certified
    return MoveVerdict(bool(c.feasible), float(c.min_distance), bool(before.certified), after)


def check_batch(batch: CheckBatch) -> list[MoveVerdict]:
    """The verdict of each check of ``batch`` (the body of a Dask task)."""
    robot = load_robot(batch.robot)
    return [_check(robot, batch.scene, c) for c in batch.checks]


def check_moves(
    robot: RobotSource, scene: Scene, checks: Sequence[MoveCheck], client: Any = None
) -> list[MoveVerdict]:
    """The verdict of each of ``checks`` (robot and scene: the ones of all of them): in
    this process, or as Dask tasks of :data:`CHECKS_PER_TASK` checks on ``client`` (the
    same verdicts: each check is computed alone, from the same values)."""
    if client is None:
        loaded = robot.load()
        return [_check(loaded, scene, c) for c in checks]
    parts = [
        CheckBatch(robot, scene, tuple(checks[a : a + CHECKS_PER_TASK]))
        for a in range(0, len(checks), CHECKS_PER_TASK)
    ]
    return [v for part in run_tasks(parts, check_batch, client=client) for v in part]
