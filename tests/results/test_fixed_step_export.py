"""adept_traj.export: a member sampled at a fixed step, checked against an independent
reference (scipy's BSpline on the uniform knot vector of the cubic B-spline, built here
from the control points), the grid's last sample at T, the CSV / ROS JSON / ROS YAML files
read back by csv, json and yaml, uncertified members refused unless allowed, bad dt and
member named with their range; and ``adept-traj export`` writes the same files."""

from __future__ import annotations

import csv
import json
import math
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest
from scipy.interpolate import BSpline

from adept_traj.cli import main
from adept_traj.errors import InvalidInputError, ResultFormatError
from adept_traj.export import (
    FORMATS,
    MAX_SAMPLES,
    export_member,
    fixed_step_times,
    ros_message,
    sample_member,
)
from adept_traj.problem import TrajectoryProblem
from adept_traj.results import PlanningResult
from adept_traj.scene.robot_motion import JointTrajectory
from adept_traj.testing.paper_moves import lift_then_lower, single_result

RATE = 1000.0  # [Hz]


@pytest.fixture(scope="module")
def result(problem: TrajectoryProblem) -> PlanningResult:
    """Members: 0 the best (lift-then-lower, T = 2.1 s, certified), 1 the same move at
    T = 2.3 s (certified), 2 the straight line (hits cube 1, not certified)."""
    x = np.stack(
        [
            lift_then_lower(problem),
            lift_then_lower(problem, T=2.3),
            problem.trajectory.straight_line(1.5),
        ]
    )
    result = single_result(problem, x, RATE, certified=np.array([True, True, False]))
    assert result.feasible
    return result


def reference(result: PlanningResult, member: int, t: np.ndarray) -> list[np.ndarray]:
    """q, qd, qdd (n, nq) at times t [s] by scipy's BSpline: control points rebuilt from
    the decision vector's layout ([T, free points joint-major], 3 points fixed at each
    end on start / goal), knots (i − 3)/S, i = 0 … n_c + 3."""
    x = result.front.x[member]
    T, nq = float(x[0]), len(result.start)
    free = x[1:].reshape(nq, -1).T  # (n_free, nq)
    P = np.vstack([np.tile(result.start, (3, 1)), free, np.tile(result.goal, (3, 1))])
    S = P.shape[0] - 3
    knots = (np.arange(P.shape[0] + 4) - 3.0) / S
    spline = BSpline(knots, P, 3, extrapolate=False)
    s = t / T
    return [spline.derivative(r)(s) / T**r if r else spline(s) for r in range(3)]


def test_the_grid_is_a_fixed_step_ending_at_T() -> None:
    t = fixed_step_times(2.1, 0.001)
    assert t.shape == (2101,)
    # each t_k the double nearest to k ms (Fraction: exact rational arithmetic), so that it
    # reads as k ms: 1.396, where 1396 * 0.001 is 1.3960000000000001
    assert np.array_equal(t[:-1], [float(Fraction(k, 1000)) for k in range(2100)])
    assert [Decimal(repr(v)) for v in t[:-1].tolist()] == [Decimal(k) / 1000 for k in range(2100)]
    assert repr(float(t[1396])) == "1.396" != repr(1396 * 0.001)
    assert t[-1] == 2.1
    t = fixed_step_times(1.0005, 0.001)  # last step shorter: 0.5 ms
    assert t.shape == (1002,)
    assert t[-2] == pytest.approx(1.0)
    assert t[-1] == 1.0005
    assert np.all(np.diff(t) > 0)
    assert np.array_equal(fixed_step_times(0.3, 0.3), [0.0, 0.3])
    t = fixed_step_times(2.1, 0.0003)  # 0.3 ms: 7 · 0.0003 reads 0.0021
    read = [Decimal(repr(v)) for v in t[:-1].tolist()]
    assert read == [Decimal(3 * k) / 10_000 for k in range(7000)]
    t = fixed_step_times(2.0, 1 / 3)  # no short decimal: k · dt, the product of doubles
    assert np.array_equal(t[:-1], np.arange(6) * (1 / 3))


@pytest.mark.parametrize("dt", [0.0, -0.001, 5.0, 1e-9, math.nan, "1ms", True])
def test_a_bad_dt_is_named_with_its_range(dt: object) -> None:
    with pytest.raises(InvalidInputError, match="dt"):
        fixed_step_times(2.1, dt)


def test_dt_out_of_range_names_the_value_and_the_range() -> None:
    with pytest.raises(InvalidInputError) as info:
        fixed_step_times(2.1, 5.0)
    assert "dt = 5 s" in str(info.value)
    assert f"T/{MAX_SAMPLES - 1}" in str(info.value)
    assert "T = 2.1 s" in str(info.value)


@pytest.mark.parametrize("member", [0, 1])
def test_samples_equal_scipys_bspline(result: PlanningResult, member: int) -> None:
    tr = sample_member(result, member, dt=0.001)
    T = float(result.front.x[member, 0])
    assert tr.t[-1] == T
    assert tr.t.shape == (math.ceil(T / 0.001 - 1e-9) + 1,)
    for got, want in zip((tr.q, tr.qd, tr.qdd), reference(result, member, tr.t), strict=True):
        scale = max(1.0, float(np.abs(want).max()))
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(tr.q[0], result.start, atol=1e-15)
    np.testing.assert_allclose(tr.q[-1], result.goal, atol=1e-12)
    np.testing.assert_allclose(tr.qd[[0, -1]], 0.0, atol=1e-12)
    np.testing.assert_allclose(tr.qdd[[0, -1]], 0.0, atol=1e-9)


def test_an_uncertified_member_is_refused_unless_allowed(result: PlanningResult) -> None:
    with pytest.raises(InvalidInputError, match=r"member 2 .*not certified.*allow_uncertified"):
        sample_member(result, 2)
    tr = sample_member(result, 2, dt=0.01, allow_uncertified=True)
    assert not tr.certified
    msg = ros_message(tr)
    assert msg["certified"] is False
    assert "NOT CERTIFIED" in msg["warning"]


@pytest.mark.parametrize("member", [-1, 3, 1.5, "1"])
def test_a_bad_member_names_the_range(result: PlanningResult, member: object) -> None:
    with pytest.raises(InvalidInputError, match=r"member.*2"):
        sample_member(result, member)


def test_the_three_formats_read_back(result: PlanningResult, tmp_path: Path) -> None:
    yaml = pytest.importorskip("yaml")
    tr = sample_member(result, 1, dt=0.002)
    paths = {f: export_member(result, tmp_path / f, member=1, format=f, dt=0.002) for f in FORMATS}
    rows = list(csv.reader(paths["csv"].open(encoding="utf-8")))
    names = result.robot.joint_names
    assert rows[0] == [
        "t [s]",
        *("q_joint1 [rad]", "q_joint2 [rad]", "q_joint3 [m]", "q_joint4 [rad]"),
        *("qd_joint1 [rad/s]", "qd_joint2 [rad/s]", "qd_joint3 [m/s]", "qd_joint4 [rad/s]"),
        *("qdd_joint1 [rad/s^2]", "qdd_joint2 [rad/s^2]", "qdd_joint3 [m/s^2]"),
        "qdd_joint4 [rad/s^2]",
    ]
    table = np.array(rows[1:], dtype=float)
    assert np.array_equal(table, np.column_stack([tr.t, tr.q, tr.qd, tr.qdd]))  # exact
    for fmt, load in (("ros-json", json.loads), ("ros-yaml", yaml.safe_load)):
        msg = load(paths[fmt].read_text(encoding="utf-8"))
        assert msg == ros_message(tr), fmt
        assert msg["joint_names"] == list(names)
        assert msg["member"] == 1
        assert msg["certified"] is True
        assert msg["warning"] is None
        stamps = [p["time_from_start"] for p in msg["points"]]
        secs = np.array([d["sec"] + 1e-9 * d["nanosec"] for d in stamps])
        np.testing.assert_allclose(secs, tr.t, atol=1e-9)
        assert all(0 <= d["nanosec"] < 10**9 for d in stamps)
        assert np.array_equal([p["positions"] for p in msg["points"]], tr.q)
        assert np.array_equal([p["accelerations"] for p in msg["points"]], tr.qdd)


def test_a_bad_format_is_refused(result: PlanningResult, tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match="csv, ros-json, ros-yaml"):
        export_member(result, tmp_path / "x", format="xml")


def test_the_command_writes_the_same_file(
    result: PlanningResult, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = result.save(tmp_path / "run")
    out = tmp_path / "m1.yaml"
    code = main(["export", str(folder), "--member", "1", "--format", "ros-yaml", "--dt", "0.002",
                 "--output", str(out)])  # fmt: skip
    assert code == 0
    want = export_member(result, tmp_path / "want.yaml", member=1, format="ros-yaml", dt=0.002)
    assert out.read_bytes() == want.read_bytes()
    assert str(out) in capsys.readouterr().out
    assert main(["export", str(folder), "--member", "2"]) == 2
    assert "not certified" in capsys.readouterr().err
    assert main(["export", str(folder), "--member", "7"]) == 2
    assert "[0, 2]" in capsys.readouterr().err
    assert main(["export", str(folder), "--dt", "0"]) == 2
    assert "dt" in capsys.readouterr().err
    code = main(["export", str(folder), "--member", "2", "--allow-uncertified",
                 "--output", str(tmp_path / "m2.csv")])  # fmt: skip
    assert code == 0
    assert (tmp_path / "m2.csv").exists()


# ============================================================================ best_trajectory.csv
def test_best_trajectory_csv_is_the_export_of_the_best_at_one_millisecond(
    result: PlanningResult, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The result folder's file is, byte for byte, what ``adept-traj export DIR`` writes (one
    mechanism), at t = 0, 1 ms, 2 ms, ..., the last row at T, and scipy's B-spline."""
    folder = result.save(tmp_path / "run")
    stored = (folder / "best_trajectory.csv").read_text(encoding="utf-8")
    assert main(["export", str(folder), "--output", "-"]) == 0
    assert capsys.readouterr().out == stored
    assert export_member(result, tmp_path / "e.csv").read_text(encoding="utf-8") == stored
    rows = list(csv.reader(stored.splitlines()))
    assert rows[0][:2] == ["t [s]", "q_joint1 [rad]"]
    table = np.array(rows[1:], dtype=float)
    T = float(result.front.x[0, 0])
    assert T == 2.1
    assert table.shape == (2101, 13)
    assert [Decimal(row[0]) for row in rows[1:-1]] == [Decimal(k) / 1000 for k in range(2100)]
    assert table[-1, 0] == T
    q, qd, qdd = reference(result, 0, table[:, 0])
    np.testing.assert_allclose(table[:, 1:5], q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(table[:, 5:9], qd, rtol=0, atol=1e-10)
    np.testing.assert_allclose(table[:, 9:13], qdd, rtol=0, atol=1e-8)
    np.testing.assert_allclose(table[-1, 1:5], result.goal, rtol=0, atol=1e-15)  # at rest
    np.testing.assert_allclose(table[-1, 5:], 0.0, atol=1e-9)


def test_best_trajectory_csv_of_a_move_not_a_whole_number_of_steps(
    problem: TrajectoryProblem, tmp_path: Path
) -> None:
    r = single_result(problem, lift_then_lower(problem, T=2.1004), RATE)
    folder = r.save(tmp_path / "odd")
    table = np.loadtxt(folder / "best_trajectory.csv", delimiter=",", skiprows=1)
    assert table.shape[0] == 2102  # 0 … 2.1 every 1 ms, then T
    np.testing.assert_array_equal(table[:-1, 0], [float(Fraction(k, 1000)) for k in range(2101)])
    assert table[-1, 0] == 2.1004
    assert PlanningResult.load(folder) == r


def test_a_changed_sample_of_best_trajectory_csv_is_refused_on_load(
    result: PlanningResult, tmp_path: Path
) -> None:
    folder = result.save(tmp_path / "run")
    path = folder / "best_trajectory.csv"
    lines = path.read_text(encoding="utf-8").splitlines()
    cells = lines[100].split(",")
    cells[2] = repr(float(cells[2]) + 1e-9)  # q_joint2, 1 nrad off
    lines[100] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    with pytest.raises(ResultFormatError, match=r"row 100, column q_joint2 \[rad\]"):
        PlanningResult.load(folder)


def test_best_trajectory_csv_is_a_second_robots_joint_table(
    result: PlanningResult, tmp_path: Path
) -> None:
    folder = result.save(tmp_path / "run")
    table = JointTrajectory.from_csv(folder / "best_trajectory.csv")
    assert table.q.shape == (2101, 4)
    q, _, _ = reference(result, 0, table.times)
    np.testing.assert_allclose(table.q, q, rtol=0, atol=1e-12)
