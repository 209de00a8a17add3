"""The local solver of the polish: scipy's SLSQP against scipy's trust-constr (issue #12).

The issue asks for a local solver from a well-kept package, chosen by certified result and
time. IPOPT (cyipopt) has no wheel for this platform, so the candidates are scipy's two
constrained methods. Both solve the same problem as
:func:`adept_traj.optimise.local.minimum_time.minimum_time` — minimise T subject to every
smooth per-sample constraint of :func:`adept_traj.problem.local_constraints` (exact
Jacobians), inside the decision bounds — from the same starts: the straight move and the two
kinematically fastest of 16 seeded ramps, each at its kinematic minimum T (as
:func:`adept_traj.optimise.time_optimal`). Printed per start and method: the T reached
[s], T / T_lb, whether the evaluator finds it feasible and the 1 kHz continuous
certificate certifies it, the iterations, the constraint evaluations and the process CPU
time [s] (the machine is shared; CPU time is steadier than wall time).

``python benchmarks/bench_solvers.py [--max-iter N]``
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _results import recorded  # benchmarks/_results.py
from scipy.optimize import Bounds, NonlinearConstraint, minimize
from threadpoolctl import threadpool_limits

from adept_traj import Robot, Scene, TrajectoryProblem, certify
from adept_traj.optimise import RampSampling, kinematic_time
from adept_traj.problem import local_constraints

_SLACK = 1e-6  # the starts' T above their kinematic minimum (relative)


def starts(problem: TrajectoryProblem, seed: int = 1) -> np.ndarray:
    """(3, n_var): the straight move and the two kinematically fastest of 16 seeded ramps,
    each at its kinematic minimum T."""
    straight = problem.trajectory.straight_line(problem.xl[0])[None]
    ramps = RampSampling().ramps(problem, 16, np.random.default_rng(seed))
    x = np.concatenate([straight, ramps])
    t_kin = kinematic_time(problem, x)
    order = np.concatenate([[0], 1 + np.argsort(t_kin[1:], kind="stable")])[:3]
    x, t_kin = x[order], t_kin[order]
    x[:, 0] = np.clip(t_kin * (1.0 + _SLACK), problem.xl[0], problem.xu[0])
    return x


def solve(problem: TrajectoryProblem, x0: np.ndarray, method: str, max_iter: int) -> dict:
    """Minimum T from ``x0`` by ``method``; the end point clipped to the bounds with T
    raised to its kinematic minimum (as the library does), evaluated and certified."""
    cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}
    count = [0]

    def pieces(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        key = x.tobytes()
        if key not in cache:
            cache.clear()
            lc = local_constraints(problem, np.clip(x, problem.xl, problem.xu))
            cache[key] = (lc.values[0], lc.jacobian[0])
            count[0] += 1
        return cache[key]

    grad = np.zeros(problem.n_var)
    grad[0] = 1.0
    cpu = time.process_time()
    with threadpool_limits(limits=1, user_api="blas"):
        if method == "SLSQP":
            res = minimize(
                lambda x: x[0], x0, jac=lambda x: grad, method="SLSQP",
                bounds=list(zip(problem.xl, problem.xu)),
                constraints=[{"type": "ineq", "fun": lambda x: -pieces(x)[0],
                              "jac": lambda x: -pieces(x)[1]}],
                options={"maxiter": max_iter, "ftol": 1e-10},
            )  # fmt: skip
        else:
            constraint = NonlinearConstraint(
                lambda x: pieces(x)[0], -np.inf, 0.0, jac=lambda x: pieces(x)[1]
            )
            res = minimize(
                lambda x: x[0], x0, jac=lambda x: grad, method="trust-constr",
                hess=lambda x: np.zeros((len(x), len(x))),
                bounds=Bounds(problem.xl, problem.xu), constraints=[constraint],
                options={"maxiter": max_iter, "gtol": 1e-8, "xtol": 1e-10},
            )  # fmt: skip
    x = np.clip(res.x, problem.xl, problem.xu)
    x[0] = min(max(x[0], kinematic_time(problem, x[None])[0] * (1.0 + _SLACK)), problem.xu[0])
    cpu = time.process_time() - cpu
    ev = problem.evaluate_batch(x)
    feasible = bool(np.all(ev.constraints <= 0.0))
    return {
        "T": float(x[0]),
        "feasible": feasible,
        "certified": bool(feasible and certify(problem, x).certified),
        "iterations": int(res.nit),
        "evaluations": count[0],
        "cpu": cpu,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--max-iter", type=int, default=100, help="iterations per solve")
    args = parser.parse_args()
    scene = Scene.paper()
    problem = TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)
    t_lb = float(problem.xl[0])
    print(f"paper scene, T_lb = {t_lb:.6f} s, max {args.max_iter} iterations per solve")
    print("| start | method | T [s] | T/T_lb | feasible | certified | iterations | "
          "constraint evaluations | CPU [s] |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|")
    for i, x0 in enumerate(starts(problem)):
        for method in ("SLSQP", "trust-constr"):
            r = solve(problem, x0, method, args.max_iter)
            print(
                f"| {i} | {method} | {r['T']:.7f} | {r['T'] / t_lb:.4f} | {r['feasible']} | "
                f"{r['certified']} | {r['iterations']} | {r['evaluations']} | {r['cpu']:.2f} |"
            )


if __name__ == "__main__":
    with recorded(__file__, "the polish's local solver: SLSQP vs trust-constr"):
        main()
