"""The branch and bound of ``CollisionChecker.min_distances``, batched over pairs (issue #15),
makes the same coal calls and finds the same minima as a one-pair-at-a-time search.

The reference below walks each (motion, obstacle) pair's candidates in increasing order of
their broad-phase bound (``BroadPhase.bounds``, the library's public bounds) and computes
each with coal called directly, on solid poses from ``Robot.geometry_poses`` and obstacle
poses from ``Scene.obstacle_poses`` (none of the checker's code), until a bound reaches the
best value found.
"""

from __future__ import annotations

import coal
import numpy as np
import pytest

from adept_traj.collision import BroadPhase, CollisionChecker
from adept_traj.collision.primitives import distance_request
from adept_traj.problem import TrajectoryProblem
from adept_traj.robot import Robot
from adept_traj.scene import Scene
from adept_traj.testing.paper_moves import lift_then_lower

INFLUENCE = 0.05


@pytest.fixture(scope="module")
def paper() -> TrajectoryProblem:
    scene = Scene.paper()
    return TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)


def _population(problem: TrajectoryProblem, kind: str) -> np.ndarray:
    """Eight seeded motions: random, near the straight move (collides), near a feasible one."""
    rng = np.random.default_rng(11)
    span = problem.xu - problem.xl
    if kind == "random":
        return problem.xl + span * rng.uniform(size=(8, problem.n_var))
    x0 = problem.trajectory.straight_line(1.6) if kind == "straight" else lift_then_lower(problem)
    x = x0 + rng.normal(scale=0.01, size=(8, problem.n_var)) * span
    return np.clip(x, problem.xl, problem.xu)


def reference_search(
    robot: Robot, scene: Scene, q: np.ndarray, t: np.ndarray
) -> tuple[np.ndarray, np.ndarray, int]:
    """(best (n_m, n_o), candidate (n_m, n_o) or -1, coal calls): one pair at a time."""
    n_m, n_t, nq = q.shape
    broad = BroadPhase(robot, scene, INFLUENCE)
    frames = robot.kinematics.joint_frames(q)
    poses_o = scene.obstacle_poses(t, in_base_frame=True)  # (n_o, n_m, n_t, 4, 4)
    per_obstacle = [
        p[0, 0] if not ob.is_moving else p.reshape(-1, 4, 4)
        for p, ob in zip(poses_o, scene.obstacles)
    ]
    bounds = broad.bounds(frames, per_obstacle, q.reshape(-1, nq))
    ns, n_o = broad.n_solids, broad.n_obstacles
    lower = bounds.lower.reshape(n_m, n_t * ns, n_o)
    known = bounds.exact.reshape(n_m, n_t * ns, n_o)
    solids = robot.geometry_poses(q)  # (n_m, n_t, ns, 4, 4)
    geoms = [g.geometry for g in robot.collision_model.geometryObjects]
    obstacles = [ob.shape.to_coal() for ob in scene.obstacles]
    best = np.full((n_m, n_o), np.inf)
    where = np.full((n_m, n_o), -1)
    calls = 0
    for m in range(n_m):
        for o in range(n_o):
            row = lower[m, :, o]
            if broad.closed_form[:, o].all() or row.min() > INFLUENCE:
                best[m, o] = row.min()  # exact already, or only a bound: no coal call
                continue
            for c in np.argsort(row, kind="stable").tolist():
                if row[c] > INFLUENCE or row[c] >= best[m, o]:
                    break
                if known[m, c, o]:
                    d = row[c]
                else:
                    ps, po = solids[m, c // ns, c % ns], poses_o[o, m, c // ns]
                    d = coal.distance(
                        geoms[c % ns],
                        coal.Transform3s(ps[:3, :3], ps[:3, 3]),
                        obstacles[o],
                        coal.Transform3s(po[:3, :3], po[:3, 3]),
                        distance_request(),
                        coal.DistanceResult(),
                    )
                    calls += 1
                if d < best[m, o]:
                    best[m, o], where[m, o] = d, c
    return best, where, calls


@pytest.mark.parametrize("kind", ["random", "straight", "feasible"])
def test_batched_search_is_the_one_pair_search(paper: TrajectoryProblem, kind: str) -> None:
    x = _population(paper, kind)
    smp = paper.trajectory.sample(x, paper.s)
    checker = CollisionChecker(paper.robot, paper.scene, influence=INFLUENCE)
    found = checker.min_distances(smp.q, smp.t)
    best, where, calls = reference_search(paper.robot, paper.scene, smp.q, smp.t)
    assert calls > 0
    assert found.n_narrow == calls
    exact = best <= INFLUENCE
    assert exact.any()
    np.testing.assert_allclose(found.distance[exact], best[exact], rtol=0, atol=1e-12)
    ns = checker.n_solids
    searched = exact & (where >= 0)
    np.testing.assert_array_equal(found.sample[searched], where[searched] // ns)
    np.testing.assert_array_equal(found.solid[searched], where[searched] % ns)
    assert (found.distance[~exact] > INFLUENCE).all()
