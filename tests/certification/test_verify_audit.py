"""``adept-traj verify`` checks everything in the folder (issue 13): each stored value that
can be recomputed from the decision vectors, the robot files and the scene is, and a
tampered folder fails with the field named (exit status 3), while an untampered one passes.

The tampered folders stay loadable: either the record is altered and saved by the library
(result.json and the CSV files then agree), or result.json alone is edited in a field the
CSV files do not mirror. The expected values come from the untampered files, not from the
audit.
"""

from __future__ import annotations

import dataclasses
import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from adept_traj.certification import AUDIT_RTOL
from adept_traj.certification.audit import audit
from adept_traj.cli import main, status
from adept_traj.optimise import plan
from adept_traj.problem import TrajectoryProblem
from adept_traj.results import Front, PlanningResult
from adept_traj.robot import Robot
from adept_traj.scene import Scene

ROOT = Path(__file__).resolve().parents[2]
OLD = ROOT / "tests" / "data" / "result_v1"
FAR_BOX = {"name": "box", "shape": "box", "min": [2.0, 2.0, 2.0], "max": [2.1, 2.1, 2.1]}
MISMATCH = re.compile(r"^  mismatch: (\S+): stored (.+), recomputed (.+?)(?: \(.*\))?$")


@pytest.fixture
def old(tmp_path: Path) -> Path:
    """A copy of the result saved by the flat layout (infeasible best: it hits cube 1)."""
    return Path(shutil.copytree(OLD, tmp_path / "old"))


def _edit_json(folder: Path, edit) -> None:
    """Apply ``edit`` to the parsed result.json of ``folder`` and write it back."""
    path = folder / "result.json"
    doc = json.loads(path.read_text(encoding="utf-8"))
    edit(doc)
    path.write_text(json.dumps(doc), encoding="utf-8")


def _verify(folder: Path, capsys: pytest.CaptureFixture[str], *options: str):
    """(exit status, {field: (stored, recomputed)} of the mismatch lines, output)."""
    code = main(["verify", str(folder), *options])
    out = capsys.readouterr().out
    found = {}
    for line in out.splitlines():
        m = MISMATCH.match(line)
        if m:
            found[m.group(1)] = (m.group(2), m.group(3))
    return code, found, out


def _save(result: PlanningResult, folder: Path) -> Path:
    result.save(folder)
    PlanningResult.load(folder)  # the tampered folder is loadable
    return folder


# ------------------------------------------------------------------ untampered
def test_untampered_infeasible_result_exits_1_without_mismatch(old, capsys) -> None:
    code, found, out = _verify(old, capsys)
    assert code == status.NOT_CERTIFIED == 1
    assert found == {}
    assert "mismatch" not in out.replace("no mismatch", "")
    assert re.search(
        r"audit: \d{4,} values in \d+ fields recomputed and compared .*: no mismatch", out
    )
    assert "NOT FEASIBLE" in out


@pytest.mark.slow  # ≥ 5 s (the default tier measured 192 s after the merges)
def test_untampered_feasible_run_passes_the_audit(tmp_path: Path) -> None:
    result = _planar_run(tmp_path)
    assert result.feasible
    assert result.front.feasible.all()
    found = audit(result)
    assert found.mismatches == ()
    assert found.n_values > 1000
    assert found.certificate == result.certificate  # same rate and tolerance


# ------------------------------------------------------------------ tampered
def test_zeroed_torques_are_named(old, tmp_path, capsys) -> None:
    r = PlanningResult.load(old)
    dense = dataclasses.replace(r.certificate.dense, tau=np.zeros_like(r.certificate.dense.tau))
    cert = dataclasses.replace(r.certificate, dense=dense)
    folder = _save(dataclasses.replace(r, certificate=cert), tmp_path / "t")
    code, found, _ = _verify(folder, capsys)
    assert code == status.MISMATCH == 3
    [field] = found
    assert re.fullmatch(r"best_trajectory\.tau\[\d+\]\[\d\]", field)
    row, col = map(int, re.findall(r"\d+", field))
    assert float(found[field][0]) == 0.0
    # re-derived by verify: the stored value to the last bits of the installed NumPy's sums
    assert r.certificate.dense.tau[row, col] != 0.0
    assert float(found[field][1]) == pytest.approx(r.certificate.dense.tau[row, col], rel=1e-12)


def test_q_shifted_by_5_centiradians_is_named(old, tmp_path, capsys) -> None:
    r = PlanningResult.load(old)
    dense = r.certificate.dense
    shifted = dataclasses.replace(dense, q=dense.q + np.array([0.05, 0.0, 0.0, 0.0]))
    cert = dataclasses.replace(r.certificate, dense=shifted)
    folder = _save(dataclasses.replace(r, certificate=cert), tmp_path / "t")
    code, found, out = _verify(folder, capsys)
    assert code == status.MISMATCH
    [field] = found
    assert re.fullmatch(r"best_trajectory\.q\[\d+\]\[0\]", field)
    stored, recomputed = map(float, found[field])
    assert stored - recomputed == pytest.approx(0.05, abs=1e-12)
    assert f"{dense.n_samples} of {dense.q.size} values differ" in out


def test_halved_objectives_are_named_per_member(old, tmp_path, capsys) -> None:
    r = PlanningResult.load(old)
    F = r.front.objectives.copy()
    F[3, 1] /= 2.0  # z2 (energy) of member 3
    front = Front(r.front.x, F, r.front.constraints, r.front.feasible)
    folder = _save(dataclasses.replace(r, front=front), tmp_path / "t")
    code, found, _ = _verify(folder, capsys)
    assert code == status.MISMATCH
    assert float(found["front[3].objectives[1]"][0]) == r.front.objectives[3, 1] / 2
    assert float(found["front[3].objectives[1]"][1]) == pytest.approx(
        r.front.objectives[3, 1], rel=AUDIT_RTOL
    )
    # the halved value moves the bounds of z2: the best's f_c, F_avg and the spread differ
    assert set(found) == {"front[3].objectives[1]", "best.f_c", "best.F_avg", "metrics.SSM"}


def test_deleted_obstacle_is_named(old, capsys) -> None:
    raw = json.loads((old / "result.json").read_text(encoding="utf-8"))
    assert raw["scene"]["obstacle"][0]["name"] == "cube1"
    _edit_json(old, lambda doc: doc["scene"]["obstacle"].pop(0))
    code, found, _ = _verify(old, capsys)
    assert code == status.MISMATCH
    n = len(raw["scene"]["obstacle"])
    assert found["scene.obstacle"] == (str(n - 1), str(n))
    # without cube 1 the best no longer collides: the stored certificate disagrees too
    assert "certificate.closest_pair" in found


def test_changed_best_index_is_named(old, capsys) -> None:
    raw = json.loads((old / "result.json").read_text(encoding="utf-8"))
    assert raw["best"]["index"] == 5

    def edit(doc):  # keep what the loader derives consistent: certificate.x, objectives, gap
        doc["best"]["index"] = 7
        doc["certificate"]["x"] = doc["front"][7]["x"]
        doc["best"]["objectives"] = doc["front"][7]["objectives"]
        doc["gap"] = doc["front"][7]["objectives"][0] / doc["lower_bound"]["T_min"]

    _edit_json(old, edit)
    code, found, _ = _verify(old, capsys)
    assert code == status.MISMATCH
    assert found["best.index"] == ("7", "5")
    assert any(f.startswith("best_trajectory.") for f in found)  # the dense move is x[5]'s


def test_changed_metric_is_named(old, capsys) -> None:
    raw = json.loads((old / "result.json").read_text(encoding="utf-8"))
    ssm = raw["metrics"]["SSM"]
    _edit_json(old, lambda doc: doc["metrics"].update(SSM=2 * ssm))
    code, found, _ = _verify(old, capsys)
    assert code == status.MISMATCH
    assert found == {"metrics.SSM": (repr(2 * ssm), repr(ssm))}


@pytest.mark.slow  # ≥ 5 s (the default tier measured 192 s after the merges)
def test_feasible_run_with_changed_hypervolume_and_robot_file(tmp_path: Path) -> None:
    result = _planar_plan(tmp_path)  # its own parameter file, changed below
    metrics = dataclasses.replace(result.metrics, hv=result.metrics.hv * 0.9)
    found = audit(dataclasses.replace(result, metrics=metrics))
    assert [m.field for m in found.mismatches] == ["metrics.HV"]
    assert found.mismatches[0].recomputed == result.metrics.hv
    # the robot's parameter file changed after the run: its limits no longer match.
    params = tmp_path / "planar.toml"
    params.write_text(params.read_text() + '[[joint]]\nname = "shoulder"\nvelocity = 0.5\n')
    fields = {m.field for m in audit(result).mismatches}
    assert "limits.qd[0]" in fields


def test_feasible_member_marked_infeasible_is_named(tmp_path: Path) -> None:
    result = _planar_run(tmp_path)
    f = result.front
    ok = np.flatnonzero(np.all(f.constraints <= 0.0, axis=1) & f.feasible)
    k = int(ok[ok != ok[np.argmin(f.x[ok, 0])]][-1])  # not the fastest: T_best stays
    flags = result.front.feasible.copy()
    flags[k] = False
    found = audit(dataclasses.replace(result, front=Front(f.x, f.objectives, f.constraints, flags)))
    by_field = {m.field: m for m in found.mismatches}
    # the member itself belongs in the front (feasible at the samples): only its flag differs
    assert set(by_field) == {f"front[{k}].feasible"}
    flag = by_field[f"front[{k}].feasible"]
    assert (flag.stored, flag.recomputed) == (False, True)


def test_certified_front_flags_are_recomputed_from_certificates(tmp_path: Path) -> None:
    """With every member certified (n_certified set), a member whose certificate passes but
    is stored as failed is named; the stored verdicts of an untampered run pass."""
    result = _planar_run(tmp_path)
    assert result.front.n_certified == int(result.front.feasible.sum())
    assert audit(result).mismatches == ()
    k = int(np.flatnonzero(result.front.feasible)[-1])
    flags = result.front.feasible.copy()
    flags[k] = False
    f = result.front
    tampered = Front(f.x, f.objectives, f.constraints, flags, n_certified=int(flags.sum()))
    found = audit(dataclasses.replace(result, front=tampered))
    assert {m.field for m in found.mismatches} >= {f"front[{k}].feasible"}


def test_member_certificates_are_recomputed(tmp_path: Path) -> None:
    """Every stored member certificate (result.json version 2) is compared field by field
    with a fresh one: an untampered run passes, a changed clearance or worst ratio is named."""
    result = _planar_run(tmp_path)
    f = result.front
    assert f.certificates is not None
    k = int(np.flatnonzero(f.feasible)[-1])
    stored = f.certificates[k]
    changed = dataclasses.replace(
        stored,
        min_distance=stored.min_distance + 0.01,
        worst=(stored.worst[0], stored.worst[1] / 2, *stored.worst[2:]),
    )
    certificates = (*f.certificates[:k], changed, *f.certificates[k + 1 :])
    tampered = dataclasses.replace(f, certificates=certificates)
    found = {m.field for m in audit(dataclasses.replace(result, front=tampered)).mismatches}
    path = f"front[{k}].certificate"
    assert found == {f"{path}.min_distance", f"{path}.worst[1]"}


def test_mismatch_line_format(old, tmp_path, capsys) -> None:
    r = PlanningResult.load(old)
    F = r.front.objectives.copy()
    F[0, 0] = 2.5
    folder = _save(
        dataclasses.replace(r, front=Front(r.front.x, F, r.front.constraints, r.front.feasible)),
        tmp_path / "t",
    )
    code, _, out = _verify(folder, capsys)
    assert code == status.MISMATCH
    z1 = float(r.front.objectives[0, 0])
    expected = f"  mismatch: front[0].objectives[0]: stored 2.5, recomputed {z1!r}"
    assert expected in out.splitlines()
    assert re.search(r"audit: .*: \d+ mismatch(es)?: the folder does not hold", out)


# ------------------------------------------------------------------ helpers
_PLANAR: list[PlanningResult] = []  # made once: a result is frozen, the tests replace parts


def _planar_run(tmp_path: Path) -> PlanningResult:
    """A tiny feasible run of the planar 2-link arm (its parameter file in ``tmp_path``),
    made once per session (the same arguments give the same result)."""
    if not _PLANAR:
        _PLANAR.append(_planar_plan(tmp_path))
    return _PLANAR[0]


def _planar_plan(tmp_path: Path) -> PlanningResult:
    params = tmp_path / "planar.toml"
    params.write_text('tool_frame = "hand"\ntask_rows = ["vx", "vz"]\n')
    robot = Robot.from_urdf(ROOT / "tests" / "data" / "planar_2link.urdf", params)
    scene = Scene.from_dict({"name": "far", "obstacle": [FAR_BOX]})
    with TrajectoryProblem(robot, scene, [0.0, 0.0], [1.0, 1.0]) as problem:
        return plan(problem, "nsga2", seed=1, pop_size=8, n_gen=2)
