"""The evaluation hot path (issue #15): the point distances computed on few temporaries and
the enclosing-ball level reusing precomputed ball centres give the textbook values.

References are written out here (closed forms of the signed distances, rotations by
numpy's einsum), sharing no code with :mod:`adept_traj.collision`.
"""

from __future__ import annotations

import numpy as np
import pytest

from adept_traj.collision import BroadPhase, point_signed_distance
from adept_traj.errors import InvalidInputError
from adept_traj.robot import Robot, stack_times
from adept_traj.scene import Box, Cylinder, Scene

BOX = Box((0.4, 0.6, 1.0))
CYLINDER = Cylinder(0.2, 1.0)
INFLUENCE = 0.05


def box_reference(p: np.ndarray, half: np.ndarray) -> np.ndarray:
    e = np.abs(p) - half
    return np.linalg.norm(np.maximum(e, 0.0), axis=-1) + np.minimum(e.max(axis=-1), 0.0)


def cylinder_reference(p: np.ndarray, radius: float, half_length: float) -> np.ndarray:
    radial = np.hypot(p[..., 0], p[..., 1]) - radius
    axial = np.abs(p[..., 2]) - half_length
    outside = np.hypot(np.maximum(radial, 0.0), np.maximum(axial, 0.0))
    return outside + np.minimum(np.maximum(radial, axial), 0.0)


@pytest.fixture(scope="module")
def points() -> np.ndarray:
    """(500, 3) points [m] inside and outside both shapes, seeded."""
    return np.random.default_rng(7).uniform(-1.0, 1.0, size=(500, 3))


def test_box_distance_is_the_closed_form(points: np.ndarray) -> None:
    given = points.copy()
    d = point_signed_distance(BOX, points)
    np.testing.assert_allclose(d, box_reference(points, np.array([0.2, 0.3, 0.5])), atol=1e-15)
    assert np.array_equal(points, given)  # the caller's points are not touched
    assert (d < 0).any()
    assert (d > 0).any()


def test_cylinder_distance_is_the_closed_form(points: np.ndarray) -> None:
    given = points.copy()
    d = point_signed_distance(CYLINDER, points)
    np.testing.assert_allclose(d, cylinder_reference(points, 0.2, 0.5), atol=1e-15)
    assert np.array_equal(points, given)
    assert (d < 0).any()
    assert (d > 0).any()


@pytest.mark.parametrize("shape", [BOX, CYLINDER])
def test_one_point_gives_a_scalar(shape: object) -> None:
    d = point_signed_distance(shape, np.array([0.1, 0.7, 0.2]))
    assert np.ndim(d) == 0
    assert float(d) == pytest.approx(0.4 if shape is BOX else 0.5071067811865476, abs=1e-15)


@pytest.fixture(scope="module")
def paper_frames() -> tuple[BroadPhase, np.ndarray, np.ndarray, list[np.ndarray]]:
    """Broad phase of the paper scene, 300 seeded configurations and times, their joint
    frames and the obstacle poses in the base frame (the pendulum moving)."""
    robot, scene = Robot.adept_one_xl(), Scene.paper()
    broad = BroadPhase(robot, scene, INFLUENCE)
    rng = np.random.default_rng(3)
    q = rng.uniform(robot.limits.lower, robot.limits.upper, size=(300, robot.nq))
    t = rng.uniform(0.0, 2.0, size=300)
    poses = [
        scene.base_from_world @ (ob.pose(t) if ob.is_moving else ob.pose(0.0))
        for ob in scene.obstacles
    ]
    return broad, q, robot.kinematics.joint_frames(q), poses


def test_precomputed_ball_centres_give_the_same_bounds(paper_frames: tuple) -> None:
    broad, q, frames, poses = paper_frames
    plain = broad.bounds(frames, poses, q)
    given = broad.bounds(frames, poses, q, centres=broad.ball_centres(frames))
    assert np.array_equal(plain.lower, given.lower)
    assert np.array_equal(plain.exact, given.exact)


def test_ball_centres_of_the_wrong_shape_are_refused(paper_frames: tuple) -> None:
    broad, q, frames, poses = paper_frames
    with pytest.raises(InvalidInputError, match="centres must have shape"):
        broad.bounds(frames, poses, q, centres=broad.ball_centres(frames)[:, :, :-1])


@pytest.mark.parametrize("gap", [False, True])
def test_ball_level_is_the_ball_distance(paper_frames: tuple, gap: bool) -> None:
    """Level 1 on every pair (``done`` empty: solids in one run, sliced) or on the solids
    with a hole in their run (gathered): d(centre, obstacle) − R."""
    broad, _, frames, poses = paper_frames
    n = frames.shape[-1]
    balls = broad.ball_centres(frames)
    done = np.zeros((broad.n_solids, broad.n_obstacles), dtype=bool)
    if gap:
        done[2] = True
    lower = np.full((broad.n_solids, broad.n_obstacles, n), np.nan)
    broad._ball_bounds(lower, balls, poses, done)
    for o, shape in enumerate(broad.obstacle_shape):
        pose = np.broadcast_to(poses[o], (n, 4, 4))
        for k in range(broad.n_solids):
            if done[k, o]:
                assert np.isnan(lower[k, o]).all()  # left alone
                continue
            local = np.einsum("nji,nj->ni", pose[:, :3, :3], balls[:, k].T - pose[:, :3, 3])
            if isinstance(shape, Box):
                d = box_reference(local, 0.5 * np.asarray(shape.size))
            elif isinstance(shape, Cylinder):
                d = cylinder_reference(local, shape.radius, 0.5 * shape.length)
            else:  # the pendulum's bob
                d = np.linalg.norm(local, axis=-1) - shape.radius
            np.testing.assert_allclose(lower[k, o], d - broad.ball_radius[k], atol=1e-12)


def test_stack_times_is_the_stacked_product() -> None:
    """One GEMM over the rows of a stack of matrices times one matrix: the sums written out
    (einsum), within rounding; shapes (..., m, k) @ (k, n) → (..., m, n)."""
    rng = np.random.default_rng(5)
    stack = rng.normal(size=(7, 5, 4, 3))
    b = rng.normal(size=(4, 4))[:3, 1:]  # a non-contiguous view, as a pose's rotation block
    out = stack_times(stack, b)
    assert out.shape == (7, 5, 4, 3)
    np.testing.assert_allclose(out, np.einsum("...ik,kj->...ij", stack, b), rtol=0, atol=1e-14)
