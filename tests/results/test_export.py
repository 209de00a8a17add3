"""adept_traj.results.ros_export: the CSV export is the certificate's grid (the
best_trajectory.csv of earlier versions, which still loads); the ROS JointTrajectory
dictionary and JSON file carry the dense trajectory exactly, with a correct
time_from_start, or the spline resampled at a given rate; bad inputs are refused.
adept_traj.results.Replay: its samples are the certificate's, its torques the robot's
inverse dynamics; the export resamples through it, never through the full problem."""

from __future__ import annotations

import csv
import itertools
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from adept_traj.errors import InvalidInputError
from adept_traj.problem import TrajectoryProblem
from adept_traj.results import PlanningResult, Replay, RobotInfo
from adept_traj.results.ros_export import (
    MAX_ROS_POINTS,
    ros_duration,
    save_ros_joint_trajectory,
    to_csv,
    to_ros_joint_trajectory,
)
from adept_traj.testing.paper_moves import lift_then_lower, single_result


@pytest.fixture(scope="module")
def result(problem: TrajectoryProblem) -> PlanningResult:
    r = single_result(problem, lift_then_lower(problem), rate_hz=1000.0)
    assert r.feasible
    return r


@pytest.fixture(scope="module")
def infeasible(problem: TrajectoryProblem) -> PlanningResult:
    r = single_result(problem, problem.trajectory.straight_line(1.5), rate_hz=200.0)
    assert not r.feasible  # the straight move hits cube 1
    return r


def column(msg: dict[str, Any], key: str) -> np.ndarray:
    return np.array([p[key] for p in msg["points"]], dtype=float)


def times(msg: dict[str, Any]) -> np.ndarray:
    return np.array(
        [
            p["time_from_start"]["sec"] + 1e-9 * p["time_from_start"]["nanosec"]
            for p in msg["points"]
        ]
    )


# ============================================================================ CSV
def test_csv_is_the_certificate_grid_of_earlier_result_folders(
    result: PlanningResult, tmp_path: Path
) -> None:
    """to_csv writes the certificate's grid, the best_trajectory.csv of folders written
    before issue #29: such a folder loads."""
    folder = result.save(tmp_path / "run")
    out = to_csv(result, tmp_path / "new" / "trajectory.csv")
    assert out == tmp_path / "new" / "trajectory.csv"
    assert (folder / "best_trajectory.csv").read_bytes() != out.read_bytes()  # fixed step now
    (folder / "best_trajectory.csv").write_bytes(out.read_bytes())
    assert PlanningResult.load(folder) == result


def test_csv_round_trip(result: PlanningResult, tmp_path: Path) -> None:
    rows = list(csv.reader(to_csv(result, tmp_path / "t.csv").open(encoding="utf-8")))
    names = result.robot.joint_names
    header = ["t"]
    for prefix in ("q", "qd", "qdd", "qddd", "tau"):
        header += [f"{prefix}_{n}" for n in names]
    assert rows[0] == [*header, "min_distance"]
    table = np.array(rows[1:], dtype=float)
    d = result.best_trajectory
    expected = np.column_stack([d.t, d.q, d.qd, d.qdd, d.qddd, d.tau, d.min_distance])
    assert table.shape == expected.shape
    assert np.array_equal(table, expected)  # exact: shortest round-trip floats


def test_csv_bad_input(tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match="PlanningResult"):
        to_csv("result", tmp_path / "t.csv")  # type: ignore[arg-type]


# ============================================================================ ROS
def test_ros_dense_round_trip(result: PlanningResult) -> None:
    msg = to_ros_joint_trajectory(result)
    assert list(msg) == [
        "certified",
        "certificate_rate_hz",
        "warning",
        "member",
        "best_tradeoff",
        "header",
        "joint_names",
        "points",
    ]
    assert msg["header"] == {"frame_id": ""}
    assert msg["joint_names"] == ["joint1", "joint2", "joint3", "joint4"]
    assert msg["joint_names"] == list(result.robot.joint_names)
    d = result.best_trajectory
    assert len(msg["points"]) == d.t.size == result.certificate.n_samples
    assert set(msg["points"][0]) == {
        "positions",
        "velocities",
        "accelerations",
        "effort",
        "time_from_start",
    }
    for key, expected in (
        ("positions", d.q),
        ("velocities", d.qd),
        ("accelerations", d.qdd),
        ("effort", d.tau),
    ):
        assert np.array_equal(column(msg, key), expected), key
    np.testing.assert_allclose(times(msg), d.t, rtol=0, atol=0.6e-9)


def test_time_from_start(result: PlanningResult) -> None:
    points = to_ros_joint_trajectory(result)["points"]
    stamps = [(p["time_from_start"]["sec"], p["time_from_start"]["nanosec"]) for p in points]
    for sec, nanosec in stamps:
        assert type(sec) is int
        assert type(nanosec) is int
        assert sec >= 0
        assert 0 <= nanosec < 1_000_000_000
    assert stamps[0] == (0, 0)
    assert all(a < b for a, b in itertools.pairwise(stamps))  # strictly increasing
    T = float(result.best_x[0])
    assert stamps[-1] == divmod(round(T * 1e9), 1_000_000_000)
    assert any(sec >= 1 for sec, _ in stamps)  # T = 2.1 s: the seconds carry


@pytest.mark.parametrize(
    ("t", "expected"),
    [
        (0.0, (0, 0)),
        (1.5, (1, 500_000_000)),
        (2.1, (2, 100_000_000)),
        (0.000_000_001, (0, 1)),
        (2.999_999_999_9, (3, 0)),  # rounds up to the next second, not nanosec = 10⁹
        (12.345_678_901_2, (12, 345_678_901)),
    ],
)
def test_duration_split(t: float, expected: tuple[int, int]) -> None:
    assert ros_duration(t) == {"sec": expected[0], "nanosec": expected[1]}


def test_resampled_at_the_certificate_rate_equals_the_dense_samples(
    result: PlanningResult,
) -> None:
    msg = to_ros_joint_trajectory(result, rate_hz=result.certificate.rate_hz)
    d = result.best_trajectory
    for key, expected in (
        ("positions", d.q),
        ("velocities", d.qd),
        ("accelerations", d.qdd),
        ("effort", d.tau),
    ):
        np.testing.assert_allclose(column(msg, key), expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(times(msg), d.t, atol=1e-9)


@pytest.mark.parametrize("rate", [50, 125.0, np.float64(333.3)])
def test_resampled_from_the_spline(
    result: PlanningResult, problem: TrajectoryProblem, rate: float
) -> None:
    msg = to_ros_joint_trajectory(result, rate_hz=rate)
    x = result.best_x
    T = float(x[0])
    n = math.ceil(T * float(rate) - 1e-9) + 1
    assert len(msg["points"]) == n
    t = times(msg)
    assert t[0] == 0.0
    assert abs(t[-1] - T) <= 1e-9
    assert np.diff(t).max() <= 1.0 / float(rate) + 1e-9
    exact = problem.trajectory.sample(x, np.linspace(0.0, 1.0, n))
    np.testing.assert_allclose(column(msg, "positions"), exact.q, atol=1e-15)
    np.testing.assert_allclose(column(msg, "velocities"), exact.qd, atol=1e-12)
    np.testing.assert_allclose(column(msg, "accelerations"), exact.qdd, atol=1e-12)
    tau = problem.robot.inverse_dynamics(exact.q, exact.qd, exact.qdd)
    np.testing.assert_allclose(column(msg, "effort"), tau, atol=1e-9)
    np.testing.assert_allclose(msg["points"][0]["positions"], result.start, atol=1e-12)
    np.testing.assert_allclose(msg["points"][-1]["positions"], result.goal, atol=1e-12)
    np.testing.assert_allclose(msg["points"][0]["velocities"], 0.0, atol=1e-12)
    np.testing.assert_allclose(msg["points"][-1]["velocities"], 0.0, atol=1e-12)


@pytest.mark.parametrize(
    "rate",
    [0, -10.0, math.nan, math.inf, True, "100", [100.0]],
    ids=["zero", "negative", "nan", "inf", "bool", "str", "list"],
)
def test_bad_rate(result: PlanningResult, rate: object) -> None:
    with pytest.raises(InvalidInputError, match="rate_hz"):
        to_ros_joint_trajectory(result, rate_hz=rate)  # type: ignore[arg-type]


def test_too_many_points(result: PlanningResult) -> None:
    rate = 2.0 * MAX_ROS_POINTS / float(result.best_x[0])
    with pytest.raises(InvalidInputError, match="at most"):
        to_ros_joint_trajectory(result, rate_hz=rate)


def test_infeasible_is_refused_unless_allowed(infeasible: PlanningResult, tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match="not verified feasible"):
        to_ros_joint_trajectory(infeasible)
    with pytest.raises(InvalidInputError, match="allow_infeasible"):
        save_ros_joint_trajectory(infeasible, tmp_path / "t.json")
    assert not (tmp_path / "t.json").exists()
    msg = to_ros_joint_trajectory(infeasible, allow_infeasible=True)
    assert len(msg["points"]) == infeasible.certificate.n_samples


def test_certified_export_says_so(result: PlanningResult, tmp_path: Path) -> None:
    out = save_ros_joint_trajectory(result, tmp_path / "t.json", rate_hz=100)
    data = json.loads(out.read_text(encoding="utf-8"))
    assert data["certified"] is True
    assert data["certificate_rate_hz"] == 1000.0  # certified at 1 kHz, exported at 100 Hz
    assert data["warning"] is None
    assert out.read_text(encoding="utf-8").splitlines()[1:4] == [
        '  "certified": true,',
        '  "certificate_rate_hz": 1000.0,',
        '  "warning": null,',
    ]


def test_uncertified_export_says_so(infeasible: PlanningResult, tmp_path: Path) -> None:
    """An export forced with allow_infeasible=True must not look like a certified one."""
    out = save_ros_joint_trajectory(infeasible, tmp_path / "t.json", allow_infeasible=True)
    data = json.loads(out.read_text(encoding="utf-8"))
    assert data["certified"] is False
    assert data["certificate_rate_hz"] == 200.0
    warning = data["warning"]
    assert warning.startswith("NOT CERTIFIED")
    assert infeasible.certificate.violations  # the straight move hits cube 1
    for violation in infeasible.certificate.violations:
        assert violation in warning
    assert "cube1" in warning
    assert len(data["points"]) == infeasible.certificate.n_samples
    assert data == to_ros_joint_trajectory(infeasible, allow_infeasible=True)


@pytest.mark.parametrize("flag", ["yes", 1, None])
def test_allow_infeasible_must_be_a_bool(infeasible: PlanningResult, flag: object) -> None:
    with pytest.raises(InvalidInputError, match="allow_infeasible"):
        to_ros_joint_trajectory(infeasible, allow_infeasible=flag)  # type: ignore[arg-type]


def test_bad_result() -> None:
    with pytest.raises(InvalidInputError, match="PlanningResult"):
        to_ros_joint_trajectory({"points": []})  # type: ignore[arg-type]


def test_saved_json_is_valid_and_equal(result: PlanningResult, tmp_path: Path) -> None:
    out = save_ros_joint_trajectory(result, tmp_path / "ros" / "trajectory.json")
    assert out == tmp_path / "ros" / "trajectory.json"
    text = out.read_text(encoding="utf-8")

    def reject(constant: str) -> None:
        raise AssertionError(f"JSON holds {constant}")

    data = json.loads(text, parse_constant=reject)
    assert "NaN" not in text
    assert "Infinity" not in text
    assert data == to_ros_joint_trajectory(result)  # exact floats after the round trip
    assert len(text.splitlines()) == len(data["points"]) + 11  # one point per line


def test_saved_json_resampled(result: PlanningResult, tmp_path: Path) -> None:
    out = save_ros_joint_trajectory(result, tmp_path / "t.json", rate_hz=100)
    data = json.loads(out.read_text(encoding="utf-8"))
    assert len(data["points"]) == math.ceil(float(result.best_x[0]) * 100 - 1e-9) + 1
    assert data == to_ros_joint_trajectory(result, rate_hz=100)


# ============================================================================ Replay
@pytest.fixture(scope="module")
def replay(result: PlanningResult) -> Replay:
    return Replay.of(result)


def test_replay_samples_equal_the_certificate(result: PlanningResult, replay: Replay) -> None:
    d = result.certificate.dense
    assert replay.duration == float(result.best_x[0])
    at_times = replay.sample(d.t, orders=(0, 1, 2, 3))
    for name in ("q", "qd", "qdd", "qddd"):
        expected = getattr(d, name)
        scale = np.abs(expected).max()
        np.testing.assert_allclose(getattr(at_times, name), expected, rtol=0, atol=1e-12 * scale)
    uniform = replay.sample_uniform(d.t.size, orders=(0, 1, 2, 3))  # the certificate's grid
    for name in ("t", "q", "qd", "qdd", "qddd"):
        np.testing.assert_array_equal(getattr(uniform, name), getattr(d, name), err_msg=name)


def test_replay_torques_are_the_inverse_dynamics(
    result: PlanningResult, replay: Replay, problem: TrajectoryProblem
) -> None:
    smp = replay.sample(np.linspace(0.0, replay.duration, 57))
    tau = replay.torques(smp)
    assert tau.shape == (57, 4)
    np.testing.assert_array_equal(tau, problem.robot.inverse_dynamics(smp.q, smp.qd, smp.qdd))
    d = result.certificate.dense
    np.testing.assert_array_equal(replay.torques(replay.sample_uniform(d.t.size)), d.tau)


def test_replay_of_uses_the_given_robot_and_scene(
    result: PlanningResult, problem: TrajectoryProblem
) -> None:
    r = Replay.of(result, result.front.x[0], robot=problem.robot, scene=problem.scene)
    assert r.robot is problem.robot
    assert r.scene is problem.scene
    np.testing.assert_array_equal(r.x, result.front.x[0])
    assert not r.x.flags.writeable


def test_replay_bad_inputs(result: PlanningResult, replay: Replay) -> None:
    robot, scene, traj, x = replay.robot, replay.scene, replay.trajectory, replay.x
    T = replay.duration
    cases: list[tuple[str, Any]] = [
        ("result", lambda: Replay.of("result")),  # type: ignore[arg-type]
        ("robot", lambda: Replay.of(result, robot="robot")),  # type: ignore[arg-type]
        ("robot", lambda: Replay("robot", scene, traj, x)),  # type: ignore[arg-type]
        ("scene", lambda: Replay(robot, {}, traj, x)),  # type: ignore[arg-type]
        ("trajectory", lambda: Replay(robot, scene, None, x)),  # type: ignore[arg-type]
        ("x", lambda: Replay(robot, scene, traj, x[:-1])),
        ("x", lambda: Replay(robot, scene, traj, np.full_like(x, np.nan))),
        ("times", lambda: replay.sample(np.zeros((2, 2)))),
        ("times", lambda: replay.sample([-0.1, 0.0])),
        ("times", lambda: replay.sample([0.0, T + 0.1])),
        ("n_samples", lambda: replay.sample_uniform(1)),
        ("n_samples", lambda: replay.sample_uniform(2.5)),
        ("n_samples", lambda: replay.sample_uniform(True)),
        ("samples", lambda: replay.torques({"q": x})),  # type: ignore[arg-type]
        ("samples", lambda: replay.torques(replay.sample([0.0, T], orders=(0,)))),
    ]
    for name, call in cases:
        with pytest.raises(InvalidInputError, match=name):
            call()


def test_ros_export_resamples_without_the_problem(
    result: PlanningResult, replay: Replay, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The export resamples the spline through a Replay: neither result.problem() nor a
    TrajectoryProblem (collision tables) is built; a given replay spares the robot reload."""
    expected = to_ros_joint_trajectory(result, rate_hz=100)

    def forbidden(*args: object, **kwargs: object) -> None:
        raise AssertionError("the export built the full problem")

    monkeypatch.setattr(PlanningResult, "problem", forbidden)
    monkeypatch.setattr(TrajectoryProblem, "__init__", forbidden)
    assert to_ros_joint_trajectory(result, rate_hz=100) == expected
    monkeypatch.setattr(RobotInfo, "load", forbidden)
    assert to_ros_joint_trajectory(result, rate_hz=100, replay=replay) == expected


def test_ros_export_refuses_another_replay(result: PlanningResult, replay: Replay) -> None:
    other = Replay(replay.robot, replay.scene, replay.trajectory, longer_move(result))
    for bad in (other, "replay"):
        with pytest.raises(InvalidInputError, match="replay"):
            to_ros_joint_trajectory(result, rate_hz=100, replay=bad)  # type: ignore[arg-type]
        with pytest.raises(InvalidInputError, match="replay"):
            to_ros_joint_trajectory(result, replay=bad)  # type: ignore[arg-type]


def longer_move(result: PlanningResult) -> np.ndarray:
    """The best solution with a 10 % longer travel time: another move."""
    x = result.best_x.copy()
    x[0] *= 1.1
    return x
