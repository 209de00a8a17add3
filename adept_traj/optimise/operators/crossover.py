r"""pymoo's simulated binary crossover (SBX) computed for the matings that cross over only.

pymoo's :class:`~pymoo.core.crossover.Crossover` decides per mating whether it crosses over
(probability :math:`p_c`, NSGA-II's 0.7) and calls the operator's ``_do`` on **all** the
matings, keeping the children of the crossed ones (the others copy their parents). SBX's
``_do`` draws, in this order, one exchange draw per mating, a (n_matings, n_var) mask of
the variables to cross (each with probability ``prob_var``, none where the parents are
within :math:`10^{-14}` or the bounds coincide), then one spread draw :math:`u` and one
exchange draw per crossed variable, and computes for each crossed variable with parents
:math:`y_1 \le y_2`, :math:`\delta = y_2 - y_1`, bounds :math:`[x_l, x_u]`:

.. math::
    \beta = 1 + \frac{2\,(y_1 - x_l)}{\delta}\ \text{(and } 1 + \frac{2\,(x_u - y_2)}{\delta}
    \text{ for the second child)}, \qquad \alpha = 2 - \beta^{-(\eta + 1)},

.. math::
    \beta_q = \begin{cases} (u\,\alpha)^{1/(\eta + 1)} & u \le 1/\alpha \\
    \left(\frac{1}{2 - u\,\alpha}\right)^{1/(\eta + 1)} & u > 1/\alpha \end{cases},
    \qquad c_{1,2} = \tfrac12\left((y_1 + y_2) \mp \beta_q\,\delta\right),

each power evaluated for both cases on every variable and one kept. :func:`sbx_children`
makes the same draws (the same sizes from the same generator, in the same order) and
evaluates each formula once per crossed variable of a crossed mating only: every number is
computed by the same elementwise operations on the same operands, hence the same bits
(tested against pymoo's ``SBX``), with about a third of the work.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pymoo.core.variable import get

__all__ = ["sbx_children"]

#: pymoo's ``cross_sbx``: parents closer than this in a variable do not cross it.
_TOO_CLOSE = 1.0e-14


def sbx_children(
    problem: Any, sbx: Any, X: np.ndarray, crossed: np.ndarray, rng: np.random.Generator
) -> np.ndarray:
    """The two children (2, k, n_var) of each of the k crossed matings (``crossed``
    (n_matings,) bool) of the parents ``X`` (2, n_matings, n_var), as pymoo's SBX ``sbx``
    (two parents, two children) makes them by ``sbx._do(problem, X)`` for all the matings,
    with the same draws from ``rng`` (see the module docstring). Bounds from
    ``problem.xl``, ``problem.xu`` (n_var,)."""
    _, n_matings, n_var = X.shape
    eta, prob_var, prob_exch, prob_bin = get(
        sbx.eta, sbx.prob_var, sbx.prob_exch, sbx.prob_bin, size=(n_matings, 1)
    )
    prob_bin[rng.random((len(prob_bin), 1)) > prob_exch] = 0.0
    X = X.astype(float)
    xl, xu = problem.xl, problem.xu
    cross = rng.random((n_matings, n_var)) < prob_var
    cross[np.abs(X[0] - X[1]) <= _TOO_CLOSE] = False
    cross[:, xl == xu] = False
    n_cross = int(cross.sum())
    spread, exchange = rng.random(n_cross), rng.random(n_cross)
    # the draws of the crossed matings' variables (row-major, as pymoo indexes them)
    mine = np.repeat(crossed, cross.sum(axis=1))
    spread, exchange = spread[mine], exchange[mine]
    rows = np.flatnonzero(crossed)
    cross = cross[rows]
    pair = X[:, rows]  # a copy: the children start as their parents
    p1, p2 = pair[0][cross], pair[1][cross]
    small = p1 < p2
    y1, y2 = np.where(small, p1, p2), np.where(small, p2, p1)
    lo, hi = np.broadcast_to(xl, cross.shape)[cross], np.broadcast_to(xu, cross.shape)[cross]
    eta = np.broadcast_to(eta[rows], cross.shape)[cross]
    prob_bin = np.broadcast_to(prob_bin[rows], cross.shape)[cross]
    delta = y2 - y1
    c1 = 0.5 * ((y1 + y2) - _spread(1.0 + (2.0 * (y1 - lo) / delta), spread, eta) * delta)
    c2 = 0.5 * ((y1 + y2) + _spread(1.0 + (2.0 * (hi - y2) / delta), spread, eta) * delta)
    child1, child2 = np.where(small, c1, c2), np.where(small, c2, c1)
    swap = np.bitwise_xor(exchange < prob_bin, p1 > p2)
    child1, child2 = np.where(swap, (child2, child1), (child1, child2))
    pair[0][cross], pair[1][cross] = child1, child2
    # pymoo's repair_clamp of each child: a value below its lower bound becomes the bound,
    # then one above its upper bound (NaN stays)
    pair = np.where(pair < xl, xl, pair)
    return np.where(pair > xu, xu, pair)


def _spread(beta: np.ndarray, u: np.ndarray, eta: np.ndarray) -> np.ndarray:
    r""":math:`\beta_q` (k,) of the module docstring for :math:`\beta`, the draws
    :math:`u` and :math:`\eta` (k,) — each case's power evaluated on its own variables only
    (0 where neither case holds, a NaN comparison, as in pymoo)."""
    alpha = 2.0 - np.power(beta, -(eta + 1.0))
    ua = u * alpha
    exponent = 1.0 / (eta + 1.0)
    first, second = u <= (1.0 / alpha), u > (1.0 / alpha)
    betaq = np.zeros(beta.shape)
    betaq[first] = np.power(ua[first], exponent[first])
    betaq[second] = np.power(1.0 / (2.0 - ua[second]), exponent[second])
    return betaq
