"""The CSV export and the joint-motion figure of any front member: another member's CSV is
its own spline resampled on the certificate's grid (its own T, at rest at start and goal),
with the robot's inverse dynamics and coal's distances; the best trade-off's CSV is
equal to its stored certificate samples; an uncertified member is refused unless allowed; an
out-of-range index names the range; the figure's title names the member."""

from __future__ import annotations

import csv
import math
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
import pytest

from adept_traj.certification import certify
from adept_traj.errors import InvalidInputError
from adept_traj.problem import TrajectoryProblem
from adept_traj.results import (
    PlanningResult,
    Replay,
    to_csv,
)
from adept_traj.testing.paper_moves import lift_then_lower, single_result
from adept_traj.viz.plots import motion

RATE = 1000.0  # [Hz]
T_OTHER = 2.3  # [s]: travel time of member 1 (certified; 2.6 s meets the pendulum)


@pytest.fixture(scope="module")
def result(problem: TrajectoryProblem) -> PlanningResult:
    """A front of three members: 0 the best (lift-then-lower, T = 2.1 s, certified), 1 the
    same move slower (T = 2.3 s, certified), 2 the straight line (hits cube 1, not
    certified)."""
    x = np.stack(
        [
            lift_then_lower(problem),
            lift_then_lower(problem, T=T_OTHER),
            problem.trajectory.straight_line(1.5),
        ]
    )
    assert certify(problem, x[1], rate_hz=RATE).feasible
    assert not certify(problem, x[2], rate_hz=200.0).feasible
    result = single_result(problem, x, RATE, certified=np.array([True, True, False]))
    assert result.feasible
    return result


def read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    rows = list(csv.reader(path.open(encoding="utf-8")))
    return rows[0], np.array(rows[1:], dtype=float)


def columns(header: list[str], table: np.ndarray, prefix: str) -> np.ndarray:
    return table[:, [i for i, h in enumerate(header) if h.startswith(prefix + "_")]]


@pytest.fixture(scope="module")
def other_csv(result: PlanningResult, tmp_path_factory: pytest.TempPathFactory) -> Path:
    return to_csv(result, tmp_path_factory.mktemp("member") / "m1.csv", member=1)


def test_another_members_csv_has_its_own_duration_and_rests_at_start_and_goal(
    result: PlanningResult, other_csv: Path
) -> None:
    header, table = read_csv(other_csv)
    names = list(result.robot.joint_names)
    assert header == [
        "t",
        *(f"{p}_{n}" for p in ("q", "qd", "qdd", "qddd", "tau") for n in names),
        "min_distance",
    ]
    t = table[:, 0]
    assert len(t) == math.ceil(T_OTHER * RATE) + 1  # the certificate's grid
    assert t[0] == 0.0
    assert t[-1] == pytest.approx(T_OTHER, abs=1e-12)
    np.testing.assert_allclose(np.diff(t), T_OTHER / (len(t) - 1), rtol=1e-9)
    q = columns(header, table, "q")
    np.testing.assert_allclose(q[0], result.start, atol=1e-12)
    np.testing.assert_allclose(q[-1], result.goal, atol=1e-12)
    for prefix in ("qd", "qdd"):
        np.testing.assert_allclose(columns(header, table, prefix)[[0, -1]], 0.0, atol=1e-9)
    # not the best's rows
    assert len(t) != result.best_trajectory.n_samples


def test_another_members_torques_are_the_robots_inverse_dynamics(
    problem: TrajectoryProblem, other_csv: Path
) -> None:
    header, table = read_csv(other_csv)
    q, qd, qdd = (columns(header, table, p) for p in ("q", "qd", "qdd"))
    tau = problem.robot.inverse_dynamics(q, qd, qdd)
    np.testing.assert_allclose(columns(header, table, "tau"), tau, rtol=1e-12, atol=1e-9)


def coal_min_distance(problem: TrajectoryProblem, q: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(n,) smallest solid–obstacle distance [m] by coal called directly, solids placed by
    Pinocchio's updateGeometryPlacements, each obstacle at its pose at that instant."""
    robot, scene = problem.robot, problem.scene
    model, gm = robot.model, robot.collision_model
    data, gdata = model.createData(), gm.createData()
    poses = scene.obstacle_poses(t, in_base_frame=True)  # (n_obstacles, n, 4, 4)
    shapes = [ob.shape.to_coal() for ob in scene.obstacles]
    request, res = coal.DistanceRequest(), coal.DistanceResult()
    request.gjk_tolerance = 1e-9
    out = np.full(len(t), np.inf)
    for n in range(len(t)):
        pin.updateGeometryPlacements(model, data, gm, gdata, q[n])
        for s, g in enumerate(gm.geometryObjects):
            tf_s = coal.Transform3s(gdata.oMg[s].rotation, gdata.oMg[s].translation)
            for o, shape in enumerate(shapes):
                res.clear()
                tf_o = coal.Transform3s(poses[o, n, :3, :3], poses[o, n, :3, 3])
                d = coal.distance(g.geometry, tf_s, shape, tf_o, request, res)
                out[n] = min(out[n], d)
    return out


def test_another_members_distances_are_coals(problem: TrajectoryProblem, other_csv: Path) -> None:
    header, table = read_csv(other_csv)
    rows = np.array([0, 600, 1150, 1700, table.shape[0] - 1])
    q, t = columns(header, table, "q")[rows], table[rows, 0]
    ref = coal_min_distance(problem, q, t)
    assert np.isfinite(ref).all()
    np.testing.assert_allclose(table[rows, -1], ref, atol=1e-6)


def test_the_bests_csv_is_its_stored_certificate_samples(
    result: PlanningResult, tmp_path: Path
) -> None:
    stored = to_csv(result, tmp_path / "default.csv").read_bytes()
    assert to_csv(result, tmp_path / "zero.csv", member=0).read_bytes() == stored
    header, table = read_csv(tmp_path / "default.csv")
    np.testing.assert_array_equal(table[:, 0], result.best_trajectory.t)
    np.testing.assert_array_equal(columns(header, table, "q"), result.best_trajectory.q)


def test_the_bests_csv_with_a_replay_of_another_member_is_refused(
    result: PlanningResult, tmp_path: Path
) -> None:
    other = Replay.of(result, result.front.x[1])
    with pytest.raises(InvalidInputError, match="replay must show"):
        to_csv(result, tmp_path / "t.csv", replay=other)
    # the right replay is accepted and changes nothing
    out = to_csv(result, tmp_path / "m1.csv", member=1, replay=other)
    assert out.read_bytes() == to_csv(result, tmp_path / "b.csv", member=1).read_bytes()


def test_an_uncertified_member_is_refused_unless_allowed(
    result: PlanningResult, tmp_path: Path
) -> None:
    with pytest.raises(InvalidInputError, match="member 2 of the front is not certified"):
        to_csv(result, tmp_path / "t.csv", member=2)
    assert not (tmp_path / "t.csv").exists()
    _, table = read_csv(to_csv(result, tmp_path / "t.csv", member=2, allow_infeasible=True))
    assert table[-1, 0] == pytest.approx(1.5, abs=1e-12)
    assert table[:, -1].min() < result.certificate.margin  # it hits cube 1
    with pytest.raises(InvalidInputError, match="allow_infeasible"):
        to_csv(result, tmp_path / "t.csv", member=2, allow_infeasible=1)  # type: ignore[arg-type]


@pytest.mark.parametrize("bad", [3, -1, 1.5, "1", True])
def test_an_out_of_range_member_names_the_range(
    result: PlanningResult, tmp_path: Path, bad: object
) -> None:
    with pytest.raises(InvalidInputError, match="member") as info:
        to_csv(result, tmp_path / "t.csv", member=bad)  # type: ignore[arg-type]
    assert "2" in str(info.value)
    with pytest.raises(InvalidInputError, match="member"):
        motion.joint_motion(result, tmp_path / "f.png", member=bad)  # type: ignore[arg-type]


@pytest.fixture
def titles(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The suptitle of every figure joint_motion saves."""
    seen: list[str] = []
    save = motion.save_figure

    def spy(fig, path):  # type: ignore[no-untyped-def]
        seen.append(fig.get_suptitle())
        return save(fig, path)

    monkeypatch.setattr(motion, "save_figure", spy)
    return seen


@pytest.mark.parametrize(
    ("member", "words"),
    [
        (1, "member 1 of the front, T = 2.300 s (certified)"),
        pytest.param(  # drawing takes ~1.4 s a figure: the other two in the slow tier
            2, "member 2 of the front, T = 1.500 s (NOT certified)", marks=pytest.mark.slow
        ),
        pytest.param(
            None,
            "the best trade-off, T = 2.100 s (verified feasible at 1000 Hz)",
            marks=pytest.mark.slow,
        ),
    ],
)
def test_the_figure_of_a_member_is_a_png_whose_title_names_it(
    result: PlanningResult, tmp_path: Path, titles: list[str], member: int | None, words: str
) -> None:
    out = motion.joint_motion(result, tmp_path / "m.png", member=member)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len(titles) == 1
    assert words in titles[0]
