"""PlanningResult: save/load round trip, JSON without NaN/inf, CSV files, bad folders."""

from __future__ import annotations

import csv
import dataclasses
import json
import math
import shutil
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from adept_traj import Robot, Scene
from adept_traj.certification import certify, certify_members
from adept_traj.errors import AdeptTrajError, InvalidInputError
from adept_traj.problem import TrajectoryProblem
from adept_traj.results import (
    FORMAT,
    NO_FEASIBLE_WARNING,
    VERSION,
    BestSolution,
    Front,
    GenerationRecord,
    Metrics,
    PlanningResult,
    ResultFormatError,
    RobotInfo,
    Timing,
)
from adept_traj.testing.paper_moves import lift_then_lower


def make_result(problem: TrajectoryProblem, x: np.ndarray, **overrides: Any) -> PlanningResult:
    """A result of version 2: the members feasible at the optimiser's samples certified."""
    ev = problem.evaluate_batch(x)
    summaries = certify_members(problem, x, np.flatnonzero(ev.feasible))
    certified = np.array([s is not None and s.feasible for s in summaries])
    front = Front(x, ev.objectives, ev.constraints, certified, int(certified.sum()), summaries)
    kwargs: dict[str, Any] = {
        "algorithm": "NSGA-II",
        "algorithm_settings": {"pop_size": np.int64(100), "eta_c": 15.0, "ops": ("sbx", "pm")},
        "seed": 7,
        "front": front,
        "best": BestSolution(0, f_c=0.25, f_avg=0.5),
        "certificate": certify(problem, x[0]),
        "timing": Timing(total_s=12.5, evaluation_s=10.0, n_evaluations=300, n_generations=3),
        "metrics": Metrics(ssm=0.1, rni=1.0, hv=0.42, hv_reference_point=np.full(6, 1.1)),
        "history": [GenerationRecord(1, 100, 0, None), GenerationRecord(2, 200, 2, 0.4)],
    }
    kwargs.update(overrides)
    return PlanningResult.from_problem(problem, **kwargs)


@pytest.fixture(scope="module")
def result(problem: TrajectoryProblem) -> PlanningResult:
    x = np.vstack(
        [
            lift_then_lower(problem),
            lift_then_lower(problem, T=2.2),
            problem.trajectory.straight_line(1.5),  # collides: infeasible member
        ]
    )
    return make_result(problem, x)


@pytest.fixture(scope="module")
def saved_once(result: PlanningResult, tmp_path_factory: pytest.TempPathFactory) -> Path:
    return result.save(tmp_path_factory.mktemp("results") / "run")


@pytest.fixture
def saved(saved_once: Path, tmp_path: Path) -> Path:
    """A fresh copy of the saved result folder (tests may damage it)."""
    return Path(shutil.copytree(saved_once, tmp_path / "run"))


def load_json(folder: Path) -> dict[str, Any]:
    def reject(constant: str) -> None:
        raise AssertionError(f"JSON holds {constant}")

    return json.loads((folder / "result.json").read_text(encoding="utf-8"), parse_constant=reject)


def dump_json(folder: Path, data: dict[str, Any]) -> None:
    (folder / "result.json").write_text(json.dumps(data), encoding="utf-8")


# ----------------------------------------------------------------------------- round trip
def test_round_trip(result: PlanningResult, saved: Path) -> None:
    assert sorted(p.name for p in saved.iterdir()) == [
        "best_trajectory.csv",
        "front.csv",
        "result.json",
    ]
    loaded = PlanningResult.load(saved)
    assert loaded == result
    for f in dataclasses.fields(PlanningResult):
        assert type(getattr(loaded, f.name)) is type(getattr(result, f.name)), f.name
    assert isinstance(loaded.start, np.ndarray)
    assert isinstance(loaded.front.x, np.ndarray)
    assert loaded.front.feasible.dtype == bool
    assert isinstance(loaded.certificate.dense.q, np.ndarray)
    np.testing.assert_array_equal(loaded.certificate.dense.tau, result.certificate.dense.tau)
    assert loaded.problem_settings == result.problem_settings
    assert loaded.scene == result.scene
    assert loaded.history == result.history
    assert loaded.versions == result.versions
    assert loaded.certificate == result.certificate
    assert loaded.certificate.feasible
    # Saving the loaded result again writes the same bytes.
    again = loaded.save(saved.parent / "again")
    for name in ("result.json", "front.csv", "best_trajectory.csv"):
        assert (again / name).read_bytes() == (saved / name).read_bytes()


def test_properties(result: PlanningResult, problem: TrajectoryProblem) -> None:
    assert result.front_objectives.shape == (3, 6)
    np.testing.assert_array_equal(result.best_objectives, result.front.objectives[0])
    assert result.best_objectives[3] > 0  # z4 positive
    assert len(result.feasible_front) == 2
    assert result.feasible_front.feasible.all()
    assert result.gap == pytest.approx(2.1 / problem.lower_bound.T_min)
    assert result.warning is None
    assert result.feasible  # the best solution's certificate
    assert result.robot == RobotInfo(
        "adept_one_xl", ("joint1", "joint2", "joint3", "joint4"), "adept_one_xl", None, "tool0"
    )
    assert result.algorithm_settings == {"pop_size": 100, "eta_c": 15.0, "ops": ["sbx", "pm"]}
    assert result.metrics.oo is None
    assert result.best_trajectory is result.certificate.dense


def test_rebuilt_problem_recertifies(result: PlanningResult, saved: Path) -> None:
    loaded = PlanningResult.load(saved)
    assert (
        certify(loaded.problem(), loaded.best_x, loaded.certificate.rate_hz) == result.certificate
    )


# ----------------------------------------------------------------------------- file contents
def test_json_schema(result: PlanningResult, saved: Path) -> None:
    text = (saved / "result.json").read_text(encoding="utf-8")
    assert "NaN" not in text
    assert "Infinity" not in text
    data = load_json(saved)
    assert data["format"] == FORMAT == "adept_traj.result"
    assert data["version"] == VERSION == 2
    for key in (
        "start", "goal", "seed", "algorithm", "problem_settings", "scene", "robot", "versions",
        "front", "best", "best_trajectory", "limits", "certificate", "metrics", "timing",
        "lower_bound", "gap", "history", "warning",
    ):  # fmt: skip
        assert key in data, key
    assert set(data["versions"]) == {"adept_traj", "numpy", "pinocchio", "coal", "pymoo", "python"}
    assert data["algorithm"]["name"] == "NSGA-II"
    assert len(data["front"]) == 3
    for item in data["front"]:
        assert len(item["objectives"]) == 6
        assert item["objectives"][3] > 0
        assert len(item["x"]) == 65
        assert len(item["constraints"]) == 21
    assert [item["feasible"] for item in data["front"]] == [True, True, False]
    assert set(data["best"]) == {"index", "objectives", "f_c", "F_avg"}
    traj = data["best_trajectory"]
    assert set(traj) == {"t", "q", "qd", "qdd", "qddd", "tau", "min_distance"}
    assert len(traj["t"]) == len(traj["q"]) == len(traj["min_distance"]) == 2101
    assert np.diff(traj["t"]).max() <= 1e-3 + 1e-15  # ≥ 1 kHz
    assert set(data["limits"]) >= {"q_lower", "q_upper", "qd", "qdd", "qddd", "tau"}
    cert = data["certificate"]
    assert cert["feasible"] is True
    assert cert["rate_hz"] == 1000.0
    for kind in ("position", "velocity", "acceleration", "jerk", "torque"):
        assert len(cert[kind]["worst"]) == 4
    assert cert["margin"] == 0.01
    assert len(cert["closest_pair"]) == 2
    assert cert["violations"] == []
    assert set(data["metrics"]) == {"SSM", "RNI", "OO", "AE", "HV", "HV_reference_point"}
    assert data["metrics"]["OO"] is None
    assert set(data["timing"]) == {"total_s", "evaluation_s", "n_evaluations", "n_generations"}
    assert data["lower_bound"]["limiting_joint"] == 3
    assert data["gap"] == pytest.approx(2.1 / data["lower_bound"]["T_min"])
    assert data["history"][0] == {
        "generation": 1,
        "n_evaluations": 100,
        "n_feasible": 0,
        "hypervolume": None,
    }


def test_csv_files(result: PlanningResult, saved: Path) -> None:
    with (saved / "front.csv").open(encoding="utf-8", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0] == [
        "z1", "z2", "z3", "z4", "z5", "z6", "feasible", *(f"x{i}" for i in range(65))
    ]  # fmt: skip
    assert len(rows) == 1 + 3
    assert [r[6] for r in rows[1:]] == ["1", "1", "0"]
    np.testing.assert_array_equal(
        np.array([[float(v) for v in r[:6]] for r in rows[1:]]), result.front_objectives
    )
    with (saved / "best_trajectory.csv").open(encoding="utf-8", newline="") as fh:
        rows = list(csv.reader(fh))
    units = {"joint1": "rad", "joint2": "rad", "joint3": "m", "joint4": "rad"}
    header = ["t [s]"]
    for prefix, per in (("q", ""), ("qd", "/s"), ("qdd", "/s^2")):
        header += [f"{prefix}_{n} [{u}{per}]" for n, u in units.items()]
    assert rows[0] == header
    # a fixed step of 1 ms: t = 0, 0.001, ..., 2.099, then T = 2.1 exactly as the last row
    assert len(rows) == 1 + 2101
    table = np.array(rows[1:], dtype=float)
    assert [Decimal(row[0]) for row in rows[1:-1]] == [Decimal(k) / 1000 for k in range(2100)]
    assert table[-1, 0] == result.best_x[0] == 2.1
    # the same move as the certificate's samples (its grid T·k/2100 is within 1e-15 s of k ms)
    d = result.certificate.dense
    np.testing.assert_allclose(table[:, 1:5], d.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(table[:, 5:9], d.qd, rtol=0, atol=1e-10)
    np.testing.assert_allclose(table[:, 9:13], d.qdd, rtol=0, atol=1e-8)
    np.testing.assert_allclose(table[-1, 1:5], result.goal, rtol=0, atol=1e-15)  # on the goal


def test_infinite_values_become_null(problem: TrajectoryProblem, tmp_path: Path) -> None:
    """No obstacle (distance +inf) and unknown acceleration limits (inf): null in JSON."""
    robot = Robot.adept_one_xl()
    lim = robot.limits
    robot = robot.replace(limits=dataclasses.replace(lim, acceleration=np.full(4, np.inf)))
    empty = Scene(robot_base=problem.scene.robot_base, name="empty")
    p = TrajectoryProblem(robot, empty, problem.start, problem.goal)
    r = make_result(p, lift_then_lower(p)[None], history=None, metrics=Metrics())
    assert r.certificate.min_distance == math.inf
    folder = r.save(tmp_path / "inf")
    data = load_json(folder)
    assert data["limits"]["qdd"] == [None] * 4
    assert data["certificate"]["min_distance"] is None
    assert data["certificate"]["closest_pair"] is None
    assert data["best_trajectory"]["min_distance"][:3] == [None] * 3
    assert data["history"] is None
    assert "inf" not in (folder / "best_trajectory.csv").read_text(encoding="utf-8")  # no distance
    assert PlanningResult.load(folder) == r


def test_nothing_feasible_sets_a_warning(problem: TrajectoryProblem, tmp_path: Path) -> None:
    r = make_result(problem, problem.trajectory.straight_line(np.array([1.5, 1.8]))[..., :])
    assert not r.front.feasible.any()
    assert r.warning == NO_FEASIBLE_WARNING
    assert not r.certificate.feasible
    assert not r.feasible
    assert len(r.feasible_front) == 0
    folder = r.save(tmp_path / "infeasible")
    data = load_json(folder)
    assert data["warning"] == NO_FEASIBLE_WARNING
    assert any("cube1" in v for v in data["certificate"]["violations"])
    assert PlanningResult.load(folder) == r


def test_construction_checks(result: PlanningResult) -> None:
    with pytest.raises(InvalidInputError, match=r"certificate\.x"):
        dataclasses.replace(result, best=BestSolution(1))
    with pytest.raises(InvalidInputError, match=r"best\.index"):
        dataclasses.replace(result, best=BestSolution(5))
    bad = result.front.objectives.copy()
    bad[1, 2] = np.nan
    with pytest.raises(InvalidInputError):
        dataclasses.replace(result.front, objectives=bad)
    assert Metrics(hv=float("nan")).hv is None
    with pytest.raises(InvalidInputError):
        Timing(-1.0, 0.0, 1, 1)


# ----------------------------------------------------------------------------- bad folders
def expect_error(folder: Path, file: str, field: str | None = None) -> ResultFormatError:
    with pytest.raises(ResultFormatError) as info:
        PlanningResult.load(folder)
    err = info.value
    assert isinstance(err, AdeptTrajError)
    assert isinstance(err, ValueError)
    assert file in str(err)
    assert Path(err.file).name == file
    if field is not None:
        assert err.field == field
        assert f"'{field}'" in str(err)
    return err


def test_missing_folder_and_files(saved: Path, tmp_path: Path) -> None:
    expect_error(tmp_path / "nowhere", "result.json")
    (saved / "front.csv").unlink()
    assert "missing" in str(expect_error(saved, "front.csv"))


def test_missing_trajectory_csv(saved: Path) -> None:
    (saved / "best_trajectory.csv").unlink()
    expect_error(saved, "best_trajectory.csv")


def test_bad_json(saved: Path) -> None:
    (saved / "result.json").write_text('{"format": "adept_traj.result", ', encoding="utf-8")
    assert "not valid JSON" in str(expect_error(saved, "result.json"))


def test_json_number_beyond_float_range_is_refused(saved: Path) -> None:
    """``1e400`` used to load as +inf and turn a collision into "no obstacle"."""
    text = (saved / "result.json").read_text(encoding="utf-8")
    (saved / "result.json").write_text(text.replace('"total_s": 12.5', '"total_s": 1e400'))
    assert "the number 1e400 is not finite" in str(expect_error(saved, "result.json"))


def test_deeply_nested_json_is_refused_without_recursion_error(saved: Path) -> None:
    (saved / "result.json").write_text("[" * 100_000 + "]" * 100_000, encoding="utf-8")
    assert "nest" in str(expect_error(saved, "result.json"))


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda d: d["best"]["objectives"].__setitem__(0, 9.0), "best.objectives[0]"),
        (lambda d: d.__setitem__("gap", 1.0), "gap"),
        (lambda d: d["certificate"].__setitem__("n_samples", 7), "certificate.n_samples"),
        (lambda d: d["certificate"]["velocity"]["within"].__setitem__(0, False), "within[0]"),
        (lambda d: d["certificate"]["torque"]["worst"].__setitem__(1, 0.0), "torque.worst[1]"),
    ],
)
def test_derived_fields_must_agree_with_the_file(saved: Path, edit, field) -> None:
    """Fields the loader derives (not reads) were ignored: tampering went unseen."""
    doc = json.loads((saved / "result.json").read_text(encoding="utf-8"))
    edit(doc)
    (saved / "result.json").write_text(json.dumps(doc), encoding="utf-8")
    message = str(expect_error(saved, "result.json"))
    assert field in message
    assert "the rest of the file gives" in message


def test_json_with_nan(saved: Path) -> None:
    text = (saved / "result.json").read_text(encoding="utf-8")
    (saved / "result.json").write_text(text.replace('"total_s": 12.5', '"total_s": NaN'))
    assert "NaN" in str(expect_error(saved, "result.json"))


@pytest.mark.parametrize(
    ("edit", "field"),
    [
        (lambda d: d.update(version=3), "version"),
        (lambda d: d.update(version=1), "front[2]"),  # version 1 has no member certificates
        (lambda d: d.pop("n_certified"), "n_certified"),
        (lambda d: d["front"][0].pop("certificate"), "front[0].certificate"),
        (lambda d: d["front"][0]["certificate"].pop("guarantee"), "front[0].certificate.guarantee"),
        (
            lambda d: d["front"][0]["certificate"]["worst"].update(speed=1.0),
            "front[0].certificate.worst.speed",
        ),
        (lambda d: d["front"][0]["certificate"].update(feasible=False), "front"),
        (lambda d: d["front"][1].update(certificate=None), "front"),
        (lambda d: d.update(version=True), "version"),
        (lambda d: d.update(format="something.else"), "format"),
        (lambda d: d.pop("timing"), "timing"),
        (lambda d: d.pop("certificate"), "certificate"),
        (lambda d: d["front"][1].pop("x"), "front[1].x"),
        (lambda d: d["timing"].pop("n_generations"), "timing.n_generations"),
        (lambda d: d.update(start="abc"), "start"),
        (lambda d: d["start"].append(1.0), "start"),
        (lambda d: d["front"][0]["objectives"].__setitem__(2, "x"), "front[0].objectives[2]"),
        (lambda d: d["best_trajectory"]["q"].pop(), "best_trajectory.q"),
        (lambda d: d["certificate"]["velocity"].pop("dense"), "certificate.velocity.dense"),
        (lambda d: d["certificate"].update(feasible=False), "certificate.feasible"),
        (lambda d: d["problem_settings"].update(colour="red"), "problem_settings.colour"),
        (lambda d: d["problem_settings"].update(margin=-1.0), "problem_settings"),
        (lambda d: d["problem_settings"].update(margin="abc"), "problem_settings"),  # TypeError
        (lambda d: d["scene"].update(obstacle="nope"), "scene"),
        (lambda d: d["limits"]["q_upper"].__setitem__(0, "high"), "limits.q_upper[0]"),
        (lambda d: d["best"].update(index=9), "best.index"),
        (lambda d: d["certificate"]["x"].__setitem__(0, 3.0), "certificate.x"),
        (lambda d: d.update(seed=1.5), "seed"),
        (lambda d: d.update(front=[]), "front"),
        (lambda d: d["front"][2].update(feasible="no"), "front[2].feasible"),
        (lambda d: d.update(history={}), "history"),
        (lambda d: d["start"].__setitem__(1, True), "start[1]"),  # a bool is not a number
        (lambda d: d["start"].__setitem__(2, None), "start[2]"),  # null: only in limits
        (
            lambda d: d["best_trajectory"]["tau"][5].__setitem__(0, "1.0"),
            "best_trajectory.tau[5][0]",
        ),
        (lambda d: d["best_trajectory"]["qd"][7].append(0.0), "best_trajectory.qd[7]"),
    ],
)
def test_malformed_fields(saved: Path, edit: Any, field: str) -> None:
    data = load_json(saved)
    edit(data)
    dump_json(saved, data)
    expect_error(saved, "result.json", field)


def test_null_limit_is_infinite(saved: Path) -> None:
    """null in a limit means an infinite (unknown) limit: legal, the file still loads."""
    data = load_json(saved)
    data["limits"]["qd"][0] = None
    name = data["limits"]["joint_names"][0]
    # the statement of what was not checked is derived from the limits: said with them
    said = f"velocity (VC): no limit for {name}: not constrained, not certified"
    data["unchecked"] = [said, *data.get("unchecked", [])]
    dump_json(saved, data)
    assert PlanningResult.load(saved).limits.velocity[0] == math.inf
    del data["unchecked"][0]
    dump_json(saved, data)
    with pytest.raises(ResultFormatError, match="field 'unchecked'"):
        PlanningResult.load(saved)


def test_csv_tampered(saved: Path) -> None:
    lines = (saved / "front.csv").read_text(encoding="utf-8").splitlines()
    cells = lines[2].split(",")
    cells[1] = "123.0"
    lines[2] = ",".join(cells)
    (saved / "front.csv").write_text("\n".join(lines) + "\n", encoding="utf-8")
    assert "row 2, column z2" in str(expect_error(saved, "front.csv"))


def test_csv_cell_not_a_number(saved: Path) -> None:
    path = saved / "best_trajectory.csv"
    lines = path.read_text(encoding="utf-8").splitlines()
    cells = lines[4].split(",")
    cells[3] = "abc"
    lines[4] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    assert "'abc' is not the number" in str(
        expect_error(saved, "best_trajectory.csv", "row 4, column q_joint3 [m]")
    )


def test_csv_bad_header_and_rows(saved: Path) -> None:
    path = saved / "best_trajectory.csv"
    lines = path.read_text(encoding="utf-8").splitlines()
    path.write_text("\n".join(lines[:-1]) + "\n", encoding="utf-8")  # a row short
    assert "rows" in str(expect_error(saved, "best_trajectory.csv"))
    path.write_text("\n".join(["time", *lines[1:]]) + "\n", encoding="utf-8")
    expect_error(saved, "best_trajectory.csv", "header")
