r"""The paper's trajectory problem: six objectives and 21 constraints, batched (pymoo).

:class:`TrajectoryProblem` is a :class:`pymoo.core.problem.Problem` over the decision vector
of :class:`~adept_traj.problem.BSplineTrajectory` (``[T, free control points]``). For a
population ``x`` (pop, n_var) it computes the objectives z1…z6 of
:data:`~adept_traj.problem.objectives.OBJECTIVES` (names, units, paper equations, which is
maximised) as follows:

- z1: the travel time :math:`T = x_0`;
- z2: :math:`\int_0^T \sum_i u_i^2\,dt` by Gauss–Legendre quadrature on each segment, the
  torques :math:`u` from :meth:`~adept_traj.robot.Robot.inverse_dynamics`;
- z3: the clearance penalty :math:`\sum_o \max(0, 1 - d_o/\delta)^2` (default), or the
  paper's eqs. 14/16 on the tool points (:func:`~adept_traj.problem.objectives.paper_penalty`);
- z4: :math:`\min_t |\det J(q(t))|` at the samples;
- z5, z6: :math:`\sum_i \int_0^T \dddot q_i^2\,dt` and :math:`\sum_i \int_0^T \ddot q_i^2\,dt`,
  exact per spline segment.

:meth:`TrajectoryProblem.evaluate_batch` reports them as they are (z4 positive); pymoo, which
minimises, receives :func:`~adept_traj.problem.objectives.to_pymoo` of them (z4 negated).
where :math:`d_o` is the exact smallest signed distance between any robot solid and obstacle
``o`` over the motion (moving obstacles at their pose at each instant) and :math:`\delta` the
``influence`` distance. Constraints :math:`g \le 0`, normalised, in this order (5 × nq + 1):

.. math::
    g^{q}_i = \frac{\max(q_i^{\max} - \bar q_i,\ \underline q_i - q_i^{\min})}
                   {\bar q_i - \underline q_i},\quad
    g^{v}_i = \frac{\max|\dot q_i|}{VC_i} - 1,\quad g^{a}_i = \frac{\max|\ddot q_i|}{WC_i} - 1,

    g^{j}_i = \frac{\max|\dddot q_i|}{JC_i} - 1,\quad g^{u}_i = \frac{\max_k |u_i(t_k)|}{UC_i} - 1,
    \quad g^{d} = \frac{m + b - \min(\min_o d_o,\ \delta)}{\delta}

(paper eqs. 7–12; the extrema of q … q⃛ are exact per spline segment, the torque maximum is
taken at the samples, the distance constraint uses the safety margin ``m`` plus the search
buffer ``b``: the distance may dip between the samples, and the certificate, which keeps
the true margin ``m``, holds for every instant).
:func:`adept_traj.testing.reference.evaluate_reference` computes the same numbers with
plain per-sample loops and no code shared with this module: the oracle for tests and the
baseline for benchmarks. With ``workers > 1`` populations are evaluated by a
:class:`~adept_traj.problem.evaluator.ParallelEvaluator` that the problem owns.
"""

from __future__ import annotations

import copy
import multiprocessing
import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from pymoo.core.problem import Problem

from adept_traj.collision import CollisionChecker, self_collision_check
from adept_traj.errors import ConfigurationError, InputShapeError, RobotModelError
from adept_traj.problem.bspline import BSplineTrajectory
from adept_traj.problem.evaluation import Evaluation, _concatenate, _finish
from adept_traj.problem.evaluator import ParallelEvaluator
from adept_traj.problem.objectives import OBJECTIVES, paper_penalty, to_pymoo
from adept_traj.problem.time_bound import kinematic_lower_bound
from adept_traj.robot.limits import LIMITS
from adept_traj.robot.robot import Robot
from adept_traj.scene.scene import Scene
from adept_traj.scene.shapes import Box
from adept_traj.validation import as_batch, as_integer, as_scalar

__all__ = ["ProblemSettings", "TrajectoryProblem"]


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
        if self.workers > 1 and "fork" not in multiprocessing.get_all_start_methods():
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


#: Smallest chunk worth sending to a worker: populations smaller than ``2 × _MIN_CHUNK`` are
#: evaluated in this process.
_MIN_CHUNK = 8
#: Samples (individuals × samples per trajectory) evaluated together: the working arrays of
#: one block stay in the CPU cache (a whole population of 500 × 116 samples would stream
#: every intermediate array through main memory: ≈ 1.3× slower, measured). A population is
#: cut into equal blocks of 2/3 to 3/2 of this (``round(pop / (4096 // n_s))`` blocks): a
#: block has a fixed cost (≈ 2.6 ms on the paper problem, the broad phase's numpy calls per
#: solid–obstacle pair), so 50 trajectories are one block, not 35 + 15 (blocks of 8 000
#: samples and more are ≈ 2× slower per sample here: their arrays leave the 2 MB L2 cache).
_BLOCK_SAMPLES = 4096


class TrajectoryProblem(Problem):
    """The multi-objective trajectory problem (see the module docstring).

    Parameters
    ----------
    robot, scene:
        The robot and the obstacles (with the robot base pose).
    start, goal:
        Rest configurations (nq,) [rad | m], inside the joint limits.
    settings:
        :class:`ProblemSettings`; keyword arguments override its fields.
    """

    def __init__(
        self,
        robot: Robot,
        scene: Scene,
        start: Any,
        goal: Any,
        settings: ProblemSettings | None = None,
        **overrides: Any,
    ) -> None:
        settings = settings or ProblemSettings()
        if overrides:
            values = {**settings.__dict__, **overrides}
            try:
                settings = ProblemSettings(**values)
            except TypeError as exc:
                raise ConfigurationError(f"unknown problem setting: {exc}") from None
        self.robot, self.scene = robot, scene
        on, self_check, pairs = self_collision_check(
            robot, settings.self_collision, settings.disabled_pairs, settings.influence
        )
        #: The robot–robot distances (``None``: self-collision off) and their pairs.
        self.self_check, self.self_pairs = self_check, pairs
        self.settings = settings = replace(
            settings, self_collision=on, disabled_pairs=self_check.disabled if on else ()
        )
        lim = robot.limits
        if robot.task_rows is None:
            raise RobotModelError(
                f"robot '{robot.name}' has no task_rows for the manipulability objective z4: "
                "give them in its parameter file or Robot.from_urdf(..., task_rows=[...])"
            )
        self.start = lim.check_position(start, "start")
        self.goal = lim.check_position(goal, "goal")
        if np.array_equal(self.start, self.goal):
            raise ConfigurationError("start and goal are the same configuration: nothing to plan")
        if self.start.shape != (robot.nq,) or self.goal.shape != (robot.nq,):
            raise InputShapeError(f"start and goal must have shape ({robot.nq},)")
        self.trajectory = BSplineTrajectory(self.start, self.goal, n_knots=settings.n_knots)
        self.lower_bound = kinematic_lower_bound(
            self.start, self.goal, lim.velocity, lim.acceleration, lim.jerk
        )
        t_min, t_max = settings.t_bounds or (self.lower_bound.T_min, 2.5 * self.lower_bound.T_min)
        xl, xu = self.trajectory.decision_bounds(lim.lower, lim.upper, t_min, t_max)
        s, w = self.trajectory.quadrature(settings.nodes_per_segment)
        self.s = np.concatenate([[0.0], s, [1.0]])  # both ends too (weight 0)
        self.weights = np.concatenate([[0.0], w, [0.0]])
        self.checker = CollisionChecker(robot, scene, settings.influence, settings.start_time)
        super().__init__(
            n_var=self.trajectory.n_var,
            n_obj=len(OBJECTIVES),
            n_ieq_constr=5 * robot.nq + 1,
            xl=xl,
            xu=xu,
            vtype=float,
            # copies (the workers' snapshot) and pickles leave the worker pool out
            exclude_from_serialization=["_evaluator"],
        )
        self._evaluator: ParallelEvaluator | None = None

    # ------------------------------------------------------------------ public
    @property
    def constraint_names(self) -> tuple[str, ...]:
        """Names of the constraints: one per limit kind and joint, named by the kind's
        quantity (``"q[joint1]"`` … ``"tau[joint4]"``, :data:`~adept_traj.robot.LIMITS`),
        then ``"distance"``."""
        names = self.robot.joint_names
        return (*(f"{k.quantity}[{n}]" for k in LIMITS for n in names), "distance")

    def evaluate_batch(self, x: Any) -> Evaluation:
        """Evaluate a population ``x`` (pop, n_var), or one vector (n_var,).

        Returns an :class:`~adept_traj.problem.Evaluation` (objectives as reported, z4
        positive; constraints; diagnostics).
        """
        xa = as_batch(x, "x", self.n_var)
        start = time.perf_counter()
        ev = self._evaluate_batch(np.atleast_2d(xa))
        return _finish(ev, start, single=xa.ndim == 1)

    # ------------------------------------------------------------------ pymoo hook
    def _evaluate(self, x: np.ndarray, out: dict[str, Any], *args: Any, **kwargs: Any) -> None:
        ev = self._evaluate_batch(np.asarray(x, dtype=float))
        out["F"] = to_pymoo(ev.objectives)  # pymoo minimises: maximised objectives negated
        out["G"] = ev.constraints

    def close(self) -> None:
        """Stop the evaluation worker processes of ``workers > 1`` (if started) and wait for
        them; they start again, from a new snapshot, when needed. Also done on leaving a
        ``with TrajectoryProblem(...) as problem:`` block, and (without waiting) when the
        problem is garbage-collected."""
        evaluator, self._evaluator = self._evaluator, None
        if evaluator is not None:
            evaluator.close()

    def __enter__(self) -> TrajectoryProblem:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------ batched
    def _evaluate_batch(self, x: np.ndarray) -> Evaluation:
        if self.settings.workers > 1 and len(x) >= 2 * _MIN_CHUNK:
            return self._parallel_evaluator().evaluate(x)
        return self._evaluate_serial(x)

    def _parallel_evaluator(self) -> ParallelEvaluator:
        """The evaluator of ``workers > 1``, made on first use: its workers run
        :meth:`_evaluate_serial` of a shallow copy of this problem (the same robot, scene,
        checker, …, without the evaluator), so the pool does not keep the problem alive."""
        if self._evaluator is None:
            snapshot = copy.copy(self)  # pymoo's __getstate__ leaves out "_evaluator"
            self._evaluator = ParallelEvaluator(
                snapshot._evaluate_serial, self.settings.workers, self.n_var
            )
        return self._evaluator

    def _evaluate_serial(self, x: np.ndarray) -> Evaluation:
        step = max(1, _BLOCK_SAMPLES // len(self.s))  # equal blocks of at most ≈ 1.5 step
        blocks = [self._evaluate_block(b) for b in np.array_split(x, max(1, round(len(x) / step)))]
        return blocks[0] if len(blocks) == 1 else _concatenate(blocks)

    def _evaluate_block(self, x: np.ndarray) -> Evaluation:
        traj, robot, st = self.trajectory, self.robot, self.settings
        T = x[:, 0]
        smp = traj.sample(x, self.s, orders=(0, 1, 2))
        u = robot.inverse_dynamics(smp.q, smp.qd, smp.qdd)  # (pop, n_s, nq)
        z2 = T * np.einsum("k,pki->p", self.weights, u**2)
        fk = robot.forward_kinematics(smp.q)
        z4 = fk.manipulability.min(axis=-1)
        integ = traj.integrals(x)
        bounds = traj.bounds(x)
        mind = self.checker.min_distances(smp.q, smp.t, joint_frames=fk.joint_frames)
        z3 = self._z3(mind.distance, smp, fk.tool_pose)
        f = np.stack([T, z2, z3, z4, integ.z5, integ.z6], axis=-1)
        closest = mind.distance.min(axis=-1, initial=np.inf)
        n_narrow = mind.n_narrow
        if self.self_check is not None:  # robot–robot pairs: the distance constraint only
            own = self.self_check.min_distances(smp.q, fk.joint_frames, below=closest)
            closest, n_narrow = np.minimum(closest, own.distance), n_narrow + own.n_narrow
        g = self._constraints(
            bounds.q_min,
            bounds.q_max,
            [bounds.qd_abs_max, bounds.qdd_abs_max, bounds.qddd_abs_max, np.abs(u).max(axis=1)],
            closest,
        )
        return Evaluation(
            objectives=f,
            constraints=g,
            min_distance=np.minimum(mind.distance, st.influence),
            n_narrow=n_narrow,
        )

    def _z3(self, min_dist: np.ndarray, smp: Any, tool_pose: np.ndarray) -> np.ndarray:
        st = self.settings
        if st.z3 == "clearance":
            return np.sum(np.maximum(0.0, 1.0 - min_dist / st.influence) ** 2, axis=-1)
        poses = self.scene.obstacle_poses(self.checker.scene_time(smp.t), in_base_frame=True)
        return self._paper_penalty(tool_pose[..., :3, 3], poses)

    def _paper_penalty(self, tool: np.ndarray, poses: np.ndarray) -> np.ndarray:
        """Eq. 14 (``"paper-sphere"``) or eq. 16 with the obstacles' axes
        (``"paper-ellipsoid"``) on the tool points (..., n_s, 3)."""
        if self.settings.z3 == "paper-sphere":
            return paper_penalty(tool, poses[..., :3, 3], self._semi_axes(), equation=14)
        return paper_penalty(
            tool, poses[..., :3, 3], self._semi_axes(), rotations=poses[..., :3, :3], equation=16
        )

    def _semi_axes(self) -> np.ndarray:
        """Semi-axes (n_obs, 3) [m] of the circumscribing spheres/ellipsoids (eqs. 13, 15)."""
        axes = []
        for ob in self.scene.obstacles:
            if self.settings.z3 == "paper-ellipsoid" and isinstance(ob.shape, Box):
                # The smallest ellipsoid with the box's axes containing it: √3 × half sides
                # (axis-aligned in the obstacle frame; the paper's cubes are axis-aligned).
                axes.append(np.sqrt(3.0) * 0.5 * np.asarray(ob.shape.size))
            else:
                axes.append(np.full(3, ob.shape.bounding_radius))
        return np.array(axes).reshape(-1, 3)

    def _constraints(
        self,
        q_min: np.ndarray,
        q_max: np.ndarray,
        abs_max: list[np.ndarray],
        min_dist: np.ndarray,
    ) -> np.ndarray:
        lim, st = self.robot.limits, self.settings
        span = lim.upper - lim.lower
        g_q = np.maximum(q_max - lim.upper, lim.lower - q_min) / span
        scales = [lim.bound(kind.name) for kind in LIMITS[1:]]
        g_rest = [m / s - 1.0 for m, s in zip(abs_max, scales)]
        g_d = (st.margin + st.search_buffer - np.minimum(min_dist, st.influence)) / st.influence
        return np.concatenate([g_q, *g_rest, g_d[:, None]], axis=-1)
