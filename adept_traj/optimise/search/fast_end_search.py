r"""Local search at the fast end of the front, inside any pymoo mating.

Evolutionary operators on 64 control points rarely improve the fastest feasible move: a
crossover of two distant parents mostly produces a slower or colliding child, and the
paper's mutation touches 1 % of the variables. :class:`FastEndSearch` wraps an
algorithm's mating and replaces a ``fraction`` of each generation's offspring by small
perturbations of the population's fastest feasible members (a (μ + λ) local search on
z1, interleaved with the evolutionary one; the rest of the offspring are the algorithm's
own):

.. math::
    P'_j(\xi) = P_j(\xi) + a_j\, b\!\left(\frac{\xi - c_j}{w_j}\right) e(\xi), \qquad
    b(u) = \cos^4\!\left(\frac{\pi u}{2}\right)\ (|u| \le 1), \qquad
    a_j \sim \mathcal N\big(0, (\sigma\,(\bar q_j - \underline q_j))^2\big),

a smooth bump per joint j at a random centre :math:`c_j \in [0, 1]` and half-width
:math:`w_j \in [0.1, 0.5]` over the control points' Greville abscissae ξ, faded out by
:math:`e(\xi)` before the fixed rest-to-rest points (a jump there is a jerk), with
:math:`\log\sigma \sim \mathcal U(\log\sigma_{lo}, \log\sigma_{hi})`;
P the control points of one of the ``n_elite`` fastest feasible members (uniformly
chosen); the child is clipped to the bounds, and the travel time set to the child's own kinematic
minimum :math:`T_{kin}(P')` (:func:`~adept_traj.optimise.kinematic_time`), the fastest move
of that shape. Survival then keeps a child only if it is better (e.g. feasible and faster).

A share ``immigrants`` (default 1/3) of these local children are instead **fresh random
ramps** from :class:`~adept_traj.optimise.RampSampling`, also at their own kinematic minimum
time (random immigrants at the fast end). Perturbations refine the fastest shapes found so
far; immigrants keep sampling new ones, so the search does not stay in the basin of the
first feasible fast move (measured on the paper scenario with NSGA-II at the paper's
settings, seeds 1–3: the fastest verified move went from 1.18–1.25 × the kinematic lower
bound without immigrants to 1.04–1.07 × with them, see ``docs/engine.md``). Immigrants are made
even before any member is feasible; perturbations only after.
The number of offspring, hence of evaluations per generation, is unchanged; randomness
comes from the algorithm's seeded generator (same seed, same front; exact resume).
Nothing about a particular scene is assumed. Before any member is feasible the mating is
the algorithm's own, apart from the immigrants.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pymoo.core.population import Population

from adept_traj.errors import ConfigurationError
from adept_traj.optimise.operators.de_variant import ArrayVariant
from adept_traj.optimise.operators.mating import ArrayMating
from adept_traj.optimise.operators.population import population_values
from adept_traj.optimise.operators.repair import (
    KINEMATIC_SLACK,
    KinematicTimeRepair,
    kinematic_time,
)
from adept_traj.optimise.search.sampling import RampSampling
from adept_traj.validation import as_integer, as_scalar

__all__ = ["FastEndSearch"]


class FastEndSearch:
    """A pymoo mating whose offspring are partly local perturbations of the fastest
    feasible members (see the module docstring).

    Parameters
    ----------
    mating:
        The algorithm's own mating (e.g. NSGA-II's SBX + PM, MODE's DE/rand/1/bin).
    fraction:
        Share of the offspring made by the local search, in [0, 1] (default 0.3).
    n_elite:
        How many of the fastest feasible members are perturbed (default 5).
    sigma:
        (lo, hi) range of the perturbation scale as a fraction of each variable's range
        (default (0.0005, 0.01)); drawn log-uniformly per child.
    immigrants:
        Share of the local children that are fresh ramps instead of perturbations, in
        [0, 1] (default 1/3; 0 disables them).
    sampling:
        Where immigrants come from (default: a :class:`~adept_traj.optimise.RampSampling`
        with its default parameters).
    """

    def __init__(
        self,
        mating: Any,
        fraction: float = 0.3,
        n_elite: int = 5,
        sigma: tuple[float, float] = (0.0005, 0.01),
        immigrants: float = 1.0 / 3.0,
        sampling: RampSampling | None = None,
    ) -> None:
        fraction = as_scalar(fraction, "fast_end fraction", minimum=0.0, error=ConfigurationError)
        immigrants = as_scalar(immigrants, "immigrants", minimum=0.0, error=ConfigurationError)
        for name, value in (("fast_end fraction", fraction), ("immigrants", immigrants)):
            if value > 1.0:
                raise ConfigurationError(f"{name} must be a number in [0, 1]; got {value}")
        n_elite = as_integer(n_elite, "n_elite", minimum=1, error=ConfigurationError)
        if len(sigma) != 2:
            raise ConfigurationError(f"sigma must be (lo, hi) with 0 < lo ≤ hi; got {sigma}")
        lo, hi = (as_scalar(v, "sigma", minimum=0.0, error=ConfigurationError) for v in sigma)
        if not 0.0 < lo <= hi:
            raise ConfigurationError(f"sigma must be (lo, hi) with 0 < lo ≤ hi; got {sigma}")
        self.mating, self.fraction = mating, fraction
        self.n_elite, self.sigma = n_elite, (lo, hi)
        self.immigrants = immigrants
        self.sampling = RampSampling() if sampling is None else sampling

    def __getattr__(self, name: str) -> Any:
        # Everything else (repair, eliminate_duplicates, ...) is the wrapped mating's.
        if name == "mating" or name.startswith("__"):  # not set yet (copying), or protocol
            raise AttributeError(name)
        return getattr(self.mating, name)

    def __call__(self, problem: Any, pop: Population, n_offsprings: int, **kwargs: Any) -> Any:
        return self.do(problem, pop, n_offsprings, **kwargs)

    def do(self, problem: Any, pop: Population, n_offsprings: int, **kwargs: Any) -> Population:
        """``n_offsprings`` children of ``pop``: the mating's, of which a random
        ``fraction`` is replaced by local-search children — perturbations of the fastest
        feasible members and fresh ramps (immigrants). The replaced children are not
        evaluated: the number of evaluations is the mating's."""
        rng = kwargs.get("random_state")
        feasible = np.flatnonzero(population_values(pop, "CV")[:, 0] <= 0.0) if len(pop) else []
        # The mating's children as an array when it can make them so (its members are
        # built once, below, without the replaced ones), else as a population.
        arrays = rng is not None and _makes_arrays(self.mating)
        # MODE's trial vectors: their kinematic time repair made for the kept ones only,
        # with the children's kinematic times (the repair's draws made where it makes them)
        repair = getattr(self.mating, "repair", None)
        deferred = arrays and isinstance(self.mating, ArrayVariant)
        deferred = deferred and isinstance(repair, KinematicTimeRepair)
        if deferred:
            off, snapped = self.mating.unrepaired_offspring(problem, pop, n_offsprings, **kwargs)
        elif arrays:
            off = self.mating.offspring(problem, pop, n_offsprings, **kwargs)
        else:
            off = self.mating.do(problem, pop, n_offsprings, **kwargs)
        n_local = min(round(self.fraction * n_offsprings), len(off))
        n_new = round(self.immigrants * n_local)
        n_bump = n_local - n_new if len(feasible) else 0
        if rng is None or len(off) == 0 or n_new + n_bump == 0:
            if deferred:
                off = repair.repaired(problem, off, snapped)
            return Population.new(X=off) if arrays else off
        # Replace a random subset of the mating's children (not its last ones: pymoo's DE
        # uses the first members of the population as targets, in order).
        keep = np.sort(rng.permutation(len(off))[: len(off) - n_new - n_bump])
        # (each immigrant's T is set below: the ramps' own fast times are not needed)
        children = self.sampling.ramps(problem, n_new, rng, fast_times=False)
        if n_bump:
            X = population_values(pop, "X")
            fastest = feasible[np.argsort(X[feasible, 0], kind="stable")[: self.n_elite]]
            parents = X[fastest[rng.integers(0, len(fastest), size=n_bump)]]
            children = np.concatenate([children, self._perturb(problem, parents, rng)])
        if deferred:  # one kinematic time call for the kept trial vectors and the children
            t_all = kinematic_time(problem, np.concatenate([off[keep], children]))
            kept = repair.repaired(problem, off[keep], snapped[keep], t_all[: len(keep)])
            t_kin = t_all[len(keep) :] * (1.0 + KINEMATIC_SLACK)
        else:
            kept = off[keep]
            t_kin = kinematic_time(problem, children) * (1.0 + KINEMATIC_SLACK)
        children[:, 0] = np.clip(t_kin, problem.xl[0], problem.xu[0])
        if arrays:
            return Population.new(X=np.concatenate([kept, children]))
        return Population.merge(off[keep], Population.new(X=children))

    def _perturb(self, problem: Any, parents: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Smooth perturbations of the parents' free control points (cos⁴ bumps times
        ``_envelope`` over the Greville abscissae), clipped to the bounds; T is set
        afterwards."""
        traj = problem.trajectory
        _, P = traj.decode(parents)
        free = P[:, 3:-3, :]  # (n, n_free, nq)
        xi = traj.free_abscissae
        n = len(parents)
        # Per child: one smooth bump per joint at a random place and width (all three
        # derivatives vanish at its ends, and it is cut off before the fixed end points).
        centre = rng.uniform(0.0, 1.0, size=(n, 1, traj.nq))
        width = rng.uniform(0.1, 0.5, size=(n, 1, traj.nq))
        u = np.clip((xi[None, :, None] - centre) / width, -1.0, 1.0)  # (n, n_free, nq)
        bump = np.cos(0.5 * np.pi * u) ** 4 * _envelope(xi)[None, :, None]
        lo, hi = np.log(self.sigma[0]), np.log(self.sigma[1])
        scale = np.exp(rng.uniform(lo, hi, size=(n, 1, 1)))
        span = problem.robot.limits.upper - problem.robot.limits.lower
        amplitude = rng.standard_normal((n, 1, traj.nq)) * scale * span
        free = free + amplitude * bump
        children = traj.encode(parents[:, 0], free)
        return np.clip(children, problem.xl, problem.xu)


def _makes_arrays(mating: Any) -> bool:
    """Whether ``mating`` makes its children as an array (``offspring``, the decision
    vectors of the members its ``do`` would return: those of
    :class:`~adept_traj.optimise.ArrayMating` and :class:`~adept_traj.optimise.ArrayVariant`
    with pymoo's plain operators)."""
    return isinstance(mating, ArrayMating | ArrayVariant) and mating.makes_arrays()


def _envelope(xi: np.ndarray) -> np.ndarray:
    r"""(n,) :math:`\min(1, (\xi / e)^4, ((1 - \xi) / e)^4)` with e = 0.15: a perturbation
    fades out smoothly before the fixed rest-to-rest control points (a jump there would be a
    third difference — a jerk — right after the start or before the goal)."""
    edge = 0.15
    return np.minimum(1.0, np.minimum(xi / edge, (1.0 - xi) / edge) ** 4)
