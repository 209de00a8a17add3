"""save_all draws its figures on several processes: the same files, in the same order, as
one process; a figure whose process fails is drawn again by the caller (its error raised
there). The drawing functions are replaced by cheap fakes (forked processes inherit them)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import adept_traj as at
from adept_traj.errors import InvalidInputError
from adept_traj.results import PlanningResult
from adept_traj.viz import plots
from adept_traj.viz.plots import all_figures

_DRAWINGS = ("pareto_matrix", "best_tradeoffs", "hypervolume_history", "joint_motion")


@pytest.fixture(scope="module")
def result() -> PlanningResult:
    scene = at.Scene.paper()
    with at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal) as p:
        return at.plan(p, "nsga2", seed=1, pop_size=8, n_gen=2, rate_hz=250.0)


def _fake(name: str, fails_in_child: bool = False, fails: bool = False):
    parent = os.getpid()

    def draw(_results, path, **_kwargs):
        if fails or (fails_in_child and os.getpid() != parent):
            raise ValueError(f"{name} failed in process {os.getpid()}")
        Path(path).write_text(f"{name} {os.getpid()}")
        return Path(path)

    return draw


def _patch(monkeypatch: pytest.MonkeyPatch, **special) -> None:
    for name in (*_DRAWINGS, "tool_path_3d"):
        monkeypatch.setattr(all_figures, name, special.get(name, _fake(name)))


def _writers(paths: list[Path]) -> dict[str, int]:
    return {p.name: int(p.read_text().split()[1]) for p in paths}


def test_two_processes_write_the_files_of_one(
    result: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _patch(monkeypatch)
    one = plots.save_all(result, tmp_path / "one", processes=1)
    two = plots.save_all(result, tmp_path / "two", processes=2)
    assert [p.name for p in two] == [p.name for p in one]
    assert [p.parent for p in two] == [tmp_path / "two"] * len(two)
    assert set(_writers(one).values()) == {os.getpid()}
    writers = _writers(two)
    assert len(set(writers.values())) == 2  # this process and one forked process
    # the heaviest two (tool path, joint motion) are drawn by different processes
    assert writers["tool_path_nsga2.png"] != writers["joint_motion_nsga2.png"]


def test_a_figure_whose_process_fails_is_drawn_again_here(
    result: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _patch(monkeypatch, joint_motion=_fake("joint_motion", fails_in_child=True))
    paths = plots.save_all(result, tmp_path, processes=2)
    assert _writers(paths)["joint_motion_nsga2.png"] == os.getpid()


def test_an_error_of_a_figure_is_raised_here(
    result: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _patch(monkeypatch, joint_motion=_fake("joint_motion", fails=True))
    with pytest.raises(ValueError, match=f"joint_motion failed in process {os.getpid()}"):
        plots.save_all(result, tmp_path, processes=2)


def test_processes_must_be_a_positive_integer(result: PlanningResult, tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match=r"processes must be an integer in \[1, ∞\]"):
        plots.save_all(result, tmp_path, processes=0)
