"""Hand-made moves on the paper scene, shared by the tests and the benchmarks."""

from __future__ import annotations

import numpy as np

from adept_traj.problem import TrajectoryProblem


def smoothstep(z: np.ndarray) -> np.ndarray:
    """Minimum-jerk ramp 10 z³ − 15 z⁴ + 6 z⁵ on [0, 1]."""
    return 10 * z**3 - 15 * z**4 + 6 * z**5


def lift_then_lower(problem: TrajectoryProblem, T: float = 2.1, late: float = 0.55) -> np.ndarray:
    """A hand-made collision-free move (paper scene, T = 2.1 s): θ1, θ2, θ4 on a smooth ramp;
    d3 held at its start value (tool high over cube 1) until ``late`` of the control
    polygon, then lowered to the goal. Decision vector (n_var,)."""
    traj = problem.trajectory
    xi = np.linspace(0.0, 1.0, traj.n_control)[3:-3]
    start, goal = problem.start, problem.goal
    free = start + (goal - start) * smoothstep(xi)[:, None]
    ramp = np.clip((xi - late) / (1 - late), 0.0, 1.0)
    free[:, 2] = start[2] + (goal[2] - start[2]) * smoothstep(ramp)
    return traj.encode(T, free)


def single_result(
    problem: TrajectoryProblem,
    x: np.ndarray,
    rate_hz: float = 1000.0,
    *,
    certified: np.ndarray | None = None,
):
    """A PlanningResult whose front is the decision vector ``x`` (n_var,), or the vectors
    ``x`` (k, n_var), the first the best trade-off, certified at ``rate_hz`` (no
    optimisation run; nominal timings). ``certified`` (k,) bool: the members' certificate
    verdicts, as when every member was certified (``front.feasible``, ``n_certified``);
    ``None``: the engine's feasibility, members not certified."""
    from adept_traj.certification import certify
    from adept_traj.results import BestSolution, Front, PlanningResult, Timing

    x = np.atleast_2d(x)
    front = Front.from_evaluation(x, problem.evaluate_batch(x))
    if certified is not None:
        verdict = np.asarray(certified, dtype=bool)
        front = Front(front.x, front.objectives, front.constraints, verdict, int(verdict.sum()))
    return PlanningResult.from_problem(
        problem,
        algorithm="NSGA-II",
        algorithm_settings={},
        seed=1,
        front=front,
        best=BestSolution(0),
        certificate=certify(problem, x[0], rate_hz=rate_hz),
        timing=Timing(total_s=1.0, evaluation_s=0.5, n_evaluations=10, n_generations=1),
    )
