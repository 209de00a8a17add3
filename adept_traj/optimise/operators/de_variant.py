r"""MODE's DE variation (pymoo's ``Variant``) with its mutation and repair on arrays.

pymoo's :class:`~pymoo.algorithms.soo.nonconvex.de.Variant` makes the trial vectors on
arrays (selection of the targets and difference vectors, the differential
:math:`v = x_{r_1} + F\,(x_{r_2} - x_{r_3})`, the bounds repair, the binomial crossover
with rate CR), then builds a ``Population`` of NP ``Individual`` objects, reads their X
back one member at a time for its polynomial mutation (drawn even at probability 0, as
MODE's is), writes the mutated ones, reads them again for the repair and writes them
again: about half of the variation's time at NP = 500.

:class:`ArrayVariant` takes the same steps in the same order with the same arguments —
the trial vectors by pymoo's own code, then ``mutation._do`` with the same draws
(:math:`u_k \le p_m` chooses the mutated rows), then ``repair._do`` — on one (NP, n_var)
array, and builds the ``Population`` once, at the end: the same trial vectors bit for bit
and the same generator state. It is used when the mutation and the repair are plain
pymoo operators (no ``vtype``, no operator-level repair); otherwise it is pymoo's
``Variant`` unchanged.

The mutation is :func:`~adept_traj.optimise.mutate` (MODE's polynomial mutation at
probability 0: its draws made, none computed). :meth:`ArrayVariant.offspring` returns the
trial vectors without building their members, and
:meth:`ArrayVariant.unrepaired_offspring` returns them before their kinematic time repair
with the repair's draws (:meth:`~adept_traj.optimise.KinematicTimeRepair.snaps`), so that
:class:`~adept_traj.optimise.FastEndSearch` repairs only the trial vectors it keeps, in
one call with its own children's kinematic times: the same numbers.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pymoo.algorithms.soo.nonconvex.de import Variant, de_differential
from pymoo.core.population import Population
from pymoo.core.repair import Repair
from pymoo.core.variable import get
from pymoo.operators.crossover.binx import mut_binomial
from pymoo.operators.crossover.expx import mut_exp
from pymoo.operators.repair.bounds_repair import repair_random_init
from pymoo.operators.selection.rnd import fast_fill_random
from pymoo.util.misc import where_is_what

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.operators.mutation import mutate
from adept_traj.optimise.operators.population import population_values
from adept_traj.optimise.operators.repair import KinematicTimeRepair

__all__ = ["ArrayVariant"]


class ArrayVariant(Variant):
    """pymoo's DE ``Variant`` with its mutation and repair on arrays (see the module
    docstring); the same parameters."""

    def do(
        self, problem: Any, pop: Population, n_offsprings: int, algorithm: Any = None, **kwargs
    ) -> Population:
        """``n_offsprings`` trial vectors from ``pop``, as pymoo's ``Variant.do`` makes them
        from ``algorithm.random_state``."""
        if not self._plain():
            return super().do(problem, pop, n_offsprings, algorithm=algorithm, **kwargs)
        off = Population.new(X=self._offspring(problem, pop, n_offsprings, algorithm, **kwargs))
        self.control.advance(off)
        return off

    def makes_arrays(self) -> bool:
        """Whether :meth:`offspring` applies: plain operators (see the module docstring)
        and a parameter control without parameters to set on the trial vectors (MODE's
        ``NoParameterControl``)."""
        return self._plain() and not self.control.params

    def offspring(
        self, problem: Any, pop: Population, n_offsprings: int, algorithm: Any = None, **kwargs
    ) -> np.ndarray:
        """The decision vectors (n_offsprings, n_var) of the trial vectors :meth:`do` makes
        (the same draws from ``algorithm.random_state``), without building their members.

        Raises
        ------
        ConfigurationError
            :meth:`makes_arrays` is false (use :meth:`do`).
        """
        if not self.makes_arrays():
            raise ConfigurationError(
                "ArrayVariant.offspring needs pymoo's plain operators and a parameter "
                "control without parameters; use do()"
            )
        return self._offspring(problem, pop, n_offsprings, algorithm, **kwargs)

    def unrepaired_offspring(
        self, problem: Any, pop: Population, n_offsprings: int, algorithm: Any = None, **kwargs
    ) -> tuple[np.ndarray, np.ndarray]:
        """The trial vectors of :meth:`offspring` before their kinematic time repair
        (n_offsprings, n_var) and the repair's draws (:meth:`KinematicTimeRepair.snaps
        <adept_traj.optimise.KinematicTimeRepair.snaps>`, (n_offsprings,) bool), made
        where the repair makes them: ``repair.repaired(problem, X, snapped)`` of any rows
        gives those rows of :meth:`offspring`, whose draws were the same.

        Raises
        ------
        ConfigurationError
            :meth:`makes_arrays` is false or the repair is not a
            :class:`~adept_traj.optimise.KinematicTimeRepair`.
        """
        if not (self.makes_arrays() and isinstance(self.repair, KinematicTimeRepair)):
            raise ConfigurationError(
                "ArrayVariant.unrepaired_offspring needs plain operators and the kinematic "
                "time repair; use offspring()"
            )
        trial = self._unrepaired(problem, pop, n_offsprings, algorithm)
        return trial, self.repair.snaps(len(trial), kwargs.get("random_state"))

    def _plain(self) -> bool:
        """Whether the mutation and the repair are pymoo's plain operators."""
        operators = (self.mutation, self.repair)
        return isinstance(self.repair, Repair) and all(
            getattr(op, "vtype", None) is None and getattr(op, "repair", None) is None
            for op in operators
        )

    def _offspring(
        self, problem: Any, pop: Population, n_offsprings: int, algorithm: Any, **kwargs
    ) -> np.ndarray:
        """:meth:`offspring` without the check."""
        trial = self._unrepaired(problem, pop, n_offsprings, algorithm)
        return np.asarray(self.repair._do(problem, trial, **kwargs))

    def _unrepaired(
        self, problem: Any, pop: Population, n_offsprings: int, algorithm: Any
    ) -> np.ndarray:
        """The trial vectors (n_offsprings, n_var) after the mutation, before the repair."""
        rng = algorithm.random_state
        self.control.tell(pop=pop)
        self.control.do(n_offsprings)
        trial = self._trial(problem, pop, n_offsprings, rng)
        return mutate(problem, self.mutation, trial, rng)

    def _trial(
        self, problem: Any, pop: Population, n_offsprings: int, rng: np.random.Generator
    ) -> np.ndarray:
        """The trial vectors (n_offsprings, n_var): pymoo's ``Variant.do`` up to its
        ``Population.new`` (pymoo's code; X read once per member)."""
        sel, n_diffs = get(self.selection, self.n_diffs, size=n_offsprings)
        if _all_same(sel) and _all_same(n_diffs):  # where_is_what's one group, at once
            H = {(sel[0], n_diffs[0]): np.arange(n_offsprings)}
        else:  # (index arrays: the same rows as pymoo's lists, without converting them)
            H = _as_arrays(where_is_what(zip(sel, n_diffs, strict=True)))
        F, CR, jitter = get(self.F, self.CR, self.jitter, size=n_offsprings)
        X = population_values(pop, "X")
        donor = np.full((n_offsprings, problem.n_var), np.nan)
        for (sel_type, n_diff), targets in H.items():
            n_matings, n_parents = len(targets), 1 + 2 * n_diff
            P = np.full([n_matings, n_parents], -1)
            itself = np.array(targets)[:, None]

            def best(n_matings: int = n_matings) -> np.ndarray:
                return rng.choice(np.where(pop.get("rank") == 0)[0], replace=True, size=n_matings)

            if sel_type == "rand":
                columns = range(n_parents)
            elif sel_type == "best":
                P[:, 0] = best()
                columns = range(1, n_parents)
            elif sel_type == "target-to-best":
                P[:, 0] = targets
                P[:, 1] = best()
                columns = range(2, n_parents)
            else:
                raise ConfigurationError(f"unknown DE selection {sel_type!r}")
            fast_fill_random(P, len(pop), columns=columns, Xp=itself, random_state=rng)
            XX = np.swapaxes(X[P], 0, 1)
            Xp = de_differential(XX, F[targets], jitter[targets], random_state=rng)
            if problem.has_bounds():
                Xp = repair_random_init(Xp, XX[0], *problem.bounds(), random_state=rng)
            donor[targets] = Xp
        trial = np.full((n_offsprings, problem.n_var), np.nan)
        kinds = get(self.crossover, size=n_offsprings)
        groups = (
            {kinds[0]: np.arange(n_offsprings)}
            if _all_same(kinds)
            else _as_arrays(where_is_what(kinds))
        )
        for name, K in groups.items():
            target, donors, rate = X[K], donor[K], CR[K]
            if name in ("bin", "exp"):
                mask = mut_binomial if name == "bin" else mut_exp
                M = mask(len(K), problem.n_var, rate, at_least_once=True, random_state=rng)
                trial_K = np.copy(target)
                trial_K[M] = donors[M]
            elif name == "line":
                w = rng.random((len(K), 1)) * rate[:, None]
                trial_K = target + w * (donors - target)
            elif name == "hypercube":
                w = rng.random((len(K), target.shape[1])) * rate[:, None]
                trial_K = target + w * (donors - target)
            else:
                raise ConfigurationError(f"unknown DE crossover {name!r}")
            trial[K] = trial_K
        return trial


def _all_same(values: Any) -> bool:
    """Whether the (n,) array ``values`` (n ≥ 1) holds one value n times: pymoo's
    ``where_is_what`` (a Python loop over the n values) then makes one group of every
    index, in order."""
    values = np.asarray(values)
    return values.ndim == 1 and len(values) > 0 and bool((values == values[0]).all())


def _as_arrays(groups: dict[Any, list[int]]) -> dict[Any, np.ndarray]:
    """``where_is_what``'s groups with their index lists as integer arrays."""
    return {key: np.asarray(index, dtype=np.intp) for key, index in groups.items()}
