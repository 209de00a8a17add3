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
import time
from dataclasses import fields, replace
from typing import Any

import numpy as np
from pymoo.core.problem import Problem

from adept_traj.collision import CollisionChecker, self_collision_check
from adept_traj.collision.joint_tables import kept_tables
from adept_traj.errors import ConfigurationError, InputShapeError, RobotModelError
from adept_traj.problem.bspline import BSplineTrajectory
from adept_traj.problem.evaluation import Evaluation, concatenate_evaluations, timed_evaluation
from adept_traj.problem.evaluator import ParallelEvaluator
from adept_traj.problem.objectives import OBJECTIVES, paper_penalty, paper_semi_axes, to_pymoo
from adept_traj.problem.problem_settings import ProblemSettings
from adept_traj.problem.time_bound import kinematic_lower_bound
from adept_traj.robot.limits import LIMITS
from adept_traj.robot.robot import Robot
from adept_traj.scene.scene import Scene
from adept_traj.validation import (
    DerivedData,
    FrozenAttributes,
    as_batch,
    readonly_copy,
)

__all__ = ["TrajectoryProblem"]


#: Smallest chunk worth sending to a worker: populations smaller than ``2 × _MIN_CHUNK`` are
#: evaluated in this process.
_MIN_CHUNK = 8
#: Samples (individuals × samples per trajectory) evaluated together: the working arrays of
#: one block stay in the CPU cache (a whole population of 500 × 116 samples would stream
#: every intermediate array through main memory, measured slower). A population is
#: cut into equal blocks of 2/3 to 3/2 of this (``round(pop / (4096 // n_s))`` blocks): a
#: block has a fixed cost (the broad phase's numpy calls per solid–obstacle pair), so 50
#: trajectories are one block, not 35 + 15 (blocks of 8 000 samples and more were slower
#: per sample here: their arrays leave the 2 MB L2 cache).
_BLOCK_SAMPLES = 4096

#: The parts a problem is made from, as :meth:`TrajectoryProblem.replace` takes them.
_PARTS = ("robot", "scene", "start", "goal", "settings")


class TrajectoryProblem(FrozenAttributes, DerivedData, Problem):
    """The multi-objective trajectory problem (see the module docstring).

    Parameters
    ----------
    robot, scene:
        The robot and the obstacles (with the robot base pose).
    start, goal:
        Rest configurations (nq,) [rad | m], inside the joint limits.
    settings:
        :class:`ProblemSettings`; keyword arguments override its fields.

    The problem is frozen: its settings, robot, scene, start and goal, and everything
    derived from them (the trajectory, the checker, the bounds ``xl``/``xu``, the samples
    ``s``), are fixed at construction (setting one raises
    :class:`~adept_traj.errors.FrozenObjectError`; :meth:`replace` makes a changed copy),
    and its arrays are read-only copies (the caller's ``start`` and ``goal`` are neither
    kept nor changed). Data derived from the problem alone is made once and kept on it
    (:meth:`derived`).
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
        self._build(robot, scene, start, goal, settings, overrides, None)

    def _build(
        self,
        robot: Robot,
        scene: Scene,
        start: Any,
        goal: Any,
        settings: ProblemSettings | None,
        overrides: dict[str, Any],
        tables: Any,
    ) -> None:
        """The constructor's work; ``tables``: the checker's distance tables already made
        (:func:`~adept_traj.collision.joint_tables.kept_tables`, from :meth:`replace`),
        or ``None``."""
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
        self.start = readonly_copy(lim.check_position(start, "start"))
        self.goal = readonly_copy(lim.check_position(goal, "goal"))
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
        self.s = readonly_copy(np.concatenate([[0.0], s, [1.0]]))  # both ends too (weight 0)
        self.weights = readonly_copy(np.concatenate([[0.0], w, [0.0]]))
        self.checker = CollisionChecker(
            robot, scene, settings.influence, settings.start_time, tables=tables
        )
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
        self.xl.setflags(write=False)  # pymoo's float copies of xl, xu
        self.xu.setflags(write=False)
        self._evaluator: ParallelEvaluator | None = None
        self._derived: dict[str, Any] = {}
        self._freeze()

    def replace(self, **changes: Any) -> TrajectoryProblem:
        """A new problem with some of this one's parts changed (``dataclasses.replace``
        for the frozen problem).

        Parameters
        ----------
        **changes:
            ``robot``, ``scene``, ``start``, ``goal`` (nq,) [rad | m], ``settings`` (a
            :class:`ProblemSettings`; default: this problem's, as it resolved them:
            ``self_collision`` and ``disabled_pairs`` included, so give new settings
            with a new robot), and any field of :class:`ProblemSettings` (e.g.
            ``margin=0.02``), which overrides the settings.

        Returns
        -------
        TrajectoryProblem
            Built anew from the changed parts (no worker pool), except the collision
            checker's single-joint distance tables of an unchanged robot and of the
            obstacles both scenes hold (the same objects, the same base pose), which are
            taken over: their values depend on nothing else.

        Raises
        ------
        ConfigurationError
            An unknown name, or a bad setting.
        """
        parts = {k: changes.pop(k, getattr(self, k)) for k in _PARTS}
        unknown = sorted(set(changes) - {f.name for f in fields(ProblemSettings)})
        if unknown:
            raise ConfigurationError(
                f"replace() takes {', '.join(_PARTS)} or ProblemSettings fields; got {unknown}"
            )
        new = TrajectoryProblem.__new__(TrajectoryProblem)
        tables = kept_tables(self.checker, parts["robot"], parts["scene"])
        new._build(*(parts[k] for k in _PARTS), changes, tables)
        return new

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
        return timed_evaluation(ev, start, single=xa.ndim == 1)

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
        return blocks[0] if len(blocks) == 1 else concatenate_evaluations(blocks)

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
            return paper_penalty(
                tool,
                poses[..., :3, 3],
                paper_semi_axes(self.scene.obstacles, self.settings.z3),
                equation=14,
            )
        return paper_penalty(
            tool,
            poses[..., :3, 3],
            paper_semi_axes(self.scene.obstacles, self.settings.z3),
            rotations=poses[..., :3, :3],
            equation=16,
        )

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
