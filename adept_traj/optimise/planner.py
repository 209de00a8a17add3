"""``plan()``: run an algorithm on a trajectory problem and return a verified result.

Steps:

1. :func:`~adept_traj.optimise.make_algorithm` (paper settings by default) and
   :func:`~adept_traj.optimise.optimise` (seeded; optional checkpoints and exact resume).
2. **Front**: the feasible non-dominated members of the final population. If no member is
   feasible, the least-infeasible ones (the 10 with the smallest total violation) with a
   warning — never an empty result.
3. **Best trade-off**: :func:`~adept_traj.analysis.best_tradeoff` (f_c and F_avg ranks,
   paper weights by default) on the front (its order is the certification order).
4. **Certificates**: every member the optimiser marked feasible is re-verified on a
   ≥ 1 kHz grid with the continuous-time distance guarantee
   (:func:`~adept_traj.analysis.certify`); ``front.feasible[i]`` is then that verdict
   (a member that fails keeps its row, not feasible) and ``front.n_certified`` counts the
   certified members. The reported solution is the first certified member in the
   trade-off order (the best trade-off when it passes), with its exact certificate; if
   none passes, the trade-off choice with its failing certificate. A front of
   least-infeasible members thus costs one certificate.
5. **Polish** (default; before steps 2–4; :func:`~adept_traj.optimise.polish_run`): the
   fastest feasible member of the final population is polished by SLSQP
   (:func:`~adept_traj.optimise.polish_fastest`), then (``polish="front"``, the default)
   the best trade-off and a few members spread over the front by an ε-constraint step
   (:func:`~adept_traj.optimise.polish_members`); a polished move that passes its
   certificate joins the population, so it replaces the members it dominates in the
   front; its certificate's summary is that member's in step 4 (no move is certified
   twice). ``algorithm="time-optimal"`` replaces step 1 and this one by
   :func:`~adept_traj.optimise.time_optimal_run` (multi-start SLSQP), or, with
   ``weights``, by :func:`~adept_traj.optimise.weighted_run` (the weighted-sum mode: the
   certified member of least :math:`f_w` is reported instead of the trade-off choice).
6. **Metrics**: SSM (spread of the front), RNI (non-dominated share of the final
   population), OO and AE (from measured times), HV of the front normalised on its own
   objective bounds (reference point 1.1; see ``docs/decision-and-metrics.md``).
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.analysis.decision import PAPER_WEIGHTS, best_tradeoff, objective_weights
from adept_traj.analysis.indicators import (
    DEFAULT_HV_REFERENCE,
    non_dominated,
    normalised_hypervolume,
    objective_bounds,
)
from adept_traj.analysis.paper_measures import (
    algorithm_effort,
    optimizer_overhead,
    ratio_non_dominated,
    spread,
)
from adept_traj.analysis.weighted_sum import WeightedSum
from adept_traj.certification.certificate import Certificate, certify
from adept_traj.certification.member_certificate import MemberCertificate
from adept_traj.errors import ConfigurationError
from adept_traj.optimise.local.multi_start import initial_starts
from adept_traj.optimise.local.polish_modes import TIME_OPTIMAL, polish_mode, time_optimal_run
from adept_traj.optimise.local.weighted_move import weighted_run
from adept_traj.optimise.parallel.early_certificates import feasible_front, start_early_certificates
from adept_traj.optimise.parallel.front_certificates import certify_front_members
from adept_traj.optimise.parallel.polish_worker import (
    Polisher,
    check_polisher,
    polish_with_certificates,
)
from adept_traj.optimise.search.run_records import GenerationInfo
from adept_traj.problem import TrajectoryProblem, from_pymoo
from adept_traj.results import (
    NO_FEASIBLE_WARNING,
    BestSolution,
    Front,
    GenerationRecord,
    Metrics,
    PlanningResult,
    Timing,
)
from adept_traj.robot import JointLimits
from adept_traj.validation import as_integer

__all__ = ["plan", "warn_missing_limits"]

#: Size of the fallback front when nothing is feasible.
_LEAST_INFEASIBLE = 10


#: Problem settings left out of a checkpoint's fingerprint at these values.
_UNSET = {"search_buffer": 0.0, "self_collision": False, "disabled_pairs": ()}


def _fingerprint(problem: TrajectoryProblem, settings: Any, seed: int) -> dict[str, Any]:
    """What a checkpoint must match to be resumed by this run."""
    return json.loads(
        json.dumps(
            {
                "start": problem.start.tolist(),
                "goal": problem.goal.tolist(),
                # workers change nothing in the results; a zero search_buffer, self-collision
                # off and no disabled pairs are left out so that checkpoints written before
                # those fields existed still resume.
                "problem_settings": {
                    k: v
                    for k, v in problem.settings.__dict__.items()
                    if k != "workers" and not (k in _UNSET and v == _UNSET[k])
                },
                "scene": problem.scene.to_dict(),
                "robot": problem.robot.name,
                "algorithm": settings.to_dict(),
                "seed": seed,
            },
            default=str,
        )
    )


#: Most generations whose hypervolume is recorded in the history (evenly spread + last).
_HV_GENERATIONS = 25


def _history(state: Any, final_front: np.ndarray | None) -> list[GenerationRecord]:
    """Generation records with the hypervolume of each generation's feasible front, on the
    bounds of the final front and of every generation's front (reference point 1.1), for
    up to ``_HV_GENERATIONS`` generations of this session (a resumed run has none for the
    generations before)."""
    n = len(state.history)
    offset = n - len(state.fronts)  # generations restored from a checkpoint
    chosen = set()
    if final_front is not None and len(state.fronts):
        k = len(state.fronts)
        chosen = {int(i) for i in np.linspace(0, k - 1, min(k, _HV_GENERATIONS)).round()}
        positive = [from_pymoo(F) for F in state.fronts if len(F)]
        lo, hi = objective_bounds(final_front, *positive)  # a one-point front would collapse
    records = []
    for i, h in enumerate(state.history):
        hv = None
        j = i - offset
        if j in chosen and len(state.fronts[j]):
            hv = normalised_hypervolume(from_pymoo(state.fronts[j]), lo, hi)
        records.append(
            GenerationRecord(
                generation=h["generation"],
                n_evaluations=h["n_evaluations"],
                n_feasible=h["n_feasible"],
                hypervolume=hv,
            )
        )
    return records


def _certify_front(
    problem: TrajectoryProblem,
    front: Front,
    order: np.ndarray,
    rate_hz: float,
    max_certify: int | None,
    known: Mapping[int, MemberCertificate] | None = None,
) -> tuple[MemberCertificate | None, ...]:
    """(n,) the summary of each member's dense certificate with the continuous guarantee
    (:func:`~adept_traj.analysis.certify_members`, on the problem's workers:
    :func:`~adept_traj.optimise.certify_front_members`), ``None`` for a member not certified.

    Only members the optimiser marked feasible are certified (a member that violates a
    constraint at the optimiser's samples fails the dense check as well), in the trade-off
    ``order`` (n,), at most ``max_certify`` of them (``None``: all). A member whose index
    is in ``known`` (the polish's summaries, made the same way) keeps that summary instead
    of being certified again.
    """
    candidates = [int(k) for k in order if front.feasible[k]]
    if max_certify is not None:
        candidates = candidates[:max_certify]
    known = {} if known is None else known
    reused = {k: known[k] for k in candidates if k in known}
    todo = [k for k in candidates if k not in reused]
    out = list(certify_front_members(problem, front.x, todo, rate_hz=rate_hz))
    for k, summary in reused.items():
        out[k] = summary
    return tuple(out)


def _certified_choice(
    problem: TrajectoryProblem, front: Front, order: np.ndarray, rate_hz: float
) -> tuple[Certificate, int]:
    """(certificate, front index) of the reported solution: the first certified member in
    the trade-off ``order`` (n,), or the best trade-off ``order[0]`` with its failing
    certificate when none is; the certificate computes every distance exactly."""
    index = next((int(k) for k in order if front.feasible[k]), int(order[0]))
    return certify(problem, front.x[index], rate_hz=rate_hz), index


def warn_missing_limits(robot: str, limits: JointLimits) -> None:
    """Warn (a :class:`UserWarning`, shown once per robot and place by Python's default
    filter) when joints have no acceleration or jerk limit: those constraints are then off,
    and the certificate says "no limit" for them (``docs/your-robot.md``: how to set them
    in a parameter file)."""
    missing = []
    for kind in ("acceleration", "jerk"):
        free = [n for n, v in zip(limits.names, getattr(limits, kind)) if not np.isfinite(v)]
        if free:
            missing.append(f"no {kind} limit for joint(s) {', '.join(free)}")
    if missing:
        warnings.warn(
            f"robot '{robot}': {'; '.join(missing)} (URDFs have none): those constraints are "
            "off; give 'acceleration' and 'jerk' per [[joint]] in a parameter file "
            "(docs/your-robot.md)",
            UserWarning,
            stacklevel=3,
        )


def plan(
    problem: TrajectoryProblem,
    algorithm: str = "nsga2",
    seed: int = 1,
    *,
    pop_size: int | None = None,
    n_gen: int | None = None,
    weights: Sequence[float] | None = None,
    checkpoint: str | Path | None = None,
    resume: bool = False,
    progress: Callable[[GenerationInfo], None] | None = None,
    rate_hz: float = 1000.0,
    max_certify: int | None = None,
    polish: bool | str = True,
    polisher: Polisher | None = None,
    **params: Any,
) -> PlanningResult:
    """Plan with ``algorithm`` (``"nsga2"``, ``"mode"`` or another pymoo name), or find one
    fastest move by gradient-based local search (``"time-optimal"``).

    Parameters
    ----------
    problem: the :class:`~adept_traj.problem.TrajectoryProblem`.
    algorithm, pop_size, n_gen, params: see :func:`~adept_traj.optimise.make_algorithm`.
    seed: random seed (the same seed gives the same front).
    weights: the six weights of f_c (``None``, the default: the paper's,
        :data:`~adept_traj.analysis.PAPER_WEIGHTS`); with ``"time-optimal"``, given
        weights turn the mode into the weighted-sum mode (below).
    checkpoint, resume: checkpoint folder and whether to resume from it.
    progress: called after every generation.
    rate_hz: rate of the dense verification (≥ 1000 Hz recommended).
    max_certify: most front members certified (in the trade-off order, among those the
        optimiser marked feasible; ``None``: all). A member not certified is reported with
        ``feasible = False``.
    polish: the polish after the evolutionary search
        (:data:`~adept_traj.optimise.POLISH_MODES`): ``"off"`` (or False), ``"fastest"``
        (the fastest feasible member by SLSQP), ``"front"`` (or True, the default: also
        the best trade-off and :data:`~adept_traj.optimise.SPREAD_MEMBERS` members spread
        over the front, by an ε-constraint step) or ``"all"`` (every front member); its
        time and evaluations are counted in ``result.timing``, its name is recorded as
        ``result.algorithm_settings["polish"]``. Ignored by ``"time-optimal"``.
    polisher: a helper process of :func:`~adept_traj.optimise.start_polisher` (started
        for ``problem`` before the search) that polishes while this process certifies
        the front (``None``: the polish runs here); the result is the same.

    With ``algorithm="time-optimal"`` the parameters ``pop_size``, ``n_gen``,
    ``checkpoint``, ``resume`` and ``progress`` are not used; ``params`` may give
    ``n_starts`` and ``max_iter`` (:func:`~adept_traj.optimise.time_optimal_run`).
    With ``weights`` it minimises instead the weighted sum :math:`f_w` of the six objectives
    with the fixed normalisation of :func:`~adept_traj.analysis.weighted_sum`, from the
    minimum-T moves (:func:`~adept_traj.optimise.weighted_run`; ``params`` may also give
    ``max_evaluations``), and reports the certified front member of lowest :math:`f_w`
    (the weights and scales in ``result.algorithm_settings["weighted_sum"]``).

    Returns
    -------
    PlanningResult
        Never empty; ``result.feasible`` is the dense certificate's verdict, and
        ``result.front.feasible[i]`` that of member ``i`` with the continuous guarantee
        (``result.front.n_certified`` of them).
    """
    seed = as_integer(seed, "seed", minimum=0, error=ConfigurationError)
    if max_certify is not None:
        max_certify = as_integer(max_certify, "max_certify", minimum=1, error=ConfigurationError)
    polish = polish_mode(polish)
    check_polisher(polisher, problem)
    weighted = None  # the weighted sum of the weighted-sum mode
    if weights is not None:
        objective_weights(weights, 6)  # bad weights refused before any long work
    warn_missing_limits(problem.robot.name, problem.robot.limits)
    n_searched: int | None = 0  # population rows made by the search (the rest by the local solver)
    polished: dict[int, MemberCertificate] = {}  # the polish's certificates, by population row
    if algorithm == TIME_OPTIMAL and weights is not None:
        state, settings_dict = weighted_run(problem, seed, weights, **params)
        weighted = WeightedSum.from_settings(settings_dict)
        name = TIME_OPTIMAL
    elif algorithm == TIME_OPTIMAL:
        state, settings_dict = time_optimal_run(problem, seed, **params)
        name = TIME_OPTIMAL
    else:
        # the evolutionary search, and pymoo with it, imported only for it
        from adept_traj.optimise.search.algorithms import make_algorithm
        from adept_traj.optimise.search.loop import optimise
        from adept_traj.optimise.search.sampling import check_population_memory

        alg, settings = make_algorithm(algorithm, pop_size, n_gen, **params)
        check_population_memory(settings.pop_size, settings.n_gen)  # before any allocation
        if not {"sampling", "starts"} & params.keys():  # the global stage's starts (#24),
            params = {**params, "starts": initial_starts(problem, rate_hz=rate_hz)}  # resumed too
            alg, settings = make_algorithm(algorithm, pop_size, n_gen, **params)
        state = optimise(
            problem,
            alg,
            settings.n_gen,
            seed,
            checkpoint=checkpoint,
            resume=resume,
            fingerprint=_fingerprint(problem, settings, seed),
            progress=progress,
        )
        settings_dict = {**settings.to_dict(), "polish": polish}
        name = settings.name
        n_searched = len(state.X) if polish != "off" else None
        # the front's certificates made meanwhile (benchmarks/results/notebook.md)
        rows = feasible_front(state.F, state.G, _weights(weights))
        rows = rows if polish != "off" and max_certify is None else []
        fork = problem.settings.workers > 1  # one worker: certified in this process
        with start_early_certificates(problem, state.X, rows, rate_hz=rate_hz, fork=fork) as early:
            state, polished = polish_with_certificates(
                problem, state, rate_hz, polish, _weights(weights), early=early, polisher=polisher
            )
    # The final population's values as the run computed them (z4 back to positive).
    objectives = from_pymoo(state.F)
    constraints = np.asarray(state.G, dtype=float)
    feasible = np.all(constraints <= 0.0, axis=1)
    if feasible.any():
        rows = np.flatnonzero(feasible)
        rows = rows[non_dominated(objectives[rows])]
        warning = None
    else:
        violation = np.maximum(constraints, 0.0).sum(axis=1)
        rows = np.argsort(violation, kind="stable")[:_LEAST_INFEASIBLE]
        warning = NO_FEASIBLE_WARNING
    rows = np.unique(rows)  # deterministic order
    front = Front(
        x=state.X[rows],
        objectives=objectives[rows],
        constraints=constraints[rows],
        feasible=feasible[rows],
    )
    choice = best_tradeoff(front.objectives, _weights(weights))
    order = choice.order if weighted is None else weighted.order(front.objectives)
    known = {k: polished[r] for k, r in enumerate(rows.tolist()) if r in polished}
    summaries = _certify_front(problem, front, order, rate_hz, max_certify, known)
    certified = np.array([s is not None and s.feasible for s in summaries], dtype=bool)
    front = Front(
        x=front.x,
        objectives=front.objectives,
        constraints=front.constraints,
        feasible=certified,
        n_certified=int(certified.sum()),
        certificates=summaries,
    )
    certificate, index = _certified_choice(problem, front, order, rate_hz)
    lo, hi = objective_bounds(front.objectives)
    metrics = Metrics(
        ssm=spread(front.objectives) if len(rows) > 1 else None,
        rni=ratio_non_dominated(objectives),
        oo=optimizer_overhead(state.total_s, state.evaluation_s),
        ae=algorithm_effort(state.total_s, state.n_evaluations),
        hv=normalised_hypervolume(front.objectives, lo, hi) if feasible.any() else None,
        hv_reference_point=np.full(6, DEFAULT_HV_REFERENCE) if feasible.any() else None,
        **_t_best(front, rows, n_searched, name),
    )
    return PlanningResult.from_problem(
        problem,
        algorithm=name,
        algorithm_settings=settings_dict,
        seed=seed,
        front=front,
        best=BestSolution(
            index=index, f_c=float(choice.f_c[index]), f_avg=float(choice.F_avg[index])
        ),
        certificate=certificate,
        timing=Timing(
            total_s=state.total_s,
            evaluation_s=state.evaluation_s,
            n_evaluations=state.n_evaluations,
            n_generations=state.n_generations,
        ),
        metrics=metrics,
        history=_history(state, front.objectives if feasible.any() else None),
        warning=warning,
    )


def _weights(weights: Sequence[float] | None) -> Sequence[float]:
    """The weights of f_c: the given ones, else the paper's."""
    return PAPER_WEIGHTS if weights is None else weights


def _t_best(front: Front, rows: np.ndarray, n_searched: int | None, name: str) -> dict[str, Any]:
    """``t_best`` [s] and ``t_best_source`` of :class:`~adept_traj.results.Metrics`: the z1
    of the front's fastest certified member when the local solver made it (its population
    row ``rows[k]`` ≥ ``n_searched``; ``n_searched`` None: no polish), else nothing."""
    ok = np.flatnonzero(front.feasible)
    if n_searched is None or len(ok) == 0:
        return {}
    k = ok[np.argmin(front.objectives[ok, 0])]
    if rows[k] < n_searched:
        return {}
    source = "time-optimal" if name == TIME_OPTIMAL else "polish"
    return {"t_best": float(front.objectives[k, 0]), "t_best_source": source}
