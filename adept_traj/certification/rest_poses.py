"""The start and goal of a move, checked before any search: :func:`check_rest_poses`.

A move rests at its start (t = 0) and at its goal (t = T); the certificate asks every
distance to be at least the safety margin at every instant, so a start or a goal closer
than the margin to an obstacle, or (self-collision on) one of the robot's links closer
than the margin to another, can never be certified: a search from it would spend its
whole budget to end "NOT FEASIBLE at t = 0.000 s". :func:`check_rest_poses` refuses it
up front, naming every such pair and its distance. The obstacles are checked at t = 0 for
the start; for the goal, whose time T is not known before the search, only the obstacles
that do not move (a moving one is left to the certificate).
"""

from __future__ import annotations

import numpy as np

from adept_traj.errors import CollidingConfigurationError
from adept_traj.problem.trajectory_problem import TrajectoryProblem

__all__ = ["check_rest_poses", "rest_pose_contacts"]


def rest_pose_contacts(problem: TrajectoryProblem) -> tuple[str, ...]:
    """Every pair closer than the problem's margin [m] at the start or the goal, as
    ``"start: link_a/solid – box 0.0042 m"``-style lines (exact distances: coal, negative
    = penetration depth), in the order start, goal; ``()`` when both clear the margin."""
    margin = float(problem.settings.margin)
    checker, scene = problem.checker, problem.scene
    moving = np.array([ob.is_moving for ob in scene.obstacles], dtype=bool)
    out = []
    for name, q in (("start", problem.start), ("goal", problem.goal)):
        if checker.n_obstacles:
            d = checker.distances(q[None, None], np.zeros((1, 1)), exact=True).distance[0, 0]
            if name == "goal":
                d = np.where(moving[None, :], np.inf, d)  # (its time T is not known yet)
            for s, o in np.argwhere(d < margin).tolist():
                out.append(
                    f"{name}: {checker.solid_names[s]} – obstacle {checker.obstacle_names[o]} "
                    f"{d[s, o]:.4g} m"
                )
        check = problem.self_check
        if check is not None and check.n_pairs:
            own = check.distances(q[None], exact_below=margin)[0]
            for p in np.flatnonzero(own < margin).tolist():
                a, b = check.pair_names[p]
                out.append(f"{name}: {a} – {b} (self-collision) {own[p]:.4g} m")
    return tuple(out)


def check_rest_poses(problem: TrajectoryProblem) -> None:
    """Refuse a problem whose start or goal is closer than the safety margin to an
    obstacle or (self-collision on) to another link of the robot, with
    :class:`~adept_traj.errors.CollidingConfigurationError` naming every such pair and its
    distance [m] (:func:`rest_pose_contacts`)."""
    found = rest_pose_contacts(problem)
    if found:
        margin = float(problem.settings.margin)
        raise CollidingConfigurationError(
            f"no move can be certified: closer than the margin {margin:g} m (negative: "
            f"penetration) at rest: {'; '.join(found)}"
        )
