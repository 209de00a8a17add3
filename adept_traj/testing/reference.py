"""The plain-loop reference evaluation of the trajectory problem (the tests' oracle).

:func:`evaluate_reference` computes the same objectives and constraints as
:meth:`~adept_traj.problem.TrajectoryProblem.evaluate_batch` with plain per-individual,
per-segment, per-sample loops: Pinocchio (RNEA, frame Jacobians) and coal are called once per
sample and per (solid, obstacle) pair, with no broad phase; the spline is evaluated segment
by segment with scalar formulas (``_ReferenceSpline``), not with
:mod:`~adept_traj.problem.spline_segments`; the constraints (paper (7)–(12)) and the
circumscribing volumes of the paper's penalty (eqs. 13, 15) are written out here again. It
shares no evaluation code with the batched problem, which makes it the oracle of the tests
and the baseline of the benchmarks; it is not meant to be fast.
"""

from __future__ import annotations

import time
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from adept_traj.collision import distance_request, point_signed_distance
from adept_traj.problem import Evaluation, TrajectoryProblem, paper_penalty
from adept_traj.robot import LIMITS, TASK_ROWS, coulomb_sign, manipulability_measure
from adept_traj.scene import Box, Sphere
from adept_traj.validation import as_batch, check_type

__all__ = ["evaluate_reference"]


def evaluate_reference(problem: TrajectoryProblem, x: Any) -> Evaluation:
    """Objectives and constraints of ``x`` by plain loops (see the module docstring).

    Parameters
    ----------
    problem: the trajectory problem (its robot, scene, settings, trajectory and samples).
    x: (pop, n_var) decision vectors, or one (n_var,).

    Returns
    -------
    :class:`~adept_traj.problem.Evaluation` like ``problem.evaluate_batch(x)`` (rows for a
    population; no population axis for a single vector), with its wall time.
    """
    check_type(problem, TrajectoryProblem, "problem")
    xa = as_batch(x, "x", problem.n_var)
    start = time.perf_counter()
    ev = _evaluate(problem, np.atleast_2d(xa))
    seconds = time.perf_counter() - start
    if xa.ndim == 1:
        return Evaluation(ev.objectives[0], ev.constraints[0], ev.min_distance[0], 0, seconds)
    return Evaluation(ev.objectives, ev.constraints, ev.min_distance, 0, seconds)


def _semi_axes(problem: TrajectoryProblem) -> np.ndarray:
    """Semi-axes (n_obs, 3) [m] of the paper's circumscribing volumes: a sphere of the
    shape's bounding radius (eq. 13), or for a box with ``"paper-ellipsoid"`` the smallest
    ellipsoid with the box's axes, √3 × the half sides (eq. 15)."""
    axes = []
    for ob in problem.scene.obstacles:
        if problem.settings.z3 == "paper-ellipsoid" and isinstance(ob.shape, Box):
            axes.append(np.sqrt(3.0) * 0.5 * np.asarray(ob.shape.size))
        else:
            axes.append(np.full(3, ob.shape.bounding_radius))
    return np.array(axes).reshape(-1, 3)


def _constraints(
    problem: TrajectoryProblem, extrema: dict[str, Any], tau_max: np.ndarray, d_min: float
) -> np.ndarray:
    """The 5·nq + 1 normalised constraints g ≤ 0 (paper (7)–(12)), written out."""
    lim, st = problem.robot.limits, problem.settings
    span = lim.upper - lim.lower
    g = [np.maximum(extrema["q_max"] - lim.upper, lim.lower - extrema["q_min"]) / span]
    peaks = {"qd": extrema["qd"], "qdd": extrema["qdd"], "qddd": extrema["qddd"], "tau": tau_max}
    for kind in LIMITS[1:]:
        g.append(peaks[kind.quantity] / lim.bound(kind.name) - 1.0)
    g.append(np.array([(st.margin - min(d_min, st.influence)) / st.influence]))
    return np.concatenate(g)


def _evaluate(problem: TrajectoryProblem, x: np.ndarray) -> Evaluation:
    """Plain loops: per individual, per segment, per sample, per pair (``x`` (pop, n_var))."""
    robot, model, st = problem.robot, problem.robot.model, problem.settings
    data = model.createData()
    gm = robot.collision_model
    gdata = gm.createData()
    tool_id = model.getFrameId(robot.tool_frame)
    rows = [TASK_ROWS.index(r) for r in robot.task_rows]
    obstacle_geoms = [ob.shape.to_coal() for ob in problem.scene.obstacles]
    solid_shapes = problem.checker.solid_shapes
    req = distance_request()  # the checker's coal settings (GJK tolerance)
    n_obs = len(obstacle_geoms)
    objectives, constraints, min_distances = [], [], []
    for xi in x:
        T, P = problem.trajectory.decode(xi)
        T = float(T)
        ref = _ReferenceSpline(P, T)
        z2 = z5 = z6 = 0.0
        z4 = np.inf
        u_max = np.zeros(robot.nq)
        d_obs = np.full(n_obs, np.inf)
        tool_points, obs_poses = [], []
        for s, w in zip(problem.s, problem.weights):
            q, qd, qdd = ref.evaluate(s)
            u = pin.rnea(model, data, q, qd, qdd) + model.damping * qd
            u = u + model.friction * coulomb_sign(qd)
            z2 += T * w * float(u @ u)
            u_max = np.maximum(u_max, np.abs(u))
            jac = pin.computeFrameJacobian(model, data, q, tool_id, pin.LOCAL_WORLD_ALIGNED)
            z4 = min(z4, float(manipulability_measure(jac[rows])))
            pin.updateGeometryPlacements(model, data, gm, gdata, q)
            tool_points.append(data.oMf[tool_id].translation.copy())
            poses = problem.scene.obstacle_poses(np.array([s * T]), in_base_frame=True)[:, 0]
            obs_poses.append(poses)
            for o, ob in enumerate(problem.scene.obstacles):
                tf_o = coal.Transform3s(poses[o, :3, :3], poses[o, :3, 3])
                for k, g in enumerate(gm.geometryObjects):
                    placement = gdata.oMg[k]
                    if isinstance(ob.shape, Sphere) and solid_shapes[k] is not None:
                        # Closed form, as documented (coal 3.0.3 misjudges a sphere's
                        # penetration depth near a cylinder cap).
                        centre = placement.rotation.T @ (poses[o, :3, 3] - placement.translation)
                        d = float(point_signed_distance(solid_shapes[k], centre)) - ob.shape.radius
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
            rotations = None if st.z3 == "paper-sphere" else poses[..., :3, :3]
            z3 = float(
                paper_penalty(
                    np.array(tool_points),
                    poses[..., :3, 3],
                    _semi_axes(problem),
                    rotations=rotations,
                    equation=14 if st.z3 == "paper-sphere" else 16,
                )
            )
        objectives.append([T, z2, z3, z4, z5, z6])
        constraints.append(_constraints(problem, extrema, u_max, d_obs.min(initial=np.inf)))
        min_distances.append(np.minimum(d_obs, st.influence))
    return Evaluation(
        objectives=np.array(objectives),
        constraints=np.array(constraints),
        min_distance=np.array(min_distances).reshape(len(x), n_obs),
    )


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
