"""Multi-objective algorithms: the paper's NSGA-II and MODE, and any pymoo algorithm by name.

:func:`make_algorithm` returns a configured pymoo algorithm and the settings actually used.

**NSGA-II** (pymoo's :class:`~pymoo.algorithms.moo.nsga2.NSGA2`, assembled from the same
parts without importing its module, which imports ``scipy.spatial``) with the paper's settings:
population 100, 100 generations, SBX crossover with probability 0.7 and η = 10, polynomial
mutation with η = 100 and "mutation probability" 0.01. The paper follows Deb's NSGA-II code,
where the real-parameter mutation probability is the probability of mutating **each
variable**; in pymoo that is ``PM(prob=1.0, prob_var=0.01)`` (every offspring goes through
the operator, each variable mutates with probability 0.01).

**MODE/rand/bin** (NP = 500, CR = 0.9, F = 0.5, 100 generations), assembled from pymoo's
parts: DE/rand/1/bin variation (pymoo's DE ``Variant`` with ``selection="rand"``,
``n_diffs=1``, binomial crossover, fixed F and CR — no self-adaptation, no extra
mutation) creates NP trial vectors from the current population; the NP parents and NP
trials are merged and the next population is chosen by non-dominated sorting and crowding
distance (pymoo's ``RankAndCrowding``, feasibility first; for both algorithms its
equivalent on arrays, :class:`~adept_traj.optimise.RankAndCrowdingSurvival`), the usual
(μ + λ) selection of multi-objective DE (Babu & Jehan 2003; Robič & Filipič's DEMO uses
the same survival).

Other names: ``nsga3``, ``unsga3``, ``smsemoa``, ``rvea`` (pymoo's MOEA/D handles no
constraints, so it is not offered)
(reference directions: Das–Dennis with 3 partitions for 6 objectives when needed).

Every algorithm starts from :class:`~adept_traj.optimise.RampSampling` unless another
``sampling`` is given, repairs travel times with
:class:`~adept_traj.optimise.KinematicTimeRepair`, makes 30 % of its offspring by
:class:`~adept_traj.optimise.FastEndSearch` (local search at the fast end of the front;
same number of evaluations; a third of those are fresh ramps from the sampling, at their
kinematic minimum time), and eliminates duplicates
(:class:`~adept_traj.optimise.BlockedDuplicateElimination`: pymoo's default decisions in
blocks of bounded memory). Randomness comes only from pymoo's
per-algorithm generator seeded by ``seed`` (see :mod:`adept_traj.optimise.planner`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from pymoo.algorithms.base.genetic import GeneticAlgorithm
from pymoo.core.algorithm import Algorithm
from pymoo.core.individual import Individual
from pymoo.core.population import Population
from pymoo.termination.default import DefaultMultiObjectiveTermination
from pymoo.util.display.multi import MultiObjectiveOutput

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.operators.de_variant import ArrayVariant
from adept_traj.optimise.operators.duplicates import BlockedDuplicateElimination
from adept_traj.optimise.operators.mating import ArrayMating
from adept_traj.optimise.operators.population import ArrayEvaluator, ranked_optimum
from adept_traj.optimise.operators.repair import KinematicTimeRepair
from adept_traj.optimise.operators.survival import RankAndCrowdingSurvival
from adept_traj.optimise.operators.tournament import binary_tournament
from adept_traj.optimise.search.algorithm_names import ALGORITHMS, PAPER_SETTINGS
from adept_traj.optimise.search.fast_end_search import FastEndSearch
from adept_traj.optimise.search.sampling import RampSampling, SeededInitialization
from adept_traj.validation import as_integer, as_scalar

__all__ = ["AlgorithmSettings", "make_algorithm"]


@dataclass(frozen=True)
class AlgorithmSettings:
    """What was run: ``name``, ``pop_size``, ``n_gen`` and the operator ``params``."""

    name: str
    pop_size: int
    n_gen: int
    params: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {"name": self.name, "pop_size": self.pop_size, "n_gen": self.n_gen, **self.params}


def make_algorithm(
    name: str = "nsga2",
    pop_size: int | None = None,
    n_gen: int | None = None,
    sampling: Any = None,
    repair: bool = True,
    fast_end: float = 0.3,
    starts: Any = None,
    **params: Any,
) -> tuple[Algorithm, AlgorithmSettings]:
    """A configured pymoo algorithm and its settings.

    Parameters
    ----------
    name:
        One of :data:`ALGORITHMS` (case-insensitive; ``"nsga-ii"`` and ``"mode/rand/bin"``
        are accepted).
    pop_size, n_gen:
        Population size (≥ 2) and generations (≥ 1); default: the paper's (NSGA-II 100 ×
        100, MODE 500 × 100) or 100 × 100 for the others. NSGA-III, U-NSGA-III and RVEA
        use 56 reference directions (Das–Dennis, 3 partitions, 6 objectives); give them a
        population of at least 56.
    sampling:
        Initial population (pymoo sampling, array or population); default
        :class:`~adept_traj.optimise.RampSampling`.
    repair:
        Apply :class:`~adept_traj.optimise.KinematicTimeRepair` to every candidate (default;
        ``False`` runs the plain algorithm).
    fast_end:
        Share of each generation's offspring made by
        :class:`~adept_traj.optimise.FastEndSearch` (local perturbations of the fastest
        feasible members and fresh ramps at their kinematic minimum time; default 0.3,
        ``0`` runs the algorithm's own mating only). The number of evaluations is unchanged.
    starts:
        (k, n_var) moves put, as given, into the initial population after the sampling's
        first member (:class:`~adept_traj.optimise.SeededInitialization`; e.g. the global
        stage's, :func:`~adept_traj.optimise.initial_starts`); their number is recorded as
        the setting ``initial_starts`` (default: none, and no such setting).
    params:
        Operator parameters overriding the paper's: NSGA-II ``crossover_prob``,
        ``crossover_eta``, ``mutation_prob_var``, ``mutation_eta``; MODE ``CR``, ``F``.

    Raises
    ------
    ConfigurationError
        Unknown name (the message lists the valid ones), bad sizes, unknown parameters.
    """
    key = str(name).lower().replace("-", "").replace("_", "")
    key = {"nsgaii": "nsga2", "mode/rand/bin": "mode", "nsgaiii": "nsga3"}.get(key, key)
    if key not in ALGORITHMS:
        raise ConfigurationError(f"unknown algorithm {name!r}; choose one of {list(ALGORITHMS)}")
    defaults = dict(PAPER_SETTINGS.get(key, {"pop_size": 100, "n_gen": 100}))
    default_pop, default_gens = defaults.pop("pop_size"), defaults.pop("n_gen")
    pop_size = default_pop if pop_size is None else pop_size
    n_gen = default_gens if n_gen is None else n_gen
    pop = as_integer(pop_size, "pop_size", minimum=2, error=ConfigurationError)
    gens = as_integer(n_gen, "n_gen", minimum=1, error=ConfigurationError)
    unknown = sorted(set(params) - set(defaults))
    if unknown:
        raise ConfigurationError(
            f"unknown parameter(s) {unknown} for {key}; accepted: {sorted(defaults)}"
        )
    settings = {
        k: as_scalar(v, f"{key} parameter {k}", minimum=0.0, error=ConfigurationError)
        for k, v in {**defaults, **params}.items()
    }
    sampling = RampSampling() if sampling is None else sampling
    fix = KinematicTimeRepair() if repair else None
    fast_end = as_scalar(fast_end, "fast_end", minimum=0.0, error=ConfigurationError)
    if fast_end > 1.0:
        raise ConfigurationError(f"fast_end must be a number in [0, 1]; got {fast_end!r}")
    algorithm = _build(key, pop, sampling, settings, fix)
    if starts is not None and len(starts):
        algorithm.initialization = SeededInitialization(algorithm.initialization, starts)
        settings["initial_starts"] = len(starts)
    if key == "nsga2":  # the same offspring, its rounds on arrays
        algorithm.mating = ArrayMating.of(algorithm.mating)
    if fast_end > 0 and hasattr(algorithm, "mating"):
        ramps = sampling if isinstance(sampling, RampSampling) else None
        algorithm.mating = FastEndSearch(algorithm.mating, fraction=fast_end, sampling=ramps)
    settings["kinematic_time_repair"] = bool(repair)
    mating = getattr(algorithm, "mating", None)
    search = mating if isinstance(mating, FastEndSearch) else None
    settings["fast_end"] = search.fraction if search else 0.0
    settings["fast_end_immigrants"] = search.immigrants if search else 0.0
    return algorithm, AlgorithmSettings(name=key, pop_size=pop, n_gen=gens, params=settings)


class _StampedGeneticAlgorithm(GeneticAlgorithm):
    """pymoo's genetic algorithm whose ``infill`` stamps each generation's offspring with
    ``n_gen`` and ``n_iter`` straight into each member's ``data``, what pymoo's
    ``Algorithm.infill`` does through ``Population.set`` (per member and key a
    ``hasattr`` that fails and a call of ``Individual.set``): the same values in the same
    members."""

    def infill(self) -> Population | None:
        if self.problem is None or not self.is_initialized:
            return super().infill()  # the first call: pymoo's initialisation
        infills = self._infill()
        if infills is None:
            return None
        members = list(infills)
        if all(type(ind) is Individual for ind in members):  # no attribute n_gen / n_iter
            n_iter = self.n_iter
            for ind in members:
                data = ind.data
                data["n_gen"] = n_iter
                data["n_iter"] = n_iter
        else:
            infills.set("n_gen", self.n_iter)
            infills.set("n_iter", self.n_iter)
        return infills


class _PaperNSGA2(_StampedGeneticAlgorithm):
    """pymoo's :class:`~pymoo.algorithms.moo.nsga2.NSGA2` as this module configures it:
    its genetic algorithm, binary tournament type, output, termination and ``opt`` (the
    rank-0 members, or the least infeasible one), without importing
    ``pymoo.algorithms.moo.nsga2``, whose module imports ``scipy.spatial`` (a noticeable
    part of the start of every run) for crowding measures this module does not use."""

    def __init__(self, **kwargs: Any) -> None:
        kwargs.setdefault("output", MultiObjectiveOutput())
        super().__init__(advance_after_initial_infill=True, **kwargs)
        self.termination = DefaultMultiObjectiveTermination()
        self.tournament_type = "comp_by_dom_and_crowding"

    def _set_optimum(self, **kwargs: Any) -> None:
        # one pass over the members: CV, its tolerance, whether the survival ranked it 0
        members = [
            (ind.CV[0], ind.config.get("cv_eps", 0.0), ind.data.get("rank") == 0)
            for ind in self.pop
        ]
        cv = np.array([m[0] for m in members])
        feasible = cv <= np.array([m[1] for m in members])
        if not feasible.any():  # pymoo's has_feasible, on arrays
            self.opt = self.pop[[np.argmin(cv)]]
        else:
            self.opt = self.pop[np.array([m[2] for m in members])]


class _PaperMODE(_StampedGeneticAlgorithm):
    """pymoo's genetic algorithm with the DE/rand/1/bin variation and rank-and-crowding
    survival (see the module docstring); its ``opt`` after every generation (pymoo's
    ``filter_optimum`` of the population, which reads three properties per member through
    ``Population.get`` and sorts the population again) is
    :func:`~adept_traj.optimise.ranked_optimum`: the feasible members the survival ranked
    0 — the same members in the same order. (NSGA-II keeps pymoo's own ``opt``: its rank-0
    members.)"""

    def _set_optimum(self) -> None:
        self.opt = ranked_optimum(self.pop)


def _build(key: str, pop: int, sampling: Any, s: dict[str, Any], repair: Any) -> Algorithm:
    # pymoo's eliminate_duplicates=True (the default of every algorithm here), its
    # decisions taken without a (pop, pop) distance matrix; pymoo's evaluator, its
    # bookkeeping on arrays.
    dup = {"eliminate_duplicates": BlockedDuplicateElimination(), "evaluator": ArrayEvaluator()}

    if key == "nsga2":
        from pymoo.operators.crossover.sbx import SBX
        from pymoo.operators.mutation.pm import PM
        from pymoo.operators.selection.tournament import TournamentSelection

        return _PaperNSGA2(
            pop_size=pop,
            sampling=sampling,
            selection=TournamentSelection(func_comp=binary_tournament),
            crossover=SBX(prob=s["crossover_prob"], eta=s["crossover_eta"]),
            mutation=PM(prob=1.0, prob_var=s["mutation_prob_var"], eta=s["mutation_eta"]),
            survival=RankAndCrowdingSurvival(),
            **dup,
            repair=repair,
        )
    if key == "mode":
        from pymoo.operators.control import NoParameterControl
        from pymoo.util.display.multi import MultiObjectiveOutput

        variant = ArrayVariant(
            selection="rand",
            n_diffs=1,
            F=s["F"],
            crossover="bin",
            CR=s["CR"],
            prob_mut=0.0,
            control=NoParameterControl,
            repair=repair,
        )
        return _PaperMODE(
            pop_size=pop,
            sampling=sampling,
            mating=variant,
            survival=RankAndCrowdingSurvival(),
            n_offsprings=pop,
            **dup,
            output=MultiObjectiveOutput(),
            advance_after_initial_infill=True,
            repair=repair,
        )
    from pymoo.util.ref_dirs import get_reference_directions

    def ref_dirs() -> Any:
        return get_reference_directions("das-dennis", 6, n_partitions=3)

    if key == "nsga3":
        from pymoo.algorithms.moo.nsga3 import NSGA3

        return NSGA3(ref_dirs=ref_dirs(), pop_size=pop, sampling=sampling, repair=repair, **dup)
    if key == "unsga3":
        from pymoo.algorithms.moo.unsga3 import UNSGA3

        return UNSGA3(ref_dirs=ref_dirs(), pop_size=pop, sampling=sampling, repair=repair, **dup)
    if key == "smsemoa":
        from pymoo.algorithms.moo.sms import SMSEMOA

        return SMSEMOA(pop_size=pop, sampling=sampling, repair=repair, **dup)
    from pymoo.algorithms.moo.rvea import RVEA

    return RVEA(ref_dirs=ref_dirs(), pop_size=pop, sampling=sampling, repair=repair, **dup)
