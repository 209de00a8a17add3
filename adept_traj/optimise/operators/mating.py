r"""pymoo's mating (selection, crossover, mutation, repair, duplicate elimination) on arrays.

pymoo's :class:`~pymoo.core.mating.Mating` makes each generation's offspring in rounds:
select parents, cross them over, mutate, repair, drop the duplicates (within the round,
of the parents, of the offspring so far), and repeat for the missing ones until there are
``n_offsprings`` (NSGA-II at the paper's settings: about 2.8 rounds a generation, since
crossover probability 0.7 and a per-variable mutation probability 0.01 copy many parents
unchanged). Every step builds a ``Population`` of ``Individual`` objects and reads or
writes their ``X`` one member at a time.

:class:`ArrayMating` takes the same steps on one (n, n_var) array of decision vectors and
builds the ``Population`` once, at the end: the same operators' array hooks
(``crossover._do``, ``mutation._do``, ``repair._do``,
:meth:`~adept_traj.optimise.BlockedDuplicateElimination.duplicates`) called with the same
arguments in the same order, the same draws from the algorithm's generator, hence the same
offspring bit for bit. Per round, with :math:`n_m = \lceil n_{rem} / n_{off}\rceil`
matings of parents :math:`I` (n_m, n_parents) chosen by the algorithm's selection:

.. math::
    X' = \begin{cases} \mathrm{crossover}(X_I) & u_k < p_c \\ X_{I_k}\ \text{(copied)} &
    \text{else} \end{cases}, \qquad
    X'' = \begin{cases} \mathrm{mutation}(X') & u'_k \le p_m \\ X' & \text{else}
    \end{cases}, \qquad X''' = \mathrm{repair}(X'') ,

then the rows of :math:`X'''` that duplicate an earlier row, a parent or an earlier
offspring are dropped. It is used when the operators are pymoo's plain ones (no
``vtype``, no operator-level repair) and the duplicate elimination is
:class:`~adept_traj.optimise.BlockedDuplicateElimination` or none; otherwise, and without
a random generator, it is pymoo's mating unchanged.

Within a generation's rounds (the same decisions and draws): NSGA-II's binary tournaments
read the members' CV, F, rank and crowding once
(:func:`~adept_traj.optimise.select_parents`), SBX is computed for the crossed matings
only (:func:`~adept_traj.optimise.sbx_children`), the polynomial mutation for the rows it
keeps (:func:`~adept_traj.optimise.mutate`), and a round's three duplicate tests (within
the round, against the parents, against the offspring so far, each a test of the row
alone) are one pass over ``[parents; offspring; round]``. :meth:`ArrayMating.offspring`
returns the children's decision vectors without building their members (for
:class:`~adept_traj.optimise.FastEndSearch`, which builds the generation's members once).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from pymoo.core.duplicate import NoDuplicateElimination
from pymoo.core.mating import Mating
from pymoo.core.population import Population
from pymoo.core.repair import Repair
from pymoo.core.variable import get
from pymoo.operators.crossover.sbx import SBX, SimulatedBinaryCrossover
from pymoo.operators.selection.tournament import TournamentSelection

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.operators.crossover import sbx_children
from adept_traj.optimise.operators.duplicates import BlockedDuplicateElimination
from adept_traj.optimise.operators.mutation import mutate
from adept_traj.optimise.operators.population import population_values
from adept_traj.optimise.operators.tournament import (
    TournamentArrays,
    binary_tournament,
    select_parents,
)

__all__ = ["ArrayMating"]


class ArrayMating(Mating):
    """pymoo's :class:`~pymoo.core.mating.Mating` with its rounds on arrays (see the module
    docstring). Parameters as pymoo's; :meth:`of` copies an existing mating's."""

    @classmethod
    def of(cls, mating: Mating) -> ArrayMating:
        """The array form of ``mating`` (its selection, crossover, mutation, repair,
        duplicate elimination and most rounds, shared, not copied)."""
        return cls(
            mating.selection,
            mating.crossover,
            mating.mutation,
            repair=mating.repair,
            eliminate_duplicates=mating.eliminate_duplicates,
            n_max_iterations=mating.n_max_iterations,
        )

    def do(
        self,
        problem: Any,
        pop: Population,
        n_offsprings: int,
        random_state: Any = None,
        n_max_iterations: int | None = None,
        **kwargs: Any,
    ) -> Population:
        """``n_offsprings`` children of ``pop`` (fewer if ``n_max_iterations`` rounds leave
        only duplicates), as pymoo's ``Mating.do`` makes them from the same generator."""
        if random_state is None or not self._plain():
            return super().do(problem, pop, n_offsprings, random_state, n_max_iterations, **kwargs)
        X = self.offspring(
            problem,
            pop,
            n_offsprings,
            random_state=random_state,
            n_max_iterations=n_max_iterations,
            **kwargs,
        )
        return Population.new(X=X)

    def makes_arrays(self) -> bool:
        """Whether :meth:`offspring` applies (pymoo's plain operators, see the module
        docstring)."""
        return self._plain()

    def offspring(
        self,
        problem: Any,
        pop: Population,
        n_offsprings: int,
        *,
        random_state: Any,
        n_max_iterations: int | None = None,
        **kwargs: Any,
    ) -> np.ndarray:
        """The decision vectors (n, n_var), n ≤ ``n_offsprings``, of the children :meth:`do`
        makes from the generator ``random_state`` (the same draws, a required keyword),
        without building their members.

        Raises
        ------
        ConfigurationError
            No ``random_state``, or operators that are not pymoo's plain ones
            (:meth:`makes_arrays` is false).
        """
        if random_state is None or not self._plain():
            raise ConfigurationError(
                "ArrayMating.offspring needs a random_state and pymoo's plain operators "
                "(no vtype, no operator-level repair); use do()"
            )
        rounds = self.n_max_iterations if n_max_iterations is None else n_max_iterations
        parents = population_values(pop, "X")
        # NSGA-II's tournaments read the members' values once for all rounds
        arrays = TournamentArrays.of(pop) if self._array_selection(kwargs) else None
        off = np.empty((0, problem.n_var))
        n_rounds = 0
        while len(off) < n_offsprings:
            n_remaining = n_offsprings - len(off)
            X = self._round(problem, pop, parents, arrays, n_remaining, random_state, **kwargs)
            X = self._unique(X, parents, off)
            off = np.concatenate([off, X[:n_remaining]])
            n_rounds += 1
            if n_rounds >= rounds:
                break
        return off

    def _plain(self) -> bool:
        """Whether the array rounds apply (pymoo's plain operators; see the module doc)."""
        operators = (self.selection, self.crossover, self.mutation, self.repair)
        return (
            all(getattr(op, "vtype", None) is None for op in operators)
            and all(getattr(op, "repair", None) is None for op in operators)
            and isinstance(self.repair, Repair)
            and isinstance(
                self.eliminate_duplicates, BlockedDuplicateElimination | NoDuplicateElimination
            )
        )

    def _array_selection(self, kwargs: dict[str, Any]) -> bool:
        """Whether the selection is NSGA-II's binary tournament (pymoo's
        ``TournamentSelection`` of :func:`~adept_traj.optimise.binary_tournament`, pressure
        2), which :func:`~adept_traj.optimise.select_parents` makes on arrays."""
        sel = self.selection
        return (
            isinstance(sel, TournamentSelection)
            and sel.func_comp is binary_tournament
            and sel.pressure == 2
            and "algorithm" in kwargs
        )

    def _round(
        self,
        problem: Any,
        pop: Population,
        parents: np.ndarray,
        arrays: TournamentArrays | None,
        n_remaining: int,
        rng: np.random.Generator,
        **kwargs: Any,
    ) -> np.ndarray:
        """One round of pymoo's ``Mating._do`` and repair: (n_matings·n_off, n_var)."""
        cross = self.crossover
        n_matings = math.ceil(n_remaining / cross.n_offsprings)
        if arrays is not None:
            options = {k: v for k, v in kwargs.items() if k != "algorithm"}
            index = select_parents(
                pop, arrays, n_matings, cross.n_parents, kwargs["algorithm"], rng, **options
            )
        else:
            index = self.selection(
                problem,
                pop,
                n_matings,
                n_parents=cross.n_parents,
                to_pop=False,
                random_state=rng,
                **kwargs,
            )
        X = np.swapaxes(parents[np.asarray(index)], 0, 1)  # (n_parents, n_matings, n_var)
        X = self._crossover(problem, X, rng, **kwargs)
        X = mutate(problem, self.mutation, X, rng)
        return np.asarray(self.repair._do(problem, X, random_state=rng, **kwargs))

    def _crossover(
        self, problem: Any, X: np.ndarray, rng: np.random.Generator, **kwargs: Any
    ) -> np.ndarray:
        """pymoo's ``Crossover.do`` of the parents ``X`` (n_parents, n_matings, n_var):
        the children (n_off·n_matings, n_var)."""
        cross = self.crossover
        n_parents, n_off = cross.n_parents, cross.n_offsprings
        n_matings = X.shape[1]
        Xp = np.empty((n_off, n_matings, X.shape[-1]), dtype=X.dtype)
        crossed = rng.random(n_matings) < get(cross.prob, size=n_matings)
        if np.any(crossed) and type(cross) in (SBX, SimulatedBinaryCrossover) and n_off == 2:
            Xp[:, crossed] = sbx_children(problem, cross, X, crossed, rng)  # the same bits
        elif np.any(crossed):
            Xp[:, crossed] = cross._do(problem, X, random_state=rng, **kwargs)[:, crossed]
        if n_off == n_parents:  # the children of an uncrossed mating: copies of its parents
            Xp[:, ~crossed] = X[:, ~crossed]
            return Xp.reshape(-1, X.shape[-1])
        for k in np.flatnonzero(~crossed):
            if n_off < n_parents:
                s = rng.choice(np.arange(n_parents), size=n_off, replace=False)
            else:
                s = []
                while len(s) < n_off:
                    s.extend(rng.permutation(n_parents))
                s = s[:n_off]
            Xp[:, k] = np.copy(X[s, k])
        return Xp.reshape(-1, X.shape[-1])

    def _unique(self, X: np.ndarray, parents: np.ndarray, off: np.ndarray) -> np.ndarray:
        """The rows of ``X`` that duplicate neither an earlier row, nor a parent, nor an
        earlier offspring (pymoo's ``eliminate_duplicates.do(X, pop, off)``, whose three
        passes drop a row by three tests of the row alone): the rows of ``X`` that
        duplicate no earlier row of ``[parents; off; X]``, in one pass."""
        dup = self.eliminate_duplicates
        if len(X) == 0 or isinstance(dup, NoDuplicateElimination):
            return X
        before = len(parents) + len(off)
        return X[~dup.duplicates(np.concatenate([parents, off, X]))[before:]]
