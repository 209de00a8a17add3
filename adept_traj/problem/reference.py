"""The plain-loop reference evaluation of the trajectory problem (the tests' oracle).

:meth:`~adept_traj.problem.TrajectoryProblem.evaluate_reference` computes the same
objectives and constraints as the batched evaluation with plain per-individual, per-segment,
per-sample loops: Pinocchio (RNEA, frame Jacobians) and coal are called once per sample and
per (solid, obstacle) pair, with no broad phase, and the spline is evaluated segment by
segment with scalar formulas (``_ReferenceSpline``), not with
:mod:`~adept_traj.problem.spline_segments`. It is the oracle of the tests and the baseline
of the benchmarks, not meant to be fast.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import coal
import numpy as np
import pinocchio as pin

from adept_traj.collision import distance_request, point_signed_distance
from adept_traj.problem.evaluation import Evaluation
from adept_traj.robot.parameter_file import TASK_ROWS
from adept_traj.robot.robot import coulomb_sign, manipulability_measure
from adept_traj.scene.shapes import Sphere

if TYPE_CHECKING:
    from adept_traj.problem.trajectory_problem import TrajectoryProblem


def _evaluate_reference(problem: TrajectoryProblem, x: np.ndarray) -> Evaluation:
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
            z3 = float(problem._paper_penalty(np.array(tool_points), poses))
        objectives.append([T, z2, z3, z4, z5, z6])
        g = problem._constraints(
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
