r"""The time-optimal mode and the polish's fastest basins: multi-start certified local
solves (:func:`time_optimal`, :func:`fastest_of_basins`) and the global stage
(:func:`global_stage`).

:func:`time_optimal` runs the certified local solver
(:func:`~adept_traj.optimise.refine_minimum_time`) from several starts — the straight move
and the ``n_starts − 1`` kinematically fastest of 8 × (``n_starts`` − 1) ramps of
:class:`~adept_traj.optimise.RampSampling` drawn from a generator seeded by ``seed``, each
at its kinematic minimum T — and returns every outcome. When none of them ends certified
within :data:`~adept_traj.optimise.GLOBAL_GAP` of the kinematic lower bound (the straight
move blocked, as on the detour scene), it adds the refinements of the global stage's
starts (:func:`global_stage`; ``docs/engine.md``). Everything is
deterministic: the same problem and seed give the same vectors.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.local.basins import basin_starts
from adept_traj.optimise.local.refinement import (
    Refinement,
    refine_starts,
    screen_starts,
)
from adept_traj.optimise.local.timed_starts import timed_roadmap_starts
from adept_traj.optimise.local.via_points import (
    GLOBAL_GAP,
    GLOBAL_SEED,
    near_lower_bound,
    via_point_starts,
)
from adept_traj.optimise.operators.repair import KINEMATIC_SLACK, kinematic_time
from adept_traj.optimise.search.sampling import RampSampling
from adept_traj.process_pool import can_fork
from adept_traj.validation import as_integer, as_scalar
from adept_traj.work_ahead import WorkAhead

__all__ = [
    "MAX_BASINS",
    "RELAXED_GAP",
    "STRETCHES",
    "GlobalStage",
    "fastest_of_basins",
    "global_stage",
    "global_starts",
    "initial_starts",
    "made_relaxed_optima",
    "relaxed_optimum",
    "relaxed_problem",
    "time_optimal",
]


#: Ramps drawn per ramp start of :func:`time_optimal` (the fastest ones are used).
_RAMPS_PER_START = 8

#: Basins refined by :func:`polish_fastest` (the fastest move of each of the fastest
#: basins), and most starts of the global stage.
MAX_BASINS = 3

#: Factors of the fixed-obstacle optimum's T at which :func:`global_starts` offers it.
STRETCHES = (1.0, 1.1, 1.25)

#: The relaxed problem's own search (:func:`relaxed_optimum`: a start and a floor of the
#: problem's, not its answer) ends at a certified move within this fraction of T_lb
#: (the problem's: :data:`~adept_traj.optimise.GLOBAL_GAP`; why: ``docs/engine.md``).
RELAXED_GAP = 0.05

#: The key under which a problem keeps its relaxed problem and optima
#: (:meth:`~adept_traj.problem.TrajectoryProblem.derived`).
_RELAXED_KEY = "optimise.local.relaxed"


def time_optimal(
    problem: Any,
    seed: int = 1,
    n_starts: int = 4,
    *,
    rate_hz: float = 1000.0,
    processes: int | None = None,
    gap: float = GLOBAL_GAP,
    **options: Any,
) -> list[Refinement]:
    """Refinements (:func:`~adept_traj.optimise.refine_minimum_time`) from the straight
    move and the ``n_starts − 1`` kinematically fastest of ``8 (n_starts − 1)`` seeded
    ramps (each at its kinematic minimum T; the evaluator-feasible ones first) and, unless
    one of them ends **certified** within :data:`~adept_traj.optimise.GLOBAL_GAP` of the
    kinematic lower bound, from the global stage's starts (:func:`global_stage`): the
    relaxed problem's optimum, always screened once the stage runs, then — while none is
    near the bound or the relaxed floor — the timed trees' starts, the other ramps and the
    via points (:func:`~adept_traj.optimise.via_point_starts`). Every start screened
    (:func:`~adept_traj.optimise.screen_starts`, ``processes`` at once), then, unless one
    is near, the fastest screened moves refined to the end
    (:func:`~adept_traj.optimise.refine_starts`).

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    seed:
        Seed of the ramps' generator (≥ 0); the global stage's is
        :data:`~adept_traj.optimise.GLOBAL_SEED`.
    n_starts:
        Number of starts (≥ 1).
    rate_hz:
        Rate [Hz] of the certificates (> 0).
    processes:
        Refinements run at once (≥ 1; default: the problem's ``workers``).
    gap:
        A certified move within this fraction (> 0, default ``GLOBAL_GAP``) of T_lb or of
        the floor ends the search (the relaxed problem's own: :data:`RELAXED_GAP`).
    options:
        ``max_boxes`` of the screening (:func:`~adept_traj.optimise.screen_starts`).
    """
    seed = as_integer(seed, "seed", minimum=0, error=ConfigurationError)
    n_starts = as_integer(n_starts, "n_starts", minimum=1, error=ConfigurationError)
    gap = as_scalar(gap, "gap", minimum=0.0, strict=True, error=ConfigurationError)
    near = functools.partial(near_lower_bound, problem, gap=gap)
    starts = _feasible_first(problem, _starts(problem, seed, n_starts))
    options = {"rate_hz": rate_hz, "processes": processes, **options}
    ahead = _relaxed_ahead(problem, rate_hz, processes)  # beside the first start
    # Without moving obstacles the global stage has no relaxed or timed starts: the ramps
    # come next whatever the first outcome, and are screened beside it (the same outcomes).
    first = 1 if problem.scene.moving else max(1, int(_wanted(problem, processes)))
    try:
        screened = screen_starts(problem, starts[:first], stop=near, **options)
        known = None if ahead is None or near(screened) else ahead.result()
    finally:
        if ahead is not None:
            ahead.cancel()  # not needed when the first start is near the bound
    stage = None
    if not near(screened):  # the relaxed problem's optimum before the other starts
        stage = global_stage(problem, n_starts=n_starts, rate_hz=rate_hz,
                             processes=processes, known=known)  # fmt: skip
        screened += _screen_stage(problem, stage, screened, starts[first:], gap=gap, **options)
    if near_lower_bound(problem, screened, floor=stage.floor if stage else 0.0, gap=gap):
        return screened
    return screened + refine_starts(problem, screened, rate_hz=rate_hz, processes=processes)


@dataclass(frozen=True)
class GlobalStage:
    """The starts of the global stage (:func:`global_stage`).

    Attributes
    ----------
    relaxed:
        (k, n_var) the relaxed problem's fastest certified move at :data:`STRETCHES` × its
        T (k = 0 without moving obstacles, or when the relaxed problem has none).
    floor:
        The relaxed problem's fastest certified T [s] (0 when there is none): the floor of
        :func:`~adept_traj.optimise.near_lower_bound`.
    make_timed, make_via:
        Make :attr:`timed` and :attr:`via` when they are first asked for (a search that
        ends at the relaxed problem's starts never grows the trees nor draws the vias).
    """

    relaxed: np.ndarray
    floor: float
    make_timed: Callable[[], np.ndarray] = dataclasses.field(repr=False, compare=False)
    make_via: Callable[[], np.ndarray] = dataclasses.field(repr=False, compare=False)

    @functools.cached_property
    def timed(self) -> np.ndarray:
        """(j, n_var) the timed trees' starts
        (:func:`~adept_traj.optimise.timed_roadmap_starts`, guided by the relaxed problem's
        fastest move: its way at the moving obstacles' phases); j = 0 without moving
        obstacles."""
        return self.make_timed()

    @functools.cached_property
    def via(self) -> np.ndarray:
        """(m, n_var) the via-point moves and ramps of
        :func:`~adept_traj.optimise.via_point_starts`."""
        return self.make_via()

    @property
    def starts(self) -> np.ndarray:
        """(k + j + m, n_var) every start: the relaxed problem's, the timed, the via-point."""
        return np.concatenate([self.relaxed, self.timed, self.via])


def global_starts(problem: Any, *, n_starts: int = 3, rate_hz: float = 1000.0) -> np.ndarray:
    """(k, n_var) the starts of :func:`global_stage`, the relaxed problem's first."""
    return global_stage(problem, n_starts=n_starts, rate_hz=rate_hz).starts


def global_stage(problem: Any, *, n_starts: int = 3, rate_hz: float = 1000.0,
                 processes: int | None = None,
                 known: tuple[np.ndarray, float] | None = None) -> GlobalStage:  # fmt: skip
    """The global stage's starts and the floor [s] of
    :func:`~adept_traj.optimise.near_lower_bound`. Where obstacles move: the fastest
    certified move of the problem **without its moving obstacles** (its own
    :func:`time_optimal`, which has no moving obstacle to recurse on) at :data:`STRETCHES` ×
    its T — the same path passing the moving obstacles at other phases —, and its T as the
    floor (that relaxed problem's feasible set contains this one's); then
    :func:`~adept_traj.optimise.via_point_starts` with
    :data:`~adept_traj.optimise.GLOBAL_SEED` (a function of the problem alone). Without
    moving obstacles, or when the relaxed problem has no certified move, the floor is 0.
    The relaxed problem's refinements run ``processes`` at once (default: the problem's
    ``workers``; ``known``: :func:`relaxed_optimum`'s answer, already computed); the via
    points are drawn when first asked for.

    Measured figures on the detour scene: ``docs/detour-scene.md``."""
    shares = _wanted(problem, processes)
    via = functools.partial(via_point_starts, problem, GLOBAL_SEED, n_starts=n_starts,
                            processes=shares)  # fmt: skip
    relaxed, floor = relaxed_optimum(problem, rate_hz=rate_hz,
                                     processes=processes) if known is None else known  # fmt: skip
    timed = functools.partial(np.empty, (0, problem.n_var))
    if problem.scene.moving:
        guide = relaxed[:1] if len(relaxed) else None
        timed = functools.partial(
            timed_roadmap_starts, problem, GLOBAL_SEED, guides=guide, n_starts=n_starts
        )
    return GlobalStage(relaxed=relaxed, floor=floor, make_timed=timed, make_via=via)


def relaxed_optimum(problem: Any, *, n_starts: int = MAX_BASINS, rate_hz: float = 1000.0,
                    processes: int | None = None) -> tuple[np.ndarray, float]:  # fmt: skip
    """The relaxed part of :func:`global_stage`: (k, n_var) the fastest certified move of
    the problem without its moving obstacles at :data:`STRETCHES` × its T, and that T [s]
    (the floor); (0, n_var) and 0 without moving obstacles or without a certified move.
    Made once per problem, ``n_starts`` and ``rate_hz`` and kept on the problem
    (:meth:`~adept_traj.problem.TrajectoryProblem.derived`; ``processes`` changes only
    how fast: the same moves)."""
    key = f"{_RELAXED_KEY}:{n_starts}:{float(rate_hz)!r}"
    make = functools.partial(_relaxed_optimum, n_starts=n_starts, rate_hz=rate_hz,
                             processes=processes)  # fmt: skip
    return problem.derived(key, make)


def _relaxed_optimum(
    problem: Any, *, n_starts: int, rate_hz: float, processes: int | None
) -> tuple[np.ndarray, float]:
    """:func:`relaxed_optimum`, made."""
    relaxed, floor, scene = np.empty((0, problem.n_var)), 0.0, problem.scene
    if scene.moving:
        fixed = relaxed_problem(problem)
        processes = _wanted(problem, processes)
        outcomes = time_optimal(fixed, GLOBAL_SEED, n_starts, rate_hz=rate_hz,
                                processes=processes, gap=RELAXED_GAP)  # fmt: skip
        done = [o for o in outcomes if o.certified]
        if done:
            best = min(done, key=lambda o: float(o.x[0])).x
            stretched = np.repeat(best[None], len(STRETCHES), axis=0)
            stretched[:, 0] = np.minimum(best[0] * np.asarray(STRETCHES), problem.xu[0])
            relaxed, floor = stretched, float(best[0])
    return relaxed, floor


def made_relaxed_optima(problem: Any) -> dict[str, tuple[np.ndarray, float]]:
    """The relaxed optima :func:`relaxed_optimum` has made and kept on ``problem``, by
    their key, to hand to a process forked before they were made (it keeps them with
    :meth:`~adept_traj.problem.TrajectoryProblem.derived`)."""
    return problem.derived_made(f"{_RELAXED_KEY}:")


def relaxed_problem(problem: Any) -> Any:
    """The problem without its moving obstacles, evaluating in one process (made once and
    kept on the problem; its feasible set contains the problem's)."""
    scene = problem.scene
    still = dataclasses.replace(scene, obstacles=scene.fixed)
    return problem.derived(f"{_RELAXED_KEY}.problem", lambda p: p.replace(scene=still, workers=1))


def initial_starts(
    problem: Any, *, rate_hz: float = 1000.0, processes: int | None = None
) -> np.ndarray:
    """(k, n_var) the global stage's starts for the evolutionary search's initial
    population: where obstacles move, the relaxed problem's fastest certified move at
    :data:`STRETCHES` × its T (:func:`relaxed_optimum` with :data:`MAX_BASINS` starts,
    as the polish asks for it: made once for both) when its T lies more than
    :data:`~adept_traj.optimise.GLOBAL_GAP` above the kinematic lower bound; (0, n_var)
    otherwise. A relaxed optimum within that gap of the bound takes the way of the
    straight move, which the sampling's straight move and ramps already cover (measured on
    the paper scene: every seed finds that basin), and the search is left as it was."""
    none = np.empty((0, problem.n_var))
    if not problem.scene.moving:
        return none
    relaxed, floor = relaxed_optimum(
        problem, n_starts=MAX_BASINS, rate_hz=rate_hz, processes=processes
    )
    if floor <= problem.lower_bound.T_min * (1.0 + GLOBAL_GAP):
        return none
    return relaxed


def _relaxed_ahead(problem: Any, rate_hz: float, processes: int | None) -> WorkAhead | None:
    """:func:`relaxed_optimum` computed ahead, at the lowest priority, while the caller
    screens its first start (:class:`~adept_traj.work_ahead.WorkAhead`: it takes no core
    from the screening, and is raised when waited for); ``None`` without moving obstacles,
    with one process, or without ``fork``."""
    n_proc = _wanted(problem, processes)
    if not problem.scene.moving or n_proc <= 1 or not can_fork():
        return None
    make = functools.partial(relaxed_optimum, problem, rate_hz=rate_hz, processes=processes)
    return WorkAhead(make, note="raised in the relaxed problem's worker")


def fastest_of_basins(
    problem: Any,
    x: Any,
    *,
    rate_hz: float = 1000.0,
    max_basins: int = MAX_BASINS,
) -> tuple[list[Refinement], np.ndarray]:
    """The refinements (:func:`~adept_traj.optimise.refine_minimum_time`) of the fastest move
    of each of the ``max_basins`` fastest basins (:func:`~adept_traj.optimise.basin_starts`)
    of the moves ``x`` (n, n_var) and, unless one of them comes within
    :data:`~adept_traj.optimise.GLOBAL_GAP` of the kinematic lower bound (no other basin
    can then be faster by more than that), of the global stage's starts
    (:func:`~adept_traj.optimise.global_starts`): every start screened
    (:func:`~adept_traj.optimise.screen_starts`, fastest basin first, stopping once one is
    near the bound), then the fastest screened moves refined to the end
    (:func:`~adept_traj.optimise.refine_starts`): the screened and the full refinements,
    in that order, and (k,) int the rows of ``x`` that the first k of them started from.

    Parameters
    ----------
    problem: the :class:`~adept_traj.problem.TrajectoryProblem`.
    x: (n, n_var) moves (e.g. the feasible members of a final population).
    rate_hz: rate [Hz] of the certificates.
    max_basins: most basins refined (≥ 1), and most via-point starts.
    """
    xs = np.asarray(x, dtype=float).reshape(-1, problem.n_var)
    max_basins = as_integer(max_basins, "max_basins", minimum=1, error=ConfigurationError)
    near = functools.partial(near_lower_bound, problem)
    screened: list[Refinement] = []
    rows = np.empty(0, dtype=int)
    if len(xs):
        rows = basin_starts(problem, xs, max_basins)
        screened = screen_starts(problem, xs[rows], rate_hz=rate_hz, stop=near)
    rows = rows[: len(screened)]  # the screening stops once one is near the bound
    stage = None
    if not near(screened):
        stage = global_stage(problem, n_starts=max_basins, rate_hz=rate_hz)
        screened += _screen_stage(problem, stage, screened, xs[:0], rate_hz=rate_hz)
    if near_lower_bound(problem, screened, floor=stage.floor if stage else 0.0):
        return screened, rows  # no other basin can be faster by more than GLOBAL_GAP
    return screened + refine_starts(problem, screened, rate_hz=rate_hz), rows


def _screen_stage(
    problem: Any,
    stage: GlobalStage,
    screened: list[Refinement],
    others: np.ndarray,
    gap: float = GLOBAL_GAP,
    **options: Any,
) -> list[Refinement]:
    """The screenings of the global stage's starts after ``screened``: the relaxed
    optimum always — a move within GLOBAL_GAP of the floor may be a worse basin's local
    optimum (measured on detour, NSGA-II seed 2: 1.1110 s, where the stretched relaxed
    optimum screens to 1.0991 s); its stop sees the relaxed outcomes only —, then, while
    no move is near the bound or the floor, the timed trees', ``others`` (n, n_var) and
    the via points, each made only when reached."""
    near = functools.partial(near_lower_bound, problem, floor=stage.floor, gap=gap)
    more = screen_starts(problem, stage.relaxed, stop=near, **options)
    for starts in (lambda: stage.timed, lambda: others, lambda: stage.via):
        if not near(screened + more):
            more += screen_starts(problem, starts(), stop=near, **options)
    return more


def _wanted(problem: Any, processes: int | None) -> Any:
    """The processes asked for: ``processes``, or by default the problem's ``workers``."""
    return problem.settings.workers if processes is None else processes


def _feasible_first(problem: Any, starts: np.ndarray) -> np.ndarray:
    """``starts`` (k, n_var) with the evaluator-feasible ones first (each group in its
    order): a refinement from inside the constraints is cheap and seldom fails."""
    ok = np.all(problem.evaluate_batch(starts).constraints <= 0.0, axis=1) if len(starts) else []
    return np.concatenate([starts[ok], starts[~np.asarray(ok, dtype=bool)]])


def _starts(problem: Any, seed: int, n_starts: int) -> np.ndarray:
    """(n_starts, n_var): the straight move, then the ``n_starts − 1`` ramps of smallest
    kinematic minimum T among ``_RAMPS_PER_START`` × as many seeded ramps, each at its
    kinematic minimum T (SLSQP from a slow detour rarely converges in a few dozen
    iterations: ``docs/engine.md``)."""
    traj = problem.trajectory
    straight = traj.straight_line(problem.xl[0])[None]
    n_ramps = _RAMPS_PER_START * (n_starts - 1)
    ramps = RampSampling().ramps(problem, n_ramps, np.random.default_rng(seed))
    x = np.concatenate([straight, ramps])
    t_kin = kinematic_time(problem, x)
    order = np.concatenate([[0], 1 + np.argsort(t_kin[1:], kind="stable")])[:n_starts]
    x, t_kin = x[order], t_kin[order]
    x[:, 0] = np.clip(t_kin * (1.0 + KINEMATIC_SLACK), problem.xl[0], problem.xu[0])
    return x
