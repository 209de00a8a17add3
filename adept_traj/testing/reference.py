"""The plain-loop reference evaluation of the trajectory problem (the tests' oracle).

:func:`evaluate_reference` computes the same objectives and constraints as
:meth:`~adept_traj.problem.TrajectoryProblem.evaluate_batch` with plain per-individual,
per-segment, per-sample loops: Pinocchio (RNEA, frame Jacobians) and coal are called once per
sample and per (solid, obstacle) pair, with no broad phase; the spline is evaluated segment
by segment with scalar formulas (``_ReferenceSpline``), not with
:mod:`~adept_traj.problem.spline_segments`; the constraints (paper (7)–(12)) are written
out here again (the circumscribing volumes of the paper's penalty, eqs. 13 and 15, are the
problem's definition, :func:`~adept_traj.problem.paper_semi_axes`, which the tests check
against the closed form). It
shares no evaluation code with the batched problem — the Coulomb sign, the manipulability
measure, the closed-form point distances of sphere obstacles and the paper's penalty are
written out here too, scalar, one sample at a time — which makes it the oracle of the tests
and the baseline of the benchmarks; it is not meant to be fast. What it shares with the
batched path are the libraries (Pinocchio's RNEA and Jacobians, coal's distances), the
problem's samples and its settings.
"""

from __future__ import annotations

import math
import time
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from adept_traj.collision import distance_request
from adept_traj.problem import Evaluation, TrajectoryProblem, paper_semi_axes
from adept_traj.robot import LIMITS, TASK_ROWS, VELOCITY_AT_REST
from adept_traj.scene import Box, Capsule, Cylinder, Sphere
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


def _coulomb_sign(v: float) -> float:
    """sign(v), 0 at rest (|v| ≤ VELOCITY_AT_REST), one joint at a time."""
    return 0.0 if abs(v) <= VELOCITY_AT_REST else math.copysign(1.0, v)


def _manipulability(jt: np.ndarray) -> float:
    """Yoshikawa's measure of a task Jacobian (m, n) with numpy's LU determinant."""
    m, n = jt.shape
    if m == n:
        return abs(float(np.linalg.det(jt)))
    gram = jt @ jt.T if m < n else jt.T @ jt
    return math.sqrt(max(float(np.linalg.det(gram)), 0.0))


def _point_to_solid(shape: Any, p: np.ndarray) -> float:
    """Signed distance [m] of one point p (3,), in the solid's frame, to the solid (box,
    cylinder or capsule along z, sphere), from the nearest point written case by case."""
    x, y, z = (float(c) for c in p)
    if isinstance(shape, Sphere):
        return math.sqrt(x * x + y * y + z * z) - shape.radius
    if isinstance(shape, Capsule):
        half = 0.5 * shape.length
        zc = min(max(z, -half), half)
        return math.sqrt(x * x + y * y + (z - zc) ** 2) - shape.radius
    if isinstance(shape, Cylinder):
        r, half = math.hypot(x, y), 0.5 * shape.length
        dr, dz = r - shape.radius, abs(z) - half
        if dr <= 0.0 and dz <= 0.0:  # inside: to the nearer of the side and the caps
            return max(dr, dz)
        return math.hypot(max(dr, 0.0), max(dz, 0.0))
    if isinstance(shape, Box):
        half = 0.5 * np.asarray(shape.size, dtype=float)
        e = np.abs([x, y, z]) - half
        if (e <= 0.0).all():
            return float(e.max())
        return math.sqrt(sum(max(v, 0.0) ** 2 for v in e))
    raise TypeError(f"no point distance for {type(shape).__name__}")


def _paper_penalty(
    tool: np.ndarray, centres: np.ndarray, axes: np.ndarray, rotations: np.ndarray | None
) -> float:
    """The paper's penalty (eqs. 13–16) by plain loops: tool (n_s, 3), centres (n_obs, n_s,
    3), semi-axes (n_obs, 3), rotations (n_obs, n_s, 3, 3) or None (eq. 14 on spheres)."""
    total = 0.0
    for o in range(len(axes)):
        closest = math.inf
        for k in range(len(tool)):
            d = tool[k] - centres[o, k]
            if rotations is None:
                r = math.sqrt(float(d @ d))  # eq. 14: r_t = ||x − x0||, inside when r ≤ r0
                inside = r <= axes[o, 0]
            else:
                u = rotations[o, k].T @ d  # eq. 16 in the obstacle's own axes
                r = max(float(np.sum(u * u / (axes[o] * axes[o]))), 1e-12)
                inside = r <= 1.0
            if inside:
                closest = min(closest, r)
        if math.isfinite(closest):
            total += 1.0 / max(closest, 1e-12) ** 2
    return total


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
    required = st.margin + st.search_buffer  # the search asks the margin plus its buffer
    g.append(np.array([(required - min(d_min, st.influence)) / st.influence]))
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
        tau_max = np.zeros(robot.nq)
        d_obs = np.full(n_obs, np.inf)
        tool_points, obs_poses = [], []
        for s, w in zip(problem.s, problem.weights):
            q, qd, qdd = ref.evaluate(s)
            tau = pin.rnea(model, data, q, qd, qdd) + model.damping * qd
            tau = tau + model.friction * np.array([_coulomb_sign(v) for v in qd])
            z2 += T * w * float(tau @ tau)
            tau_max = np.maximum(tau_max, np.abs(tau))
            jac = pin.computeFrameJacobian(model, data, q, tool_id, pin.LOCAL_WORLD_ALIGNED)
            z4 = min(z4, _manipulability(jac[rows]))
            pin.updateGeometryPlacements(model, data, gm, gdata, q)
            tool_points.append(data.oMf[tool_id].translation.copy())
            scene_t = st.start_time + s * T  # the move starts at scene time t0
            poses = problem.scene.obstacle_poses(np.array([scene_t]), in_base_frame=True)[:, 0]
            obs_poses.append(poses)
            for o, ob in enumerate(problem.scene.obstacles):
                tf_o = coal.Transform3s(poses[o, :3, :3], poses[o, :3, 3])
                for k, g in enumerate(gm.geometryObjects):
                    placement = gdata.oMg[k]
                    if isinstance(ob.shape, Sphere) and solid_shapes[k] is not None:
                        # Closed form, as documented (coal 3.0.3 misjudges a sphere's
                        # penetration depth near a cylinder cap).
                        centre = placement.rotation.T @ (poses[o, :3, 3] - placement.translation)
                        d = _point_to_solid(solid_shapes[k], centre) - ob.shape.radius
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
            z3 = _paper_penalty(
                np.array(tool_points),
                poses[..., :3, 3],
                paper_semi_axes(problem.scene.obstacles, problem.settings.z3),
                rotations,
            )
        objectives.append([T, z2, z3, z4, z5, z6])
        constraints.append(_constraints(problem, extrema, tau_max, d_obs.min(initial=np.inf)))
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
