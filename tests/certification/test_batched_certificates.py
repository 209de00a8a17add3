"""The front's certificates formed in batches (issue #15): several members' dense samples
in one inverse dynamics and one distance call give the summaries of each member certified
alone, and the summaries the code gave before the change (stored in
tests/data/member_certificates/, made by the previous version: paper front members,
colliding ramps whose continuous bound refines, and a UR5 front with self-collision)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

import adept_traj as at
from adept_traj.certification import (
    MemberCertificate,
    batch_samples,
    certify,
    certify_members,
    certifying_problem,
    dense_samples,
)
from adept_traj.robot import installed_data_dirs

DATA = Path(__file__).parents[1] / "data" / "member_certificates"
EXAMPLES = Path(__file__).parents[2] / "examples" / "data"
_FOUND = [d / "example-robot-data/robots" for d in installed_data_dirs()]
ROBOTS = next((d for d in _FOUND if d.is_dir()), None)


def _stored(name: str) -> tuple[np.ndarray, list[dict]]:
    doc = json.loads((DATA / f"{name}.json").read_text())
    return np.array(doc["x"]), doc["summaries"]


def _as_stored(summary: MemberCertificate) -> dict:
    """The summary as the stored JSON holds it (tuples as lists; floats exact)."""
    return json.loads(json.dumps(dataclasses.asdict(summary)))


#: Relative tolerance of the floats compared with the stored summaries: the last bits of a
#: sum depend on the NumPy and BLAS builds installed (numpy 2.4.6 moved some by 1e-15).
REL = 1e-12


def _assert_same(now: dict, stored: dict) -> None:
    """Every field equal; floats to :data:`REL`. A worst sample's time may differ only
    where that worst value itself moved in its last bits (two samples tied to rounding:
    which one is the argmax is then a matter of rounding)."""
    assert now.keys() == stored.keys()
    for key, value in stored.items():
        if key == "t_worst":
            moved = [a != b for a, b in zip(now["worst"], stored["worst"])]
            kept = [a for a, m in zip(now[key], moved) if not m]
            assert kept == pytest.approx([b for b, m in zip(value, moved) if not m], rel=REL)
        elif isinstance(value, float) or (
            isinstance(value, list) and value and all(isinstance(v, float) for v in value)
        ):
            assert now[key] == pytest.approx(value, rel=REL, abs=1e-15), key
        elif isinstance(value, dict):
            _assert_same(now[key], value)
        else:
            assert now[key] == value, key


def _check(problem: at.TrajectoryProblem, name: str) -> None:
    x, before = _stored(name)
    sizes = [dense_samples(T, 1000.0) for T in x[:, 0]]
    most = batch_samples(certifying_problem(problem)[0])
    assert sum(sizes[:2]) <= most < sum(sizes)  # batches of several, and several
    batched = certify_members(problem, x, rate_hz=1000.0)
    assert len(batched) == len(before)
    for summary, stored in zip(batched, before):  # every field
        _assert_same(_as_stored(summary), stored)
    fast, influence = certifying_problem(problem)
    for k in (0, len(x) - 1):  # each alone, the library called directly
        alone = MemberCertificate.of(certify(fast, x[k], exact=False), influence)
        assert alone == batched[k]


def test_paper_summaries_are_unchanged(problem: at.TrajectoryProblem) -> None:
    # stored with self-collision off (the default then); on by default now (issue 26), the
    # summaries are the same but for the self-distance they add
    off = at.TrajectoryProblem(problem.robot, problem.scene, problem.start, problem.goal,
                               self_collision=False)  # fmt: skip
    _check(off, "paper")
    x, before = _stored("paper")
    on = [_as_stored(s) for s in certify_members(problem, x, rate_hz=1000.0)]
    assert all(s.pop("self_distance")["min_distance"] > 0.01 for s in on)  # above the margin
    for summary, stored in zip(on, before, strict=True):
        _assert_same(summary, {k: v for k, v in stored.items() if k != "self_distance"})


@pytest.mark.skipif(ROBOTS is None, reason="example-robot-data is not installed")
def test_ur5_self_collision_summaries_are_unchanged() -> None:
    robot = at.Robot.from_urdf(
        ROBOTS / "ur_description/urdf/ur5_robot.urdf",
        EXAMPLES / "ur5.toml",
        srdf=ROBOTS / "ur_description/srdf/ur5.srdf",
    )
    scene = at.Scene.from_file(EXAMPLES / "ur5_box.toml")
    problem = at.TrajectoryProblem(robot, scene, scene.start, scene.goal)
    assert problem.self_check is not None
    _check(problem, "ur5_box")
