"""Distance derivatives from coal's witness points (collision.distance_gradients) and the
motion laws' point velocities, against central differences of Pinocchio and coal called
directly (no code of the package in the reference)."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest

from adept_traj import Scene, TrajectoryProblem
from adept_traj.collision import distance_gradients
from adept_traj.errors import InvalidInputError
from adept_traj.scene import FixedPose, MotionLaw
from adept_traj.testing.paper_moves import lift_then_lower


class _Reference:
    """Smallest robot–obstacle distance per obstacle by Pinocchio's geometry placements and
    coal (GJK tolerance ``tolerance``), one configuration at a time."""

    def __init__(self, problem: TrajectoryProblem, tolerance: float = 1e-14) -> None:
        robot = problem.robot
        self.model, self.data = robot.model, robot.model.createData()
        self.gmodel = robot.collision_model
        self.gdata = self.gmodel.createData()
        self.scene = problem.scene
        self.obstacles = [ob.shape.to_coal() for ob in self.scene.obstacles]
        self.request = coal.DistanceRequest()
        self.request.gjk_tolerance = tolerance

    def __call__(self, q: np.ndarray, t: float) -> np.ndarray:
        """(n_obs, n_solids) signed distances [m]."""
        pin.updateGeometryPlacements(self.model, self.data, self.gmodel, self.gdata, q)
        poses = self.scene.obstacle_poses(np.float64(t), in_base_frame=True)
        out = np.empty((len(self.obstacles), len(self.gmodel.geometryObjects)))
        for o, geometry in enumerate(self.obstacles):
            tf = coal.Transform3s(poses[o][:3, :3], poses[o][:3, 3])
            for k, solid in enumerate(self.gmodel.geometryObjects):
                placement = self.gdata.oMg[k]
                out[o, k] = coal.distance(
                    solid.geometry,
                    coal.Transform3s(placement.rotation, placement.translation),
                    geometry,
                    tf,
                    self.request,
                    coal.DistanceResult(),
                )
        return out


def _central(reference: _Reference, q: np.ndarray, t: float, h: float):
    """(n_obs, nq) and (n_obs,) central differences of the per-obstacle minimum."""
    dq = np.empty((len(reference.obstacles), len(q)))
    for j in range(len(q)):
        e = np.zeros(len(q))
        e[j] = h
        dq[:, j] = (reference(q + e, t).min(axis=1) - reference(q - e, t).min(axis=1)) / (2 * h)
    dt = (reference(q, t + h).min(axis=1) - reference(q, t - h).min(axis=1)) / (2 * h)
    return dq, dt


@pytest.fixture(scope="module")
def cases(problem):
    """Samples (q (n, nq), t (n,)) of moves that come close to or into obstacles: the
    straight move at T = 2, 2.5, 4 s (through cube 1 and the pendulum rod and bob), a
    lift-then-lower move (1.3 cm from the moving rod) and a seeded ramp."""
    from adept_traj.optimise import RampSampling, kinematic_time

    ramp = RampSampling().ramps(problem, 1, np.random.default_rng(5))
    ramp[:, 0] = kinematic_time(problem, ramp) * 1.2
    straight = [problem.trajectory.straight_line(T) for T in (2.0, 2.5, 4.0)]
    x = np.concatenate([straight, lift_then_lower(problem)[None], ramp])
    smp = problem.trajectory.sample(x, problem.s, orders=(0,))
    return smp.q.reshape(-1, problem.robot.nq), smp.t.reshape(-1)


def _close_pairs(problem, reference, q, t, separated: bool, n: int):
    """Up to ``n`` (sample, obstacle) pairs of a fixed and ``n`` of a moving obstacle, at a
    distance below influence, separated (> 1 mm) or penetrating (< −1 mm), whose closest
    solid is unique by 1 mm, drawn at random (seeded)."""
    found: dict[bool, list[tuple[int, int]]] = {False: [], True: []}
    for i in range(len(q)):
        ref = reference(q[i], t[i])
        for o in range(ref.shape[0]):
            d = np.sort(ref[o])
            if d[0] >= problem.checker.influence or d[1] - d[0] < 1e-3:
                continue
            if (d[0] > 1e-3) if separated else (d[0] < -1e-3):
                found[problem.scene.obstacles[o].is_moving].append((i, o))
    rng = np.random.default_rng(11)
    return {
        moving: [pairs[j] for j in rng.permutation(len(pairs))[:n]]
        for moving, pairs in found.items()
    }


@pytest.mark.parametrize("separated", [True, False], ids=["separated", "penetrating"])
def test_gradients_match_central_differences_of_coal(problem, cases, separated) -> None:
    """∂d/∂q and ∂d/∂t (pendulum included) of separated pairs to 1e-5 (relative to
    1 + |·|; measured ≤ 4e-6: GJK on the curved rod; with the distances' own 1e-9 m GJK
    tolerance the witness points were 1e-4 off), of penetrating pairs to 1e-4 (measured
    2e-5; EPA is accurate to ~3 µm, so the reference takes h = 1e-4)."""
    q, t = cases
    reference = _Reference(problem)
    grad = distance_gradients(problem.checker, q, t)
    chosen = _close_pairs(problem, reference, q, t, separated, 6)
    assert len(chosen[True]) >= 3
    assert len(chosen[False]) >= 3
    pairs = chosen[True] + chosen[False]
    h, tol = (1e-6, 1e-5) if separated else (1e-4, 1e-4)
    for i, o in pairs:
        dq, dt = _central(reference, q[i], t[i], h)
        assert grad.distance[i, o] == pytest.approx(reference(q[i], t[i])[o].min(), abs=1e-6)
        np.testing.assert_array_less(np.abs(grad.dq[i, o] - dq[o]) / (1 + np.abs(dq[o])), tol)
        assert abs(grad.dt[i, o] - dt[o]) / (1 + abs(dt[o])) < tol
        if not problem.scene.obstacles[o].is_moving:
            assert grad.dt[i, o] == 0.0


def test_far_pairs_have_zero_gradient_and_no_solid(problem, cases) -> None:
    """Where the smallest distance is at least ``influence`` the derivatives are exactly 0
    (the clipped distance is constant there) and no solid is named; elsewhere one is."""
    q, t = cases
    grad = distance_gradients(problem.checker, q, t)
    far = grad.distance >= problem.checker.influence
    assert far.any()
    assert (~far).any()
    assert np.all(grad.dq[far] == 0.0)
    assert np.all(grad.dt[far] == 0.0)
    assert np.all(grad.solid[far] == -1)
    assert np.all(grad.solid[~far] >= 0)


def test_batch_shape_and_no_obstacles(problem, cases) -> None:
    """A (2, n_t, nq) batch gives the rows of the flat call; a scene without obstacles
    gives empty arrays."""
    q, t = cases
    flat = distance_gradients(problem.checker, q[:20], t[:20])
    batch = distance_gradients(problem.checker, q[:20].reshape(2, 10, -1), t[:20].reshape(2, 10))
    assert batch.dq.shape == (2, 10, problem.checker.n_obstacles, problem.robot.nq)
    np.testing.assert_array_equal(batch.dq.reshape(flat.dq.shape), flat.dq)
    np.testing.assert_array_equal(batch.dt.reshape(flat.dt.shape), flat.dt)
    empty = TrajectoryProblem(problem.robot, Scene(()), problem.start, problem.goal)
    none = distance_gradients(empty.checker, q[:5], t[:5])
    assert none.dq.shape == (5, 0, problem.robot.nq)
    assert none.n_narrow == 0


def test_pendulum_point_velocity_matches_its_pose(problem) -> None:
    """The pendulum's closed-form point velocity against central differences of its pose
    (points fixed in the moving frame), at seeded times and points; a fixed pose gives 0."""
    law = problem.scene.moving[0].motion
    rng = np.random.default_rng(2)
    t = rng.uniform(0.0, 4.0, 9)
    local = rng.normal(size=(9, 3))
    h = 1e-6

    def world(tt):
        pose = law.pose(tt)
        return np.einsum("nij,nj->ni", pose[:, :3, :3], local) + pose[:, :3, 3]

    expected = (world(t + h) - world(t - h)) / (2 * h)
    np.testing.assert_allclose(law.point_velocity(t, world(t)), expected, atol=1e-8)
    # The generic rule (central differences of pose) agrees with the closed form.
    np.testing.assert_allclose(MotionLaw._point_velocity(law, t, world(t)), expected, atol=1e-8)
    fixed = FixedPose.from_xyz_rpy((1.0, 2.0, 3.0), (0.1, 0.2, 0.3))
    assert np.all(fixed.point_velocity(t, world(t)) == 0.0)


def test_point_velocity_refuses_bad_input(problem) -> None:
    law = problem.scene.moving[0].motion
    with pytest.raises(InvalidInputError, match="points"):
        law.point_velocity(0.0, np.zeros(2))
    with pytest.raises(InvalidInputError, match="broadcast"):
        law.point_velocity(np.zeros(3), np.zeros((2, 3)))
    with pytest.raises(InvalidInputError):
        law.point_velocity(np.nan, np.zeros(3))


def test_a_failing_tight_gjk_call_falls_back_to_a_looser_tolerance(problem) -> None:
    """coal 3.0.3's GJK at tolerance 1e-14 fails for this flange–cube pose of the detour
    scene (−1.8e308, NaN points); the gradient is then taken at the next tolerance and
    matches central differences (it was NaN)."""
    scene = Scene.shipped("detour")
    detour = TrajectoryProblem(problem.robot, scene, scene.start, scene.goal)
    q = np.array(
        [-0.2529752057706764, -0.15920972455919985, 0.19942757751768095, 0.14922563773283035]
    )
    t = 1.018201431736103
    grad = distance_gradients(detour.checker, q[None], np.array([t]))
    assert detour.checker.solid_names[grad.solid[0, 0]] == "link4/flange"
    dq, _ = _central(_Reference(detour, tolerance=1e-12), q, t, 1e-5)  # 1e-14 fails too
    np.testing.assert_allclose(grad.dq[0, 0], dq[0], rtol=0, atol=1e-5)
