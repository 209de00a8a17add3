"""The unseen benchmark scenes of issue #24 (benchmarks/scenes/, docs/reference-moves.md).

The scene files are benchmarks, not shipped data; these tests check that they say what
their comments claim: each loads, its fixed obstacle (the wall, the post) alone blocks the
straight joint-space move at every speed, the pendulums block the rest poses at the
stated instants, and the reference move stored for it in
benchmarks/reference/reference_vectors.json is certified — its distances re-checked by
coal called pair by pair (``test_verification.coal_min_distances``).
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

import adept_traj as at
from adept_traj.certification import certify
from adept_traj.collision import distance_gradients
from tests.certification.test_verification import coal_min_distances

BENCHMARKS = Path(__file__).parents[2] / "benchmarks"
SCENES = {path.stem: path for path in sorted((BENCHMARKS / "scenes").glob("*.toml"))}
VECTORS = json.loads((BENCHMARKS / "reference" / "reference_vectors.json").read_text())
MOVES = json.loads((BENCHMARKS / "reference" / "reference_moves.json").read_text())

#: The fixed obstacle of each scene that blocks the straight move.
BLOCKER = {"wall_crane": "wall", "post_two_pendulums": "post"}


def problem_of(name: str, *, fixed_only: bool = False) -> at.TrajectoryProblem:
    scene = at.Scene.from_file(SCENES[name])
    if fixed_only:
        scene = dataclasses.replace(scene, obstacles=scene.fixed)
    return at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal)


def test_both_unseen_scenes_are_there() -> None:
    assert set(SCENES) == set(BLOCKER)


@pytest.mark.parametrize("name", sorted(BLOCKER))
def test_the_fixed_obstacle_alone_blocks_the_straight_move(name: str) -> None:
    """Without the pendulums, the straight move hits the wall / the post at every T."""
    problem = problem_of(name, fixed_only=True)
    T = np.linspace(float(problem.xl[0]), float(problem.xu[0]), 4)
    x = problem.trajectory.straight_line(T)
    s = np.linspace(0.0, 1.0, 401)
    q = problem.trajectory.sample(x, s, orders=(0,)).q  # (4, 401, 4)
    names = [ob.name for ob in problem.scene.obstacles]
    d = distance_gradients(problem.checker, q, T[:, None] * s).distance  # (4, 401, n_obs)
    blocker = names.index(BLOCKER[name])
    assert np.all(d[:, :, blocker].min(axis=1) < 0.0)  # penetration at every speed


def test_the_crane_load_blocks_the_goal_pose_when_it_passes() -> None:
    """The comment's claim: the load hits the arm held at the goal at t = 1.0 s (inside
    0.70–1.30 s) and not at t = 1.5 s; the start pose is never hit."""
    problem = problem_of("wall_crane")
    scene = problem.scene
    t = np.array([[0.0, 1.0, 1.5, 2.0]])
    names = [ob.name for ob in scene.obstacles]
    crane = [i for i, n in enumerate(names) if n.startswith("crane.")]
    for q, expected in ((scene.goal, [False, True, False, True]), (scene.start, [False] * 4)):
        qq = np.broadcast_to(q, (1, 4, 4)).copy()
        d = distance_gradients(problem.checker, qq, t).distance[0][:, crane].min(axis=1)
        assert list(d < problem.settings.margin) == expected


#: The stored moves of the unseen scenes: (scene, vector key, the reference_moves field
#: holding its T); ``<scene>_drake`` is Drake's move where the best known one is not.
STORED = [
    (key.removesuffix("_drake"), key, "drake_T" if key.endswith("_drake") else "T")
    for key in sorted(VECTORS)
    if key.removesuffix("_drake") in SCENES
]


@pytest.mark.slow  # ~4 s per move: a 1 kHz certificate and a coal loop over its samples
@pytest.mark.parametrize(("name", "key", "field"), STORED)
def test_the_reference_move_is_certified(name: str, key: str, field: str) -> None:
    problem = problem_of(name)
    x = np.array(VECTORS[key]["x"], dtype=float)
    assert MOVES[name][field] == pytest.approx(x[0], abs=1e-6)
    c = certify(problem, x)
    assert c.feasible, c.violations
    best, _ = coal_min_distances(problem, c.dense.q, c.dense.t)
    np.testing.assert_allclose(c.dense.min_distance, best, rtol=0, atol=1e-9)
    assert best.min() >= problem.settings.margin
