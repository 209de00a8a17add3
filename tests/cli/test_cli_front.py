"""Picking a member of the front: ``adept-traj front``, ``show --member``, the ROS export
of any member and the viewer's playback of it."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from adept_traj.analysis import best_tradeoff
from adept_traj.cli import main
from adept_traj.errors import InvalidInputError
from adept_traj.results import Front, PlanningResult, Replay, to_ros_joint_trajectory

OLD = Path(__file__).parents[1] / "data" / "result_v1"
_TINY = ["plan", "--pop", "8", "--gens", "2", "--no-html", "--no-plots", "--quiet", "--no-polish"]


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A tiny paper run (seed 1): a front of two certified members."""
    out = tmp_path_factory.mktemp("front") / "run"
    assert main([*_TINY, "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def run(run_dir: Path) -> PlanningResult:
    r = PlanningResult.load(run_dir)
    assert len(r.front) == 2
    assert r.front.n_certified == 2
    return r


@pytest.fixture(scope="module")
def one_failed(run: PlanningResult) -> PlanningResult:
    """``run`` with its non-best member marked as failing its certificate."""
    other = 1 - run.best.index
    feasible = np.ones(2, dtype=bool)
    feasible[other] = False
    fr = run.front
    return dataclasses.replace(
        run, front=Front(fr.x, fr.objectives, fr.constraints, feasible, n_certified=1)
    )


def _table(out: str) -> tuple[list[str], list[list[str]], list[str]]:
    """(header cells, rows of cells with the best mark as a first cell ``*`` or ``.``,
    trailing lines)."""
    lines = out.strip().splitlines()
    header = [c for c in lines[0].strip().split("  ") if c]
    rows, rest = [], []
    for line in lines[1:]:
        cells = line[2:].split()
        if line[:2] in ("* ", "  ") and cells[0].isdigit():
            rows.append(["*" if line[0] == "*" else ".", *cells])
        else:
            rest.append(line)
    return header, rows, rest


# ------------------------------------------------------------------------------ front
def test_front_lists_every_member_of_a_v1_result(capsys: pytest.CaptureFixture[str]) -> None:
    raw = json.loads((OLD / "result.json").read_text(encoding="utf-8"))
    assert main(["front", str(OLD), "--sort", "index"]) == 0
    out = capsys.readouterr().out
    header, rows, rest = _table(out)
    assert [h.strip() for h in header] == [
        "index",
        "T [s]",
        "z2 [N²·m²·s]",
        "z3 [-]",
        "z4 [m²]",
        "z5 [rad²/s⁵]",
        "z6 [rad²/s³]",
        "f_c [-]",
        "F_avg [-]",
        "certified",
        "clearance [m]",
        "T/T_lb [-]",
        "T/T_best [-]",
    ]
    n = len(raw["front"])
    assert [int(r[1]) for r in rows] == list(range(n))
    best = raw["best"]["index"]
    assert [int(r[1]) for r in rows if r[0] == "*"] == [best]
    # T is x[0] of each member, as stored; no v1 member other than the best is certified
    assert [float(r[2]) for r in rows] == pytest.approx([m["x"][0] for m in raw["front"]], 1e-5)
    assert [r[10] for r in rows] == ["no"] * n  # the v1 best failed its certificate
    assert [r[11] for r in rows if int(r[1]) != best] == ["-"] * (n - 1)
    assert float(rows[best][11]) == pytest.approx(raw["certificate"]["min_distance"], 1e-5)
    assert rest[0] == f"* best trade-off (member {best}); 0 of {n} members certified"
    assert rest[1].startswith("note: saved before every member was certified")


@pytest.mark.parametrize("descending", [False, True])
@pytest.mark.parametrize("column", ["T", "z2", "f_c", "F_avg"])
def test_front_sorts_by_any_column(
    column: str, descending: bool, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["front", str(OLD), "--sort", column] + (["--descending"] if descending else [])
    assert main(argv) == 0
    header, rows, _ = _table(capsys.readouterr().out)
    j = [h.split()[0] for h in header].index(column)
    values = [float(r[j + 1]) for r in rows]
    assert values == sorted(values, reverse=descending)
    assert sorted(int(r[1]) for r in rows) == list(range(len(rows)))


def test_front_scores_are_best_tradeoff_with_the_given_weights(
    capsys: pytest.CaptureFixture[str],
) -> None:
    weights = [0.5, 0.1, 0.1, 0.1, 0.1, 0.1]
    argv = ["front", str(OLD), "--sort", "index", "--weights", ",".join(map(str, weights))]
    assert main(argv) == 0
    _, rows, _ = _table(capsys.readouterr().out)
    choice = best_tradeoff(PlanningResult.load(OLD).front.objectives, weights)
    assert [float(r[8]) for r in rows] == pytest.approx(choice.f_c, rel=1e-5, abs=1e-9)
    assert [float(r[9]) for r in rows] == pytest.approx(choice.F_avg, rel=1e-5, abs=1e-9)


def test_front_of_a_certified_run(
    run_dir: Path, run: PlanningResult, capsys: pytest.CaptureFixture[str]
) -> None:
    """A version-2 result lists every certified member's clearance from its own stored
    certificate (the best's from its exact certificate)."""
    raw = json.loads((run_dir / "result.json").read_text(encoding="utf-8"))
    assert raw["version"] == 2
    assert main(["front", str(run_dir)]) == 0
    _, rows, rest = _table(capsys.readouterr().out)
    assert [r[10] for r in rows] == ["yes", "yes"]
    assert rest == [f"* best trade-off (member {run.best.index}); 2 of 2 members certified"]
    other = 1 - run.best.index
    member = raw["front"][other]["certificate"]
    cell = rows[other][11]
    assert cell.startswith("≥") != member["min_distance_exact"]
    assert float(cell.lstrip("≥")) == pytest.approx(member["min_distance"], rel=1e-5)
    best = float(rows[run.best.index][11])
    assert best == pytest.approx(raw["certificate"]["min_distance"], rel=1e-5)


def test_front_refuses_an_unknown_column(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["front", str(OLD), "--sort", "speed"])
    assert exc.value.code == 2
    assert "invalid choice: 'speed'" in capsys.readouterr().err


# ------------------------------------------------------------------------------ ROS export
def test_ros_export_of_another_member(run: PlanningResult) -> None:
    other = 1 - run.best.index
    x = run.front.x[other]
    msg = to_ros_joint_trajectory(run, member=other)
    assert (msg["member"], msg["best_tradeoff"], msg["certified"]) == (other, False, True)
    assert msg["warning"] is None
    # resampled at the certificate's rate over the member's own T, from start to goal
    points = msg["points"]
    assert len(points) == math.ceil(float(x[0]) * run.certificate.rate_hz - 1e-9) + 1
    end = points[-1]["time_from_start"]
    assert end["sec"] + end["nanosec"] * 1e-9 == pytest.approx(float(x[0]), abs=1e-9)
    assert points[0]["positions"] == pytest.approx(run.start, abs=1e-12)
    assert points[-1]["positions"] == pytest.approx(run.goal, abs=1e-12)
    assert float(x[0]) != float(run.best_x[0])  # another move than the best trade-off


def test_ros_export_of_the_best_member_is_the_default(run: PlanningResult) -> None:
    msg = to_ros_joint_trajectory(run, member=run.best.index)
    assert msg == to_ros_joint_trajectory(run)
    assert (msg["member"], msg["best_tradeoff"]) == (run.best.index, True)
    assert len(msg["points"]) == run.certificate.n_samples  # the stored dense samples


@pytest.mark.parametrize("member", [2, -1, True, 1.0, "1"])
def test_ros_export_names_the_valid_range(run: PlanningResult, member: object) -> None:
    with pytest.raises(InvalidInputError, match=r"member must be an integer in \[0, 1\]"):
        to_ros_joint_trajectory(run, member=member)  # type: ignore[arg-type]


def test_ros_export_refuses_an_uncertified_member(one_failed: PlanningResult) -> None:
    other = 1 - one_failed.best.index
    with pytest.raises(InvalidInputError, match=f"member {other} of the front is not certified"):
        to_ros_joint_trajectory(one_failed, member=other)
    msg = to_ros_joint_trajectory(one_failed, member=other, allow_infeasible=True, rate_hz=50)
    assert msg["certified"] is False
    assert msg["warning"].startswith(f"NOT CERTIFIED: member {other}")


def test_ros_export_refuses_the_replay_of_another_member(run: PlanningResult) -> None:
    other = 1 - run.best.index
    with pytest.raises(InvalidInputError, match=f"replay must show member {other}"):
        to_ros_joint_trajectory(run, member=other, replay=Replay.of(run))
    mine = Replay.of(run, run.front.x[other])
    assert to_ros_joint_trajectory(run, member=other, replay=mine, rate_hz=50)["member"] == other


# ------------------------------------------------------------------------------ viewer
def test_playback_of_another_member(run: PlanningResult) -> None:
    from adept_traj.viz.playback import build_animation

    other = 1 - run.best.index
    playback = build_animation(run, member=other, fps=10)
    assert (playback.member, playback.certified) == (other, True)
    assert playback.duration == float(run.front.x[other, 0])
    assert playback.tool_path.shape[0] > 2
    best = build_animation(run, fps=10)
    assert (best.member, best.duration) == (run.best.index, float(run.best_x[0]))
    # both moves start and end at the same tool positions
    assert np.allclose(playback.tool_path[[0, -1]], best.tool_path[[0, -1]])
    assert not np.allclose(playback.q[len(playback.q) // 2], best.q[len(best.q) // 2])


def test_show_refuses_a_bad_member_before_the_server_starts(
    run_dir: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["show", str(run_dir), "--member", "7"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["adept-traj: error: member must be an integer in [0, 1]; got 7"]


def test_show_refuses_an_uncertified_member(
    one_failed: PlanningResult, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = one_failed.save(tmp_path / "one_failed")
    other = 1 - one_failed.best.index
    assert main(["show", str(folder), "--member", str(other)]) == 2
    err = capsys.readouterr().err
    assert f"member {other} of the front is not certified" in err
    assert "--allow-infeasible" in err


def test_front_lists_the_best_tradeoff_first_by_default(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Default order: the result's best, then certified members by best_tradeoff's order,
    then the others in that order (the v1 result certified none)."""
    r = PlanningResult.load(OLD)
    assert main(["front", str(OLD)]) == 0
    _, rows, _ = _table(capsys.readouterr().out)
    order = [int(k) for k in best_tradeoff(r.front.objectives).order]
    best = r.best.index
    assert [int(row[1]) for row in rows] == [best, *(k for k in order if k != best)]
    assert rows[0][0] == "*"


def test_front_into_a_closed_pipe_ends_quietly(tmp_path: Path) -> None:
    import subprocess
    import sys

    code = "import sys; from adept_traj.cli import main; sys.exit(main(['front', sys.argv[1]]))"
    proc = subprocess.Popen([sys.executable, "-c", code, str(OLD)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)  # fmt: skip
    proc.stdout.close()  # no reader left before the listing is written: EPIPE, as after head
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 0, err
    assert "Broken pipe" not in err
    assert err == ""
