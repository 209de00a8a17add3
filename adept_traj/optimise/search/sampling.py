r"""Initial populations for trajectory problems.

pymoo's default :class:`~pymoo.operators.sampling.rnd.FloatRandomSampling` draws every
control point uniformly inside the joint limits: such trajectories shake between the limits
and violate the velocity, acceleration and jerk limits by orders of magnitude, so a run
spends most of its budget finding the feasible region. :class:`RampSampling` (the default)
draws **rest-to-rest ramps with random timing and a random detour per joint**:

.. math::
    P_{c,j} = q_{s,j} + \Delta_j\,\sigma\!\left(\frac{\xi_c - a_j}{b_j - a_j}\right)
              + \beta_j \sin(\pi \xi_c)\,(\bar q_j - \underline q_j),

with :math:`\xi_c` the control points' Greville abscissae in [0, 1], σ a normalised
S-curve — the position profile of a trapezoidal acceleration (jerk phases of a random
fraction r ∈ [0.05, 0.25] of the move, r = 0.25 being a triangular acceleration), the shape
of time-optimal jerk-limited moves — a window
:math:`0 \le a_j < b_j \le 1` (the whole motion with probability ``full_window``, else
random) and a random detour amplitude
:math:`\beta_j \sim \mathcal N(0, \text{detour}^2)` (with probability ``detour_prob``,
else 0); T is uniform in its bounds. The straight
joint-space move is always included. Control points are clipped to the decision bounds.
Travel times: half the individuals get T uniform in its bounds, the other half T just above
their own kinematic minimum (:func:`~adept_traj.optimise.kinematic_time` × U[1, 1.3]), so the
fast end of the front is explored from the start. Nothing about a particular scene is
assumed.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pymoo.core.initialization import Initialization
from pymoo.core.sampling import Sampling

from adept_traj.errors import ConfigurationError
from adept_traj.memory import check_memory
from adept_traj.optimise.operators.repair import kinematic_time
from adept_traj.validation import as_integer, as_scalar

__all__ = [
    "RampSampling",
    "SeededInitialization",
    "check_population_memory",
    "population_bytes",
]


_GRID = np.linspace(0.0, 1.0, 2001)

#: S-curves (one per individual and joint) tabulated at once on :data:`_GRID`: a block of
#: 512 curves holds 512 × 2001 × 8 B ≈ 8 MB per temporary array (about six are alive at a
#: time), whatever the population size (pop × nq × 2001 × 8 B ≈ 320 MB per array at pop
#: 5 000 unblocked).
_BLOCK_CURVES = 512


#: The ramps' numerator on :data:`_GRID`: the distance to the nearer end of the grid h and
#: to its middle 0.5 - h, the smaller of the two, in [0, 0.25], signed +1 on the first half
#: of the grid and -1 on the second.
_HALF = np.minimum(_GRID, 1.0 - _GRID)
_SIGNED_RISE = np.where(_GRID < 0.5, 1.0, -1.0) * np.minimum(_HALF, 0.5 - _HALF)


def _s_curve(u: np.ndarray, r: np.ndarray) -> np.ndarray:
    r"""Normalised S-curves σ(u) (σ(0) = 0, σ(1) = 1, rest to rest) with jerk-phase fraction
    ``r``: acceleration ramps up over r, holds, ramps down over r (first half), mirrored
    negative in the second half. ``u`` (..., k) clipped to [0, 1]; ``r`` (...) broadcast.

    Tabulated on :data:`_GRID` (two running sums of the acceleration), then interpolated;
    only the ``2 k`` tabulated points each curve is read at are normalised. The
    acceleration is

    .. math::
        a = \mathrm{clip}\!\left(\frac{s\,\min(h,\ 0.5 - h)}{r},\ -1,\ 1\right)
          = s\,\min\!\left(\frac{h}{r},\ \frac{0.5 - h}{r},\ 1\right)

    (s = ±1 the half's sign, h the distance to the nearer end), the same numbers bit for
    bit as the right-hand side: r > 0, so the smaller numerator gives the smaller rounded
    quotient, and a sign of ±1 commutes with the rounded division and the clipping. One
    division and two clippings in place instead of two divisions, three minima and a
    product (≈ 35 % less of the curve's table)."""
    r = np.asarray(r, dtype=float)[..., None]
    acc = np.divide(_SIGNED_RISE, r)
    np.minimum(acc, 1.0, out=acc)
    np.maximum(acc, -1.0, out=acc)
    pos = np.cumsum(np.cumsum(acc, axis=-1, out=acc), axis=-1, out=acc)
    first, last = pos[..., :1], pos[..., -1:]
    uu = np.clip(u, 0.0, 1.0)
    idx = np.minimum((uu * (len(_GRID) - 1)).astype(int), len(_GRID) - 2)
    w = uu * (len(_GRID) - 1) - idx
    span = last - first

    def at(i: np.ndarray) -> np.ndarray:
        return (np.take_along_axis(pos, i, axis=-1) - first) / span

    return at(idx) * (1 - w) + at(idx + 1) * w


def _s_curves_blocked(u: np.ndarray, r: np.ndarray) -> np.ndarray:
    """:func:`_s_curve` of ``u`` (n, nq, k) and ``r`` (n, nq), computed in blocks of rows of
    at most :data:`_BLOCK_CURVES` curves: the same numbers, bit for bit (every row is
    computed alone), with a peak memory independent of n."""
    rows = max(1, _BLOCK_CURVES // max(1, u.shape[1]))
    if len(u) <= rows:
        return _s_curve(u, r)
    out = np.empty(u.shape)
    for i in range(0, len(u), rows):
        out[i : i + rows] = _s_curve(u[i : i + rows], r[i : i + rows])
    return out


def population_bytes(pop_size: int, n_gen: int = 1) -> int:
    r"""Estimated peak memory [B] of a run with ``pop_size`` individuals over ``n_gen``
    generations (the whole process, Python and the libraries included):

    .. math::
        M = 170\,\text{MiB} + 20\,\text{kB} \cdot N + 4\,\text{B} \cdot N^2
            + 300\,\text{B} \cdot N \cdot G .

    The sampler, the repair, the evaluation and the duplicate elimination
    (:class:`~adept_traj.optimise.BlockedDuplicateElimination`) work in blocks and add only
    the linear term. The :math:`N^2` term is the non-dominated sorting of the 2N parents
    and offspring (pymoo's compiled fast non-dominated sort keeps, for each member, the
    members it dominates: 4 B per ordered pair, 8 B·N² if every pair were ordered; the term
    allows for half of them). The :math:`N G` term is the history of the generations' fronts
    and the allocator's growth over the generations (measured 200–600 B per individual and
    generation over the first 15 generations, less later). Fitted to the peak RSS of
    ``adept-traj plan`` (``benchmarks/bench_memory.py``; NSGA-II and MODE): 163 MB at
    N = 100, 172–197 MB at N = 1 000–4 000 and 274–338 MB at N = 16 000 (2 generations),
    217–225 MB at N = 4 000 over 15 generations, 187 MB at N = 5 000 (one generation;
    555 MB with pymoo's (N, N) duplicate elimination) — each at most this estimate.
    """
    n = as_integer(pop_size, "pop_size", minimum=1, error=ConfigurationError)
    g = as_integer(n_gen, "n_gen", minimum=1, error=ConfigurationError)
    return 170 * 2**20 + 20_000 * n + 4 * n * n + 300 * n * g


def check_population_memory(
    pop_size: int, n_gen: int = 1, *, options: tuple[str, str] = ("pop_size", "n_gen")
) -> int:
    """:func:`population_bytes` if it fits the memory budget
    (:func:`~adept_traj.memory.memory_budget`), else
    :class:`~adept_traj.errors.ResourceLimitError` naming ``options[0]`` (the population
    option, e.g. ``"--pop"``) or ``options[1]`` (the generations) when the population alone
    fits."""
    need = population_bytes(pop_size, n_gen)
    alone = population_bytes(pop_size, 1)
    check_memory(alone, options[0], pop_size)
    check_memory(need, options[1], f"{n_gen} with {options[0]} = {pop_size}")
    return need


class RampSampling(Sampling):
    """Random rest-to-rest ramps with random per-joint timing and detours (see module doc).

    Parameters
    ----------
    detour:
        Standard deviation of the detour amplitude, as a fraction of each joint's range
        (default 0.05).
    detour_prob:
        Probability that a joint makes a detour at all (default 0.25): detours explore
        around obstacles but slow a move down, so most ramps go straight.
    min_window:
        Smallest fraction of the control polygon over which a joint moves (default 0.3).
    full_window:
        Probability that a joint moves over the whole motion (window [0, 1], the shape of
        time-optimal moves) instead of a random sub-window (default 0.5).
    """

    def __init__(
        self,
        detour: float = 0.05,
        min_window: float = 0.3,
        full_window: float = 0.5,
        detour_prob: float = 0.25,
    ) -> None:
        super().__init__()
        bad = ConfigurationError
        detour = as_scalar(detour, "detour", minimum=0.0, error=bad)
        min_window = as_scalar(min_window, "min_window", minimum=0.0, strict=True, error=bad)
        full_window = as_scalar(full_window, "full_window", minimum=0.0, error=bad)
        detour_prob = as_scalar(detour_prob, "detour_prob", minimum=0.0, error=bad)
        for name, value in (
            ("min_window", min_window),
            ("full_window", full_window),
            ("detour_prob", detour_prob),
        ):
            if value > 1.0:
                raise bad(f"{name} must be a number ≤ 1; got {value}")
        self.detour, self.min_window = detour, min_window
        self.full_window, self.detour_prob = full_window, detour_prob

    def _do(self, problem: Any, n_samples: int, random_state: Any = None, **kwargs: Any):
        if n_samples > 0:  # the first step of a run: refuse a population beyond the budget
            check_population_memory(n_samples)
        rng = random_state if random_state is not None else np.random.default_rng()
        x = self.ramps(problem, n_samples, rng)
        if n_samples > 0:
            x[0] = problem.trajectory.straight_line(0.5 * (problem.xl[0] + problem.xu[0]))
        return np.clip(x, problem.xl, problem.xu)

    def ramps(
        self, problem: Any, n_samples: int, rng: np.random.Generator, *, fast_times: bool = True
    ) -> np.ndarray:
        """(n_samples, n_var) random ramps (the module's distribution, without the straight
        move), clipped to the decision bounds; randomness from ``rng`` only.

        ``fast_times=False`` leaves the travel time T of the half that would get T just
        above its kinematic minimum at its uniform draw (the same draws are made, the
        kinematic minima are not computed): for a caller that sets every T itself, as
        :class:`~adept_traj.optimise.FastEndSearch` does; every other number is the
        same."""
        traj = problem.trajectory
        nq = traj.nq
        xi = traj.free_abscissae
        span = problem.robot.limits.upper - problem.robot.limits.lower
        T = rng.uniform(problem.xl[0], problem.xu[0], size=n_samples)
        a = rng.uniform(0.0, 1.0 - self.min_window, size=(n_samples, nq))
        b = a + rng.uniform(self.min_window, 1.0, size=(n_samples, nq)) * (1.0 - a)
        b = np.maximum(b, a + self.min_window)
        full = rng.uniform(size=(n_samples, nq)) < self.full_window
        a, b = np.where(full, 0.0, a), np.where(full, 1.0, b)
        r = rng.uniform(0.05, 0.25, size=(n_samples, nq))
        u = (xi[None, None, :] - a[:, :, None]) / (b - a)[:, :, None]  # (n, nq, n_free)
        ramp = np.swapaxes(_s_curves_blocked(u, r), 1, 2)  # (n, n_free, nq)
        detour = rng.normal(0.0, self.detour, size=(n_samples, 1, nq)) * span
        detour *= rng.uniform(size=(n_samples, 1, nq)) < self.detour_prob
        free = (
            traj.start
            + (traj.goal - traj.start) * ramp
            + detour * np.sin(np.pi * xi)[None, :, None]
        )  # (n_samples, n_free, nq)
        x = traj.encode(T, free)
        fast = rng.uniform(size=n_samples) < 0.5
        above = rng.uniform(1.0, 1.3, size=fast.sum())
        if fast_times:
            x[fast, 0] = kinematic_time(problem, x[fast]) * above
        return np.clip(x, problem.xl, problem.xu)


class SeededInitialization(Initialization):
    """pymoo's initialization (sampling, repair, duplicate elimination), then given moves
    put, as they are, in place of the population's rows 1 … k (row 0, the sampling's
    straight move, kept): the global stage's starts
    (:func:`~adept_traj.optimise.initial_starts`). They are not repaired: the
    kinematic-time repair would snap some of them to the kinematic minimum T of their
    path (a random share of every candidate), where the relaxed problem's optimum passes
    the moving obstacles at other phases.

    Parameters
    ----------
    initialization:
        The algorithm's own :class:`pymoo.core.initialization.Initialization`.
    starts:
        (k, n_var) moves inside the decision bounds, each at or above its kinematic
        minimum T; at most ``n_samples − 1`` are used.
    """

    def __init__(self, initialization: Initialization, starts: Any) -> None:
        super().__init__(
            initialization.sampling,
            repair=initialization.repair,
            eliminate_duplicates=initialization.eliminate_duplicates,
        )
        self.starts = np.array(starts, dtype=float, ndmin=2)

    def do(self, problem: Any, n_samples: int, random_state: Any = None, **kwargs: Any):
        pop = super().do(problem, n_samples, random_state=random_state, **kwargs)
        if self.starts.shape[1] != problem.n_var:
            raise ConfigurationError(
                f"starts must have n_var = {problem.n_var} columns; got {self.starts.shape}"
            )
        m = min(len(self.starts), len(pop) - 1)
        if m > 0:
            x = pop.get("X")
            x[1 : 1 + m] = np.clip(self.starts[:m], problem.xl, problem.xu)
            pop.set("X", x)
        return pop
