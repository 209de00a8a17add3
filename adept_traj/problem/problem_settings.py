"""The settings of a :class:`~adept_traj.problem.TrajectoryProblem`: a frozen dataclass,
checked at construction (:class:`~adept_traj.errors.ConfigurationError` naming the value and
its valid range)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from adept_traj.errors import ConfigurationError
from adept_traj.process_pool import can_fork
from adept_traj.validation import as_integer, as_scalar

__all__ = ["ProblemSettings"]


@dataclass(frozen=True)
class ProblemSettings:
    """Settings of a :class:`TrajectoryProblem` (SI units).

    Attributes
    ----------
    n_knots:
        B-spline knots m (paper: 20).
    nodes_per_segment:
        Gauss–Legendre nodes per spline segment where torques, manipulability and distances
        are sampled (default 6: 114 samples, plus both ends).
    margin:
        Safety distance [m] that the certificate checks at every instant.
    search_buffer:
        Distance [m] added to the margin in the optimiser's distance constraint only: the
        search asks :math:`\\min_o d_o \\ge` margin + search_buffer at its samples, so that
        the distance, which can drop between two samples, still clears the margin there
        (see docs/problem.md for the measurement behind the default). The certificate keeps
        the true margin. Need margin + search_buffer ≤ influence.
    influence:
        Distance δ [m] below which distances are exact and the clearance penalty z3 acts.
    t_bounds:
        (T_min, T_max) [s] of the travel time; ``None``: from the kinematic lower bound
        :math:`T_{lb}`, ``(T_lb, 2.5 T_lb)``.
    z3:
        ``"clearance"`` (default, exact distances), ``"paper-sphere"`` or
        ``"paper-ellipsoid"`` (eqs. 13–16 on the tool point).
    workers:
        Processes evaluating a population in parallel (default 1: in this process).
        With ``workers > 1`` a population of at least 16 is split into ``workers``
        chunks (one row each if fewer), evaluated by this process and ``workers - 1``
        forked processes (Linux) of a :class:`~adept_traj.problem.evaluator.ParallelEvaluator`
        that the problem owns; results are identical to the serial evaluation. The
        workers are forked when first needed and hold a snapshot of the problem (later
        edits of ``robot.model`` are not seen by them); :meth:`TrajectoryProblem.close`
        stops them.
    self_collision:
        Check the robot's own links against each other (the pairs of
        :class:`~adept_traj.collision.SelfCollision`) in the distance constraint and the
        certificate, with the same margin. ``None`` (default): on for every robot with a
        pair to check; without an SRDF, parameter-file pairs or ``disabled_pairs``, the
        pairs in contact at every pose of its sampled collision matrix are left out
        (:func:`~adept_traj.collision.self_collision_check`). The problem's
        :attr:`~TrajectoryProblem.settings` hold the resolved ``True``/``False``.
    disabled_pairs:
        ``(link1, link2)`` pairs left out of the self-collision check besides the robot's
        SRDF pairs. The problem's settings hold every disabled pair naming two links with
        solids (these and the SRDF's, sorted), so that a saved result rebuilds the same
        check.
    start_time:
        Scene time t0 [s] (≥ 0) of the move's start: obstacles are seen at t0 + t.
    """

    n_knots: int = 20
    nodes_per_segment: int = 6
    margin: float = 0.01
    influence: float = 0.05
    t_bounds: tuple[float, float] | None = None
    z3: str = "clearance"
    workers: int = 1
    search_buffer: float = 0.002
    self_collision: bool | None = None
    disabled_pairs: tuple[tuple[str, str], ...] = ()
    start_time: float = 0.0

    def __post_init__(self) -> None:
        if self.z3 not in ("clearance", "paper-sphere", "paper-ellipsoid"):
            raise ConfigurationError(
                f"z3 must be 'clearance', 'paper-sphere' or 'paper-ellipsoid'; got {self.z3!r}"
            )
        if not (0 <= self.margin <= self.influence and self.influence > 0):
            raise ConfigurationError(
                f"need 0 ≤ margin ≤ influence and influence > 0 [m]; got margin={self.margin}, "
                f"influence={self.influence}"
            )
        if not (0 <= self.search_buffer <= self.influence - self.margin):
            raise ConfigurationError(
                f"need 0 ≤ search_buffer ≤ influence − margin = "
                f"{self.influence - self.margin:.4g} [m]; got search_buffer={self.search_buffer}"
            )
        if self.self_collision is not None and not isinstance(self.self_collision, bool):
            raise ConfigurationError(
                f"self_collision must be True, False or None; got {self.self_collision!r}"
            )
        try:
            pairs = tuple((str(a), str(b)) for a, b in self.disabled_pairs)
        except (TypeError, ValueError):
            raise ConfigurationError(
                f"disabled_pairs must be (link1, link2) pairs; got {self.disabled_pairs!r}"
            ) from None
        object.__setattr__(self, "disabled_pairs", pairs)
        t0 = as_scalar(self.start_time, "start_time", "[s]", minimum=0, error=ConfigurationError)
        object.__setattr__(self, "start_time", t0)
        for name, minimum in (("workers", 1), ("nodes_per_segment", 1), ("n_knots", 4)):
            value = as_integer(getattr(self, name), name, minimum=minimum, error=ConfigurationError)
            object.__setattr__(self, name, value)
        if self.workers > 1 and not can_fork():
            raise ConfigurationError("workers > 1 needs the 'fork' start method (Linux)")
        if self.t_bounds is not None:
            try:
                lo, hi = (float(v) for v in self.t_bounds)
            except (TypeError, ValueError):
                raise ConfigurationError(
                    f"t_bounds must be (T_min, T_max) in seconds; got {self.t_bounds!r}"
                ) from None
            if not (np.isfinite(hi) and 0.0 < lo < hi):
                raise ConfigurationError(f"t_bounds must satisfy 0 < T_min < T_max; got {lo, hi}")
            object.__setattr__(self, "t_bounds", (lo, hi))
