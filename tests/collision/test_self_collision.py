"""Self-collision in the planning problem and the certificate (issue 14).

References share no code with what they test: solids placed by Pinocchio
(``pin.updateGeometryPlacements``) and their distance computed by coal directly, finite
differences, and the obstacle-only problem (``self_collision=False``) for the paper.
"""

from __future__ import annotations

import json
from dataclasses import replace

import coal
import numpy as np
import pinocchio as pin
import pytest

from adept_traj.certification import certify, certify_members
from adept_traj.cli import main
from adept_traj.collision import (
    SelfCollision,
    enclosing_capsule,
    pair_lever_arms,
    segment_distance,
)
from adept_traj.problem import TrajectoryProblem
from adept_traj.results import PlanningResult
from adept_traj.robot import Robot, installed_data_dirs
from adept_traj.scene import Box, FixedPose, Obstacle, Scene
from adept_traj.testing.paper_moves import lift_then_lower, single_result

_FOUND = [d / "example-robot-data/robots" for d in installed_data_dirs()]
ROBOTS = next((d for d in _FOUND if d.is_dir()), None)
needs_ur5 = pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
PARAMS = "examples/data/ur5.toml"
HOME = np.array([0.0, -1.57, 0.0, -1.57, 0.0, 0.0])
FOLDED = np.array([0.0, -1.57, 3.1, 0.0, 0.0, 0.0])  # the elbow folded flat: wrist in the arm
#: A box far from the UR5: the obstacle distance never matters here.
FAR = Scene(obstacles=(Obstacle("box", Box((0.1, 0.1, 0.1)), FixedPose.from_xyz_rpy((2, 2, 0))),))


@pytest.fixture(scope="module")
def ur5() -> Robot:
    return Robot.from_urdf(
        ROBOTS / "ur_description/urdf/ur5_robot.urdf",
        PARAMS,
        srdf=ROBOTS / "ur_description/srdf/ur5.srdf",
    )


def _reference(robot: Robot, q: np.ndarray, pairs: tuple[tuple[str, str], ...]) -> np.ndarray:
    """(n, n_pairs) coal distances of the named solid pairs placed by Pinocchio."""
    gm = robot.collision_model
    data, gdata = robot.model.createData(), gm.createData()
    request = coal.DistanceRequest()
    out = np.empty((len(q), len(pairs)))
    for n, qn in enumerate(np.atleast_2d(q)):
        pin.updateGeometryPlacements(robot.model, data, gm, gdata, qn)
        for k, (a, b) in enumerate(pairs):
            ia, ib = gm.getGeometryId(a), gm.getGeometryId(b)
            pa, pb = gdata.oMg[ia], gdata.oMg[ib]
            out[n, k] = coal.distance(
                gm.geometryObjects[ia].geometry, coal.Transform3s(pa.rotation, pa.translation),
                gm.geometryObjects[ib].geometry, coal.Transform3s(pb.rotation, pb.translation),
                request, coal.DistanceResult(),
            )  # fmt: skip
    return out


# ---------------------------------------------------------------------------- the SCARA
def test_the_scara_quill_through_the_outer_arm_is_not_a_checked_pair() -> None:
    """link3 carries no solid: link4 (quill, flange, gripper) is adjacent to link2."""
    names = {frozenset(p) for p in SelfCollision(Robot.adept_one_xl()).pair_names}
    for solid in ("link4/quill", "link4/flange", "link4/gripper"):
        assert frozenset(("link2/outer_arm", solid)) not in names
    assert frozenset(("link1/inner_arm", "link4/gripper")) in names  # a real pair stays


def test_the_paper_problem_is_unchanged_with_self_collision_on(problem) -> None:
    """On by default (the shipped robot has no SRDF: its sampled collision matrix leaves
    only the adjacent pairs out); on, the paper problem evaluates and certifies
    bit-identically to off: its 10 checked pairs never come within δ."""
    assert problem.settings.self_collision is True
    assert problem.self_check.n_pairs == 10
    assert problem.settings.disabled_pairs == ()
    off = TrajectoryProblem(problem.robot, problem.scene, problem.start, problem.goal,
                            self_collision=False)  # fmt: skip
    assert off.self_check is None
    rng = np.random.default_rng(3)
    x = problem.xl + (problem.xu - problem.xl) * rng.random((60, problem.n_var))
    x = np.vstack([x, lift_then_lower(problem)])
    on_ev, off_ev = problem.evaluate_batch(x), off.evaluate_batch(x)
    np.testing.assert_array_equal(on_ev.objectives, off_ev.objectives)
    np.testing.assert_array_equal(on_ev.constraints, off_ev.constraints)
    np.testing.assert_array_equal(on_ev.min_distance, off_ev.min_distance)
    c_on, c_off = certify(problem, x[-1], 250.0), certify(off, x[-1], 250.0)
    assert c_on.certified
    assert c_off.certified
    assert c_off.self_distance is None
    assert c_on.self_distance.min_distance > problem.settings.influence  # never close
    assert c_on.self_distance.distance_bound > problem.settings.margin


# ---------------------------------------------------------------------------- UR5
@needs_ur5
def test_adjacent_and_srdf_pairs_are_left_out_and_recorded(ur5: Robot) -> None:
    bare = Robot.from_urdf(ROBOTS / "ur_description/urdf/ur5_robot.urdf", PARAMS)
    assert TrajectoryProblem(bare, FAR, HOME, FOLDED).self_check.n_pairs  # no SRDF: on too
    assert TrajectoryProblem(bare, FAR, HOME, FOLDED, self_collision=False).self_check is None
    problem = TrajectoryProblem(ur5, FAR, HOME, FOLDED, disabled_pairs=[("base_link", "ee_link")])
    names = {frozenset(p) for p in problem.self_check.pair_names}
    assert frozenset(("upper_arm_link_0", "forearm_link_0")) not in names  # adjacent
    assert frozenset(("wrist_1_link_0", "wrist_3_link_0")) not in names  # SRDF
    assert frozenset(("base_link_0", "ee_link_0")) not in names  # given
    recorded = problem.settings.disabled_pairs
    assert ("base_link", "ee_link") in recorded
    assert ("wrist_1_link", "wrist_3_link") in recorded
    assert recorded == tuple(sorted(recorded))


@needs_ur5
def test_pair_lever_arms_bound_the_rate_of_every_pair_distance(ur5: Robot) -> None:
    check = SelfCollision(ur5)
    rho = pair_lever_arms(ur5, check.pairs)
    k = check.pair_names.index(("forearm_link_0", "ee_link_0"))
    assert rho[k, :3].tolist() == [0.0, 0.0, 0.0]  # joints moving both: no change
    rng = np.random.default_rng(0)
    lim, h = ur5.limits, 1e-6
    for _ in range(6):
        q = lim.lower + (lim.upper - lim.lower) * rng.uniform(0.3, 0.7, ur5.nq)
        v = rng.normal(size=ur5.nq)
        slope = (_reference(ur5, q + h * v, check.pair_names)
                 - _reference(ur5, q - h * v, check.pair_names))[0] / (2 * h)  # fmt: skip
        assert np.all(np.abs(slope) <= np.abs(v) @ rho.T + 1e-6)


@needs_ur5
def test_distances_and_the_motion_minimum_match_coal_called_directly(ur5: Robot) -> None:
    check = SelfCollision(ur5, influence=0.08)
    s = np.linspace(0.0, 1.0, 25)[:, None]
    goals = [FOLDED, np.array([0.5, -1.2, 2.6, -2.9, 1.0, 0.0])]
    q = np.stack([HOME + (g - HOME) * s for g in goals])  # (2 motions, 25, 6)
    ref = _reference(ur5, q.reshape(-1, 6), check.pair_names).reshape(2, 25, -1)
    d = check.distances(q)
    near = ref <= check.influence
    np.testing.assert_allclose(d[near], ref[near], atol=1e-6)
    assert np.all(d[~near] > check.influence)
    assert np.all(d[~near] <= ref[~near] + 1e-9)
    found = check.min_distances(q)
    np.testing.assert_allclose(found.distance, ref.min(axis=(1, 2)), atol=1e-6)
    m = int(np.argmin(found.distance))
    assert ref[m, found.sample[m], found.pair[m]] == pytest.approx(found.distance[m], abs=1e-6)
    low = ref.min(axis=(1, 2)) - 1e-3  # just below each motion's minimum: bounds above it
    capped = check.min_distances(q, below=low)
    assert np.all(capped.distance > low)
    assert np.all(capped.distance <= ref.min(axis=(1, 2)) + 1e-9)


@needs_ur5
def test_a_move_folding_into_itself_is_refused_and_not_certified(ur5: Robot) -> None:
    """The obstacle-only problem certifies the move; with self-collision on (the default
    for a robot with checked pairs) its constraint is violated and it is not certified,
    and the certificate names the pair."""
    on = TrajectoryProblem(ur5, FAR, HOME, FOLDED, n_knots=8)
    off = TrajectoryProblem(ur5, FAR, HOME, FOLDED, n_knots=8, self_collision=False)
    x = on.trajectory.straight_line(on.xu[0])
    assert off.evaluate_batch(x).constraints[-1] <= 0.0
    assert certify(off, x, 100.0).certified
    g = on.evaluate_batch(x).constraints[-1]
    st = on.settings
    q = on.trajectory.sample(x, on.s).q
    own = _reference(ur5, q, on.self_check.pair_names).min()
    obstacle = off.evaluate_batch(x).min_distance.min()
    expected = (st.margin + st.search_buffer - min(own, obstacle, st.influence)) / st.influence
    assert g == pytest.approx(expected, abs=1e-9)
    assert g > 0.0
    cert = certify(on, x, 100.0)
    assert not cert.feasible
    assert not cert.certified
    own = cert.self_distance
    assert own.min_distance < 0.0
    assert own.exact
    q_at = on.trajectory.sample(x, [own.t_min_distance / on.xu[0]]).q[0]
    assert _reference(ur5, q_at, (own.pair,))[0, 0] == pytest.approx(own.min_distance, abs=1e-6)
    assert any(v.startswith("self-distance") and own.pair[0] in v for v in cert.violations)


@needs_ur5
def test_the_continuous_self_guarantee_holds_against_dense_coal(ur5: Robot) -> None:
    """A move passing close to itself, certified at 50 Hz: its bound is below the
    self-distance at 1 000 Hz computed by coal directly on every checked pair."""
    goal = np.array([0.0, -1.57, 2.75, -1.0, 0.0, 0.0])
    problem = TrajectoryProblem(ur5, FAR, HOME, goal, n_knots=8)
    x = problem.trajectory.straight_line(problem.xu[0])
    own = certify(problem, x, 50.0).self_distance
    assert own.guarantee == "continuous"
    assert problem.settings.margin <= own.distance_bound <= own.min_distance < 0.05
    dense = problem.trajectory.sample(x, np.linspace(0, 1, int(1000 * x[0]))).q
    ref = _reference(ur5, dense, problem.self_check.pair_names)
    assert ref.min() >= own.distance_bound
    assert ref.min() <= own.min_distance + 1e-6  # the certificate's samples are real


@pytest.mark.slow
@needs_ur5
def test_the_result_records_self_collision_and_verify_rebuilds_it(
    ur5: Robot, tmp_path, capsys
) -> None:
    problem = TrajectoryProblem(ur5, FAR, HOME, FOLDED, n_knots=8)
    x = problem.trajectory.straight_line(problem.xu[0])
    result = single_result(problem, x, 100.0)
    members = certify_members(problem, x[None], rate_hz=100.0)
    front = replace(result.front, feasible=[False], n_certified=0, certificates=members)
    result = replace(result, front=front)
    result.save(tmp_path)
    back = PlanningResult.load(tmp_path)
    assert back.problem_settings == problem.settings
    assert back.certificate.self_distance == result.certificate.self_distance
    assert back.front.certificates[0] == members[0]
    assert members[0].self_distance.pair == result.certificate.self_distance.pair
    rebuilt = back.problem()
    assert rebuilt.self_check.pair_names == problem.self_check.pair_names
    main(["verify", str(tmp_path)])  # (single_result's nominal metrics do not match)
    clean = [line for line in capsys.readouterr().out.splitlines() if "mismatch:" in line]
    assert not [line for line in clean if "certificate" in line or "problem" in line], clean
    doc = json.loads((tmp_path / "result.json").read_text())
    doc["front"][0]["certificate"]["self_distance"]["min_distance"] += 0.001  # tampered
    (tmp_path / "result.json").write_text(json.dumps(doc))
    assert main(["verify", str(tmp_path)]) == 3
    assert "front[0].certificate.self_distance.min_distance" in capsys.readouterr().out
    off = single_result(
        TrajectoryProblem(ur5, FAR, HOME, FOLDED, n_knots=8, self_collision=False),
        problem.trajectory.straight_line(problem.xu[0]),
        100.0,
    )
    off.save(tmp_path / "off")
    text = (tmp_path / "off" / "result.json").read_text()
    assert "self_collision" not in text
    assert "self_distance" not in text
    assert PlanningResult.load(tmp_path / "off").problem().self_check is None


# ---------------------------------------------------------------------------- capsules
def test_segment_distance_matches_dense_sampling_of_both_segments() -> None:
    rng = np.random.default_rng(7)
    ends = rng.normal(size=(4, 3, 50))
    ends[2] = ends[0] + 1e-3 * rng.normal(size=(3, 50))  # some nearly degenerate cases
    got = segment_distance(*ends)
    s = np.linspace(0.0, 1.0, 401)
    for k in range(50):
        a = ends[0][:, k, None] + s * (ends[1][:, k] - ends[0][:, k])[:, None]  # (3, 401)
        b = ends[2][:, k, None] + s * (ends[3][:, k] - ends[2][:, k])[:, None]
        brute = np.sqrt(((a[:, :, None] - b[:, None]) ** 2).sum(axis=0)).min()
        step = np.linalg.norm(ends[1][:, k] - ends[0][:, k]) + np.linalg.norm(
            ends[3][:, k] - ends[2][:, k]
        )
        assert brute - step / 400 - 1e-12 <= got[k] <= brute + 1e-12


def test_the_enclosing_capsule_contains_the_solid_box() -> None:
    box = coal.Box(0.4, 0.1, 0.06)
    a0, a1, radius = enclosing_capsule(box)
    corners = np.array(np.meshgrid(*[[-1, 1]] * 3)).reshape(3, -1).T * [0.2, 0.05, 0.03]
    gap = segment_distance(*(np.repeat(p[:, None], 8, axis=1) for p in (a0, a1)),
                           corners.T, corners.T)  # fmt: skip
    assert np.all(gap <= radius + 1e-12)
    assert radius == pytest.approx(0.5 * np.hypot(0.1, 0.06))
