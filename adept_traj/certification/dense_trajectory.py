r"""A trajectory sampled on a dense uniform time grid: the samples a certificate checks.

:func:`dense_samples` gives the number of samples
:math:`n = \lceil T \cdot \text{rate} \rceil + 1` of the grid over :math:`[0, T]` (both
ends included) and :class:`DenseTrajectory` holds the states, torques and smallest
distances at those samples (built by :func:`~adept_traj.certification.certificate.certify`).

The states, torques and distances of several moves are formed together (one inverse
dynamics call and one distance call for up to :func:`batch_samples` samples of several
moves, :func:`~adept_traj.analysis.certify_members`): every sample's values depend on that
sample alone, so a move's values are those of its own call (tested bit for bit).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.problem.trajectory_problem import TrajectoryProblem
from adept_traj.robot.limits import LIMITS
from adept_traj.validation import DeepEqual, as_finite_array, as_scalar, readonly_copy

__all__ = [
    "BATCH_SAMPLES",
    "BATCH_VALUES",
    "DenseStates",
    "DenseTrajectory",
    "batch_samples",
    "dense_samples",
    "dense_states",
]

#: Most dense samples of the several moves formed in one batch by
#: :func:`~adept_traj.analysis.certify_members` (a move with more is formed alone): the
#: per-call work of the inverse dynamics and the distances is shared, and the batch's
#: arrays stay in the CPU cache. Measured on the paper front (42 solid–obstacle pairs):
#: about 6 000 samples (3–4 moves at 1 kHz) were the fastest, faster than one move at a
#: time and than 12 000 samples.
BATCH_SAMPLES = 6144

#: Most solid–obstacle distances (samples × pairs, 2 MiB of them) of one batch: a scene
#: with many obstacles batches fewer samples (:func:`batch_samples`).
BATCH_VALUES = 2**18


def batch_samples(problem: TrajectoryProblem) -> int:
    """Most dense samples of one batch for ``problem``: :data:`BATCH_SAMPLES`, or fewer so
    that the batch holds at most :data:`BATCH_VALUES` solid–obstacle distances (6 144 for
    the paper's 7 solids and 6 obstacles, 187 for 7 solids and 200 obstacles)."""
    pairs = problem.checker.n_solids * problem.checker.n_obstacles
    return max(1, min(BATCH_SAMPLES, BATCH_VALUES // max(1, pairs)))


#: A move's dense states: (the spline samples :class:`~adept_traj.problem.TrajectorySamples`
#: ``t`` (n,) [s], ``q, qd, qdd, qddd`` (n, nq); the torques ``tau`` (n, nq) [N·m | N]; the
#: distances (n, n_solids, n_obstacles) [m] of every solid–obstacle pair, or ``None`` when
#: the scene has no obstacle or the robot no solid).
DenseStates = tuple[Any, np.ndarray, np.ndarray | None]


@dataclass(frozen=True, eq=False)
class DenseTrajectory(DeepEqual):
    """A trajectory sampled on a uniform grid (both ends included).

    Attributes
    ----------
    t: (n,) sample times [s], ``t[0] = 0``, ``t[-1] = T``.
    q: (n, nq) positions [rad | m].
    qd: (n, nq) velocities [rad/s | m/s].
    qdd: (n, nq) accelerations [rad/s² | m/s²].
    qddd: (n, nq) jerks [rad/s³ | m/s³].
    tau: (n, nq) joint torques/forces [N·m | N] (inverse dynamics with friction).
    min_distance: (n,) smallest signed distance over every (solid, obstacle) pair [m]
        (negative: penetration depth; ``inf`` when the scene has no obstacle).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    qddd: np.ndarray
    tau: np.ndarray
    min_distance: np.ndarray

    def __post_init__(self) -> None:
        t = readonly_copy(as_finite_array(self.t, "t"))
        if t.ndim != 1 or t.size < 2:
            raise InvalidInputError(f"t must have shape (n,) with n ≥ 2; got {t.shape}")
        object.__setattr__(self, "t", t)
        nq = None
        for name in (kind.quantity for kind in LIMITS):
            arr = readonly_copy(as_finite_array(getattr(self, name), name))
            if arr.ndim != 2 or arr.shape[0] != t.size or (nq is not None and arr.shape[1] != nq):
                raise InvalidInputError(
                    f"{name} must have shape ({t.size}, nq) like the others; got {arr.shape}"
                )
            nq = arr.shape[1]
            object.__setattr__(self, name, arr)
        d = np.array(self.min_distance, dtype=np.float64)
        if d.shape != t.shape or np.isnan(d).any() or (d == -np.inf).any():
            raise InvalidInputError(
                f"min_distance must have shape {t.shape} with no NaN or -inf; got {d.shape}"
            )
        object.__setattr__(self, "min_distance", readonly_copy(d))

    @property
    def n_samples(self) -> int:
        """Number of samples n."""
        return int(self.t.size)

    @property
    def nq(self) -> int:
        """Number of joints."""
        return int(self.q.shape[1])

    __hash__ = None  # type: ignore[assignment]


def dense_samples(T: float, rate_hz: float) -> int:
    """Number of uniform samples over [0, T] [s] with spacing at most 1/``rate_hz`` [Hz],
    both ends included: ``ceil(T·rate) + 1`` (at least 2). The 1e-9 keeps
    T·rate = 2100.0000000000005 at 2100."""
    T = as_scalar(T, "T", "[s]", minimum=0.0)
    rate_hz = as_scalar(rate_hz, "rate_hz", "[Hz]", minimum=0.0, strict=True)
    return max(2, math.ceil(T * rate_hz - 1e-9) + 1)


def dense_states(
    problem: TrajectoryProblem, xs: Sequence[np.ndarray], rate_hz: float, exact: bool
) -> list[DenseStates]:
    """The :data:`DenseStates` of each move on its dense grid, all moves' samples in one
    inverse-dynamics call and one :meth:`~adept_traj.collision.CollisionChecker.distances`
    call.

    Parameters
    ----------
    problem:
        The :class:`~adept_traj.problem.TrajectoryProblem`.
    xs:
        Checked moves, each (n_var,) ``[T [s], control points [rad | m]]``.
    rate_hz:
        Grid rate [Hz]: move k has :func:`dense_samples` ``(T_k, rate_hz)`` samples.
    exact:
        As :meth:`~adept_traj.collision.CollisionChecker.distances`: exact distances also
        beyond the influence distance.

    Returns
    -------
    list of DenseStates
        Per move: its samples (``t`` (n,) [s], ``q`` … ``qddd`` (n, nq)), its torques (n, nq)
        [N·m | N] and its distances (n, n_solids, n_obstacles) [m] (``None`` without solids or
        obstacles).
    """
    samples = [
        problem.trajectory.sample(x, np.linspace(0.0, 1.0, dense_samples(float(x[0]), rate_hz)))
        for x in xs
    ]
    ends = np.cumsum([len(smp.t) for smp in samples])[:-1]
    t, q, qd, qdd = (
        np.concatenate([getattr(smp, name) for smp in samples]) for name in ("t", "q", "qd", "qdd")
    )
    tau = np.split(problem.robot.inverse_dynamics(q, qd, qdd), ends)
    checker = problem.checker
    pairs: list[np.ndarray | None] = [None] * len(samples)
    if checker.n_obstacles and checker.n_solids:
        pairs = list(np.split(checker.distances(q[None], t[None], exact=exact).distance[0], ends))
    return list(zip(samples, tau, pairs))
