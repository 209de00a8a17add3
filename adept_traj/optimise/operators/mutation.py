r"""pymoo's mutation step on arrays, the polynomial mutation computed for the mutated rows only.

pymoo's :class:`~pymoo.core.mutation.Mutation` mutates **every** row of the offspring
(``_do``) and then keeps the mutated row with probability ``prob`` per row (one draw per
row, :math:`u_k \le p`). MODE's DE variation calls pymoo's polynomial mutation (PM) at
``prob = 0``: 500 rows mutated a generation, none kept. :func:`mutate` makes PM's draws
for all rows — the (n, n_var) uniforms of the variables to mutate (each with probability
``prob_var``), one integer per row that drew none when ``at_least_once`` (pymoo makes one
call per row, in order; one call of that size gives the same numbers and generator state,
tested against pymoo), one uniform per mutated variable — then the per-row choice, and computes
the mutation for the chosen rows only, by pymoo's own ``mut_pm`` fed with the chosen rows'
draws (:class:`_Replay`): the same rows, the same bits, the same generator state.
Another mutation than PM runs as pymoo runs it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pymoo.core.variable import get
from pymoo.operators.mutation.pm import PM, PolynomialMutation, mut_pm

from adept_traj.errors import ConfigurationError

__all__ = ["mutate"]


def mutate(problem: Any, mutation: Any, X: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """pymoo's ``mutation.do`` of the decision vectors ``X`` (n, n_var) (modified in place
    and returned) with the generator ``rng``: ``mutation._do`` on every row, the rows chosen
    with probability ``mutation.prob`` replaced by their mutation (see the module
    docstring)."""
    n = len(X)
    prob = get(mutation.prob, size=n)
    if type(mutation) not in (PM, PolynomialMutation) or np.all(prob >= 1.0):
        # (every row kept, e.g. NSGA-II's PM at probability 1: nothing to leave out)
        mutated = mutation._do(problem, X, random_state=rng)
        chosen = rng.random(size=n) <= prob
        X[chosen] = mutated[chosen]
        return X
    xl, xu = problem.xl, problem.xu
    eta = get(mutation.eta, size=n)
    prob_var = mutation.get_prob_var(problem, size=n)
    # PM's draws for every row (mut_pm: mut_binomial, at least once, the spread draws)
    uniforms = rng.random((n, X.shape[1]))
    mask = uniforms < (np.ones(n) * prob_var)[:, None]
    forced: dict[int, Any] = {}
    if mutation.at_least_once:
        # pymoo draws one integer per row without a variable, one call each: the same
        # numbers (and generator state) as one call of that size
        empty = np.flatnonzero(~np.any(mask, axis=1))
        picks = rng.integers(X.shape[1], size=len(empty))
        mask[empty, picks] = True
        forced = dict(zip(empty.tolist(), picks, strict=True))
    mask[:, xl == xu] = False
    spread = rng.random(int(mask.sum()))
    chosen = rng.random(size=n) <= prob
    if chosen.any():
        rows = np.flatnonzero(chosen)
        replay = _Replay(
            uniforms[rows],
            [forced[int(k)] for k in rows if int(k) in forced],
            spread[np.repeat(chosen, mask.sum(axis=1))],
        )
        X[rows] = mut_pm(
            X[rows].astype(float),
            xl,
            xu,
            eta[rows],
            prob_var[rows],
            at_least_once=mutation.at_least_once,
            random_state=replay,
        )
        replay.check_used()
    return X


class _Replay:
    """A stand-in for the generator inside pymoo's ``mut_pm``: returns the draws already
    made, in ``mut_pm``'s order (the variable uniforms, the forced integers, the spread
    uniforms), and refuses any other request."""

    def __init__(self, uniforms: np.ndarray, forced: list[Any], spread: np.ndarray) -> None:
        self._uniforms: np.ndarray | None = uniforms
        self._forced = list(forced)
        self._spread: np.ndarray | None = spread

    def random(self, size: Any) -> np.ndarray:
        """The variable uniforms, then the spread uniforms (shapes checked)."""
        for name in ("_uniforms", "_spread"):
            draws = getattr(self, name)
            if draws is not None:
                if tuple(np.atleast_1d(size)) != draws.shape:
                    raise ConfigurationError(f"mutation replay: asked {size}, has {draws.shape}")
                setattr(self, name, None)
                return draws
        raise ConfigurationError("mutation replay: more uniform draws asked than made")

    def integers(self, high: int) -> Any:
        """The next forced integer."""
        if not self._forced:
            raise ConfigurationError("mutation replay: more integer draws asked than made")
        return self._forced.pop(0)

    def check_used(self) -> None:
        """Every draw replayed (else pymoo's ``mut_pm`` drew differently)."""
        if self._uniforms is not None or self._spread is not None or self._forced:
            raise ConfigurationError("mutation replay: draws left unused")
