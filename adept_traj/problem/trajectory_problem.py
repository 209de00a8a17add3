r"""The paper's trajectory problem: six objectives and 21 constraints, batched (pymoo).

:class:`TrajectoryProblem` is a :class:`pymoo.core.problem.Problem` over the decision vector
of :class:`~adept_traj.trajectory.BSplineTrajectory` (``[T, free control points]``).
For a population ``x`` (pop, n_var) it returns (pymoo minimises):

============  =======================================================================  ===========
objective     definition                                                               paper
============  =======================================================================  ===========
z1            travel time :math:`T` [s]                                                (1)
z2            :math:`\int_0^T \sum_i u_i^2\,dt` [N²·m²·s], Gauss–Legendre per segment  (2)
z3            clearance penalty :math:`\sum_o \max(0, 1 - d_o/\delta)^2` [-]           (3), 13–16
z4            :math:`\min_t |\det J(q(t))|` [m²] (entered negated: maximised)          (4)
z5            :math:`\sum_i \int_0^T \dddot q_i^2\,dt` exact [rad²/s⁵ …]               (5)
z6            :math:`\sum_i \int_0^T \ddot q_i^2\,dt` exact [rad²/s³ …]                (6)
============  =======================================================================  ===========

where :math:`d_o` is the exact smallest signed distance between any robot solid and obstacle
``o`` over the motion (moving obstacles at their pose at each instant) and :math:`\delta` the
``influence`` distance. Constraints :math:`g \le 0`, normalised, in this order (5 × nq + 1):

.. math::
    g^{q}_i = \frac{\max(q_i^{\max} - \bar q_i,\ \underline q_i - q_i^{\min})}
                   {\bar q_i - \underline q_i},\quad
    g^{v}_i = \frac{\max|\dot q_i|}{VC_i} - 1,\quad g^{a}_i = \frac{\max|\ddot q_i|}{WC_i} - 1,

    g^{j}_i = \frac{\max|\dddot q_i|}{JC_i} - 1,\quad g^{u}_i = \frac{\max_k |u_i(t_k)|}{UC_i} - 1,
    \quad g^{d} = \frac{m - \min(\min_o d_o,\ \delta)}{\delta}

(paper eqs. 7–12; the extrema of q … q⃛ are exact per spline segment, the torque maximum is
taken at the samples, the distance constraint uses the safety margin ``m``).
:meth:`TrajectoryProblem.evaluate_reference` computes the same numbers with plain
per-sample loops (Pinocchio and coal called once per sample and pair): the oracle for tests
and the baseline for benchmarks.
"""

from __future__ import annotations

import multiprocessing
import signal
import time
import weakref
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

import coal
import numpy as np
import pinocchio as pin
from pymoo.core.problem import Problem

from adept_traj.collision import distance_request
from adept_traj.collision.checker import CollisionChecker, point_signed_distance
from adept_traj.errors import ConfigurationError, InputShapeError, RobotModelError
from adept_traj.problem.bspline import BSplineTrajectory, kinematic_lower_bound
from adept_traj.problem.objectives import paper_penalty
from adept_traj.robot.parameter_file import TASK_ROWS
from adept_traj.robot.robot import Robot, coulomb_sign, manipulability_measure
from adept_traj.scene.scene import Scene
from adept_traj.scene.shapes import Box, Sphere
from adept_traj.validation import as_batch

__all__ = ["OBJECTIVE_NAMES", "Evaluation", "ProblemSettings", "TrajectoryProblem"]

#: Names of the objectives, in order.
OBJECTIVE_NAMES = ("z1", "z2", "z3", "z4", "z5", "z6")
_KINDS = ("q", "qd", "qdd", "qddd", "u")


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
        Safety distance [m]: the constraint is :math:`\\min_o d_o \\ge` margin.
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
        With ``workers > 1`` the population is split into contiguous chunks evaluated by
        forked worker processes (Linux); results are identical to the serial evaluation.
        The workers are forked when first needed and hold a snapshot of the problem (later
        edits of ``robot.model`` are not seen by them); :meth:`TrajectoryProblem.close`
        stops them.
    """

    n_knots: int = 20
    nodes_per_segment: int = 6
    margin: float = 0.01
    influence: float = 0.05
    t_bounds: tuple[float, float] | None = None
    z3: str = "clearance"
    workers: int = 1

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
        if isinstance(self.workers, bool) or not isinstance(self.workers, int) or self.workers < 1:
            raise ConfigurationError(f"workers must be an integer ≥ 1; got {self.workers!r}")
        if self.workers > 1 and "fork" not in multiprocessing.get_all_start_methods():
            raise ConfigurationError("workers > 1 needs the 'fork' start method (Linux)")
        n = self.nodes_per_segment
        if isinstance(n, bool) or not isinstance(n, int) or n < 1:
            raise ConfigurationError(f"nodes_per_segment must be an integer ≥ 1; got {n!r}")
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


@dataclass(frozen=True)
class Evaluation:
    """Objectives, constraints and diagnostics of a population.

    Attributes
    ----------
    objectives: (pop, 6) z1…z6 with z4 **positive** (as reported).
    constraints: (pop, 5·nq + 1) normalised g (feasible where all ≤ 0).
    min_distance: (pop, n_obstacles) smallest distance to each obstacle [m], clipped at
        ``influence`` (beyond it only a lower bound is known).
    n_narrow: coal distance calls made.
    seconds: wall time of the evaluation [s].
    """

    objectives: np.ndarray
    constraints: np.ndarray
    min_distance: np.ndarray
    n_narrow: int = 0
    seconds: float = 0.0

    @property
    def feasible(self) -> np.ndarray:
        """(pop,) bool: every constraint satisfied (at the evaluation's resolution)."""
        return np.all(self.constraints <= 0.0, axis=-1)


#: Problems shared with forked evaluation workers (looked up by id in the child). Weak: a
#: problem that is no longer used is collected, and its workers stop (``weakref.finalize``).
_REGISTRY: weakref.WeakValueDictionary[int, TrajectoryProblem] = weakref.WeakValueDictionary()
#: Smallest chunk worth sending to a worker.
_MIN_CHUNK = 8
#: Samples (individuals × samples per trajectory) evaluated together: the working arrays of
#: one block stay in the CPU cache (a whole population of 500 × 116 samples would stream
#: every intermediate array through main memory: ≈ 1.3× slower, measured).
_BLOCK_SAMPLES = 4096


def _worker_init() -> None:
    """Workers leave Ctrl-C to the parent, which checkpoints and stops the run."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _worker_evaluate(key: int, x: np.ndarray) -> Evaluation:
    return _REGISTRY[key]._evaluate_serial(x)


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
        self.robot, self.scene, self.settings = robot, scene, settings
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
        t_min, t_max = settings.t_bounds or (
            self.lower_bound.T_min,
            2.5 * self.lower_bound.T_min,
        )
        xl, xu = self.trajectory.decision_bounds(lim.lower, lim.upper, t_min, t_max)
        s, w = self.trajectory.quadrature(settings.nodes_per_segment)
        self.s = np.concatenate([[0.0], s, [1.0]])  # both ends too (weight 0)
        self.weights = np.concatenate([[0.0], w, [0.0]])
        self.checker = CollisionChecker(robot, scene, influence=settings.influence)
        super().__init__(
            n_var=self.trajectory.n_var,
            n_obj=6,
            n_ieq_constr=5 * robot.nq + 1,
            xl=xl,
            xu=xu,
            vtype=float,
        )

    # ------------------------------------------------------------------ public
    @property
    def constraint_names(self) -> tuple[str, ...]:
        """Names of the constraints, e.g. ``"qd[joint2]"``, then ``"distance"``."""
        names = self.robot.joint_names
        return (*(f"{k}[{n}]" for k in _KINDS for n in names), "distance")

    def evaluate_batch(self, x: Any) -> Evaluation:
        """Evaluate a population ``x`` (pop, n_var), or one vector (n_var,).

        Returns an :class:`Evaluation` (objectives with z4 positive, constraints, diagnostics).
        """
        xa = as_batch(x, "x", self.n_var)
        start = time.perf_counter()
        ev = self._evaluate_batch(np.atleast_2d(xa))
        return _finish(ev, start, single=xa.ndim == 1)

    def evaluate_reference(self, x: Any) -> Evaluation:
        """The same as :meth:`evaluate_batch` with plain per-individual, per-sample loops."""
        xa = as_batch(x, "x", self.n_var)
        start = time.perf_counter()
        ev = self._evaluate_reference(np.atleast_2d(xa))
        return _finish(ev, start, single=xa.ndim == 1)

    # ------------------------------------------------------------------ pymoo hook
    def _evaluate(self, x: np.ndarray, out: dict[str, Any], *args: Any, **kwargs: Any) -> None:
        ev = self._evaluate_batch(np.asarray(x, dtype=float))
        f = ev.objectives.copy()
        f[:, 3] = -f[:, 3]  # pymoo minimises; z4 is maximised
        out["F"] = f
        out["G"] = ev.constraints

    def close(self) -> None:
        """Stop the evaluation worker processes of ``workers > 1`` (if started); they start
        again when needed. Also done when the problem is garbage-collected, or on leaving a
        ``with TrajectoryProblem(...) as problem:`` block."""
        pool = self.__dict__.pop("_pool", None)
        if pool is not None:
            self.__dict__.pop("_pool_finalizer").detach()
            pool.shutdown(wait=True, cancel_futures=True)
        _REGISTRY.pop(id(self), None)

    def __enter__(self) -> TrajectoryProblem:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ------------------------------------------------------------------ batched
    def _evaluate_batch(self, x: np.ndarray) -> Evaluation:
        workers = self.settings.workers
        if workers > 1 and len(x) >= 2 * _MIN_CHUNK:
            return self._evaluate_parallel(x, workers)
        return self._evaluate_serial(x)

    def _evaluate_parallel(self, x: np.ndarray, workers: int) -> Evaluation:
        pool = self.__dict__.get("_pool")
        if pool is None:
            _REGISTRY[id(self)] = self
            pool = ProcessPoolExecutor(
                max_workers=workers,
                mp_context=multiprocessing.get_context("fork"),
                initializer=_worker_init,
            )
            self.__dict__["_pool"] = pool
            self.__dict__["_pool_finalizer"] = weakref.finalize(
                self, pool.shutdown, wait=False, cancel_futures=True
            )
        chunks = np.array_split(x, workers)
        futures = [pool.submit(_worker_evaluate, id(self), c) for c in chunks if len(c)]
        try:
            parts = [f.result() for f in futures]
        except BaseException:
            for f in futures:
                f.cancel()
            raise
        return _concatenate(parts)

    def _evaluate_serial(self, x: np.ndarray) -> Evaluation:
        step = max(1, _BLOCK_SAMPLES // len(self.s))
        if len(x) <= step:
            return self._evaluate_block(x)
        return _concatenate([self._evaluate_block(x[i : i + step]) for i in range(0, len(x), step)])

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
        g = self._constraints(
            bounds.q_min,
            bounds.q_max,
            [bounds.qd_abs_max, bounds.qdd_abs_max, bounds.qddd_abs_max, np.abs(u).max(axis=1)],
            mind.distance.min(axis=-1, initial=np.inf),
        )
        return Evaluation(
            objectives=f,
            constraints=g,
            min_distance=np.minimum(mind.distance, st.influence),
            n_narrow=mind.n_narrow,
        )

    def _z3(self, min_dist: np.ndarray, smp: Any, tool_pose: np.ndarray) -> np.ndarray:
        st = self.settings
        if st.z3 == "clearance":
            return np.sum(np.maximum(0.0, 1.0 - min_dist / st.influence) ** 2, axis=-1)
        poses = self.scene.obstacle_poses(smp.t, in_base_frame=True)  # (n_obs, pop, n_s, 4, 4)
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
        scales = [lim.velocity, lim.acceleration, lim.jerk, lim.effort]
        g_rest = [m / s - 1.0 for m, s in zip(abs_max, scales)]
        g_d = (st.margin - np.minimum(min_dist, st.influence)) / st.influence
        return np.concatenate([g_q, *g_rest, g_d[:, None]], axis=-1)

    # ------------------------------------------------------------------ reference
    def _evaluate_reference(self, x: np.ndarray) -> Evaluation:
        """Plain loops: per individual, per segment, per sample, per pair."""
        robot, model, st = self.robot, self.robot.model, self.settings
        data = model.createData()
        gm = robot.collision_model
        gdata = gm.createData()
        tool_id = model.getFrameId(robot.tool_frame)
        rows = [TASK_ROWS.index(r) for r in robot.task_rows]
        obstacle_geoms = [ob.shape.to_coal() for ob in self.scene.obstacles]
        solid_shapes = self.checker.solid_shapes
        req = distance_request()  # the checker's coal settings (GJK tolerance)
        n_obs = len(obstacle_geoms)
        objectives, constraints, min_distances = [], [], []
        for xi in x:
            T, P = self.trajectory.decode(xi)
            T = float(T)
            ref = _ReferenceSpline(P, T)
            z2 = z5 = z6 = 0.0
            z4 = np.inf
            u_max = np.zeros(robot.nq)
            d_obs = np.full(n_obs, np.inf)
            tool_points, obs_poses = [], []
            for s, w in zip(self.s, self.weights):
                q, qd, qdd = ref.evaluate(s)
                u = pin.rnea(model, data, q, qd, qdd) + model.damping * qd
                u = u + model.friction * coulomb_sign(qd)
                z2 += T * w * float(u @ u)
                u_max = np.maximum(u_max, np.abs(u))
                jac = pin.computeFrameJacobian(model, data, q, tool_id, pin.LOCAL_WORLD_ALIGNED)
                z4 = min(z4, float(manipulability_measure(jac[rows])))
                pin.updateGeometryPlacements(model, data, gm, gdata, q)
                tool_points.append(data.oMf[tool_id].translation.copy())
                poses = self.scene.obstacle_poses(np.array([s * T]), in_base_frame=True)[:, 0]
                obs_poses.append(poses)
                for o, ob in enumerate(self.scene.obstacles):
                    tf_o = coal.Transform3s(poses[o, :3, :3], poses[o, :3, 3])
                    for k, g in enumerate(gm.geometryObjects):
                        placement = gdata.oMg[k]
                        if isinstance(ob.shape, Sphere) and solid_shapes[k] is not None:
                            # Closed form, as documented (coal 3.0.3 misjudges a sphere's
                            # penetration depth near a cylinder cap).
                            centre = placement.rotation.T @ (
                                poses[o, :3, 3] - placement.translation
                            )
                            d = (
                                float(point_signed_distance(solid_shapes[k], centre))
                                - ob.shape.radius
                            )
                        else:
                            res = coal.DistanceResult()
                            tf_g = coal.Transform3s(placement.rotation, placement.translation)
                            d = coal.distance(g.geometry, tf_g, obstacle_geoms[o], tf_o, req, res)
                        d_obs[o] = min(d_obs[o], d)
            extrema = ref.extrema()
            z5, z6 = extrema["jerk_sq"], extrema["acc_sq"]
            if st.z3 == "clearance":
                z3 = float(np.sum(np.maximum(0.0, 1.0 - d_obs / st.influence) ** 2))
            else:
                poses = np.array(obs_poses).transpose(1, 0, 2, 3)  # (n_obs, n_s, 4, 4)
                z3 = float(self._paper_penalty(np.array(tool_points), poses))
            objectives.append([T, z2, z3, z4, z5, z6])
            g = self._constraints(
                extrema["q_min"][None],
                extrema["q_max"][None],
                [extrema["qd"][None], extrema["qdd"][None], extrema["qddd"][None], u_max[None]],
                np.array([d_obs.min(initial=np.inf)]),
            )[0]
            constraints.append(g)
            min_distances.append(np.minimum(d_obs, st.influence))
        return Evaluation(
            objectives=np.array(objectives),
            constraints=np.array(constraints),
            min_distance=np.array(min_distances).reshape(len(x), n_obs),
        )


def _concatenate(parts: list[Evaluation]) -> Evaluation:
    """One evaluation of the stacked populations of ``parts``."""
    return Evaluation(
        objectives=np.concatenate([e.objectives for e in parts]),
        constraints=np.concatenate([e.constraints for e in parts]),
        min_distance=np.concatenate([e.min_distance for e in parts]),
        n_narrow=sum(e.n_narrow for e in parts),
    )


def _finish(ev: Evaluation, start: float, single: bool) -> Evaluation:
    seconds = time.perf_counter() - start
    if single:
        return Evaluation(
            objectives=ev.objectives[0],
            constraints=ev.constraints[0],
            min_distance=ev.min_distance[0],
            n_narrow=ev.n_narrow,
            seconds=seconds,
        )
    return Evaluation(ev.objectives, ev.constraints, ev.min_distance, ev.n_narrow, seconds)


class _ReferenceSpline:
    """One trajectory evaluated the plain way: per segment, scalar formulas (reference)."""

    _M = np.array([[-1, 3, -3, 1], [3, -6, 3, 0], [-3, 0, 3, 0], [1, 4, 1, 0]]) / 6.0

    def __init__(self, P: np.ndarray, T: float) -> None:
        self.P, self.T = P, T
        self.S = P.shape[0] - 3
        self.rate = self.S / T

    def _coeffs(self, j: int) -> np.ndarray:
        return self._M @ self.P[j : j + 4]  # (4, nq): u³, u², u, 1

    def evaluate(self, s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        j = min(int(s * self.S), self.S - 1)
        u = s * self.S - j
        c3, c2, c1, c0 = self._coeffs(j)
        q = ((c3 * u + c2) * u + c1) * u + c0
        qd = (3 * c3 * u * u + 2 * c2 * u + c1) * self.rate
        qdd = (6 * c3 * u + 2 * c2) * self.rate**2
        return q, qd, qdd

    def extrema(self) -> dict[str, Any]:
        nq = self.P.shape[1]
        q_min, q_max = np.full(nq, np.inf), np.full(nq, -np.inf)
        qd, qdd, qddd = np.zeros(nq), np.zeros(nq), np.zeros(nq)
        acc_sq = jerk_sq = 0.0
        r = self.rate
        for j in range(self.S):
            c3, c2, c1, c0 = self._coeffs(j)
            for i in range(nq):
                cands = [0.0, 1.0]
                poly = [3 * c3[i], 2 * c2[i], c1[i]]
                roots = np.roots(poly) if any(poly) else []
                cands += [z.real for z in roots if abs(z.imag) < 1e-12 and 0 < z.real < 1]
                for u in cands:
                    value = ((c3[i] * u + c2[i]) * u + c1[i]) * u + c0[i]
                    q_min[i], q_max[i] = min(q_min[i], value), max(q_max[i], value)
                vcands = [0.0, 1.0]
                if c3[i] != 0 and 0.0 < -c2[i] / (3 * c3[i]) < 1.0:
                    vcands.append(-c2[i] / (3 * c3[i]))
                for u in vcands:
                    qd[i] = max(qd[i], abs((3 * c3[i] * u * u + 2 * c2[i] * u + c1[i]) * r))
                for u in (0.0, 1.0):
                    qdd[i] = max(qdd[i], abs((6 * c3[i] * u + 2 * c2[i]) * r**2))
                qddd[i] = max(qddd[i], abs(6 * c3[i] * r**3))
                a, b = 6 * c3[i], 2 * c2[i]
                acc_sq += (a * a / 3 + a * b + b * b) * r**3
                jerk_sq += a * a * r**5
        return {
            "q_min": q_min,
            "q_max": q_max,
            "qd": qd,
            "qdd": qdd,
            "qddd": qddd,
            "acc_sq": acc_sq,
            "jerk_sq": jerk_sq,
        }
