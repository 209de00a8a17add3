"""The finish of ``adept-traj plan`` (after the optimiser returns): the figures are drawn by
a forked process while result.json is written; result.json is the same bytes as a plain
save; an error of the figure process is reported (not swallowed), the exit status is not
0 and the run is not marked complete (that the error keeps its type and carries the forked
traceback is tested on start_save_all, tests/viz/test_plots_parallel.py). The optimiser is
replaced by a stored result and the drawings by cheap fakes (forked processes inherit
them)."""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

import adept_traj.cli.report as report
import adept_traj.optimise as optimise  # cli.plan runs its plan (imported on use)
from adept_traj.cli.app import main
from adept_traj.results import PlanningResult
from adept_traj.viz.plots import all_figures

DATA = Path(__file__).parents[1] / "data"
_DRAWINGS = ("pareto_matrix", "best_tradeoffs", "hypervolume_history", "joint_motion")


@pytest.fixture(scope="module")
def stored() -> PlanningResult:
    return PlanningResult.load(DATA / "result_v1")


@pytest.fixture(scope="module")
def plain(stored: PlanningResult, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The folder of a plain ``stored.save``."""
    folder = tmp_path_factory.mktemp("plain") / "run"
    stored.save(folder)
    return folder


def _fake(name: str, error: BaseException | None = None):
    def draw(_results, path, **_kwargs):
        if error is not None:
            raise error
        Path(path).write_text(f"{name} {os.getpid()}")
        return Path(path)

    return draw


def _plan(monkeypatch: pytest.MonkeyPatch, result: PlanningResult, out: Path, **fakes) -> int:
    """``adept-traj plan --out out`` whose optimiser returns ``result`` at once."""
    monkeypatch.setattr(optimise, "plan", lambda *_args, **_kwargs: result)
    for name in (*_DRAWINGS, "tool_path_3d"):
        monkeypatch.setattr(all_figures, name, fakes.get(name, _fake(name)))
    monkeypatch.setattr(all_figures, "load_matplotlib", lambda: None)  # the fakes need none
    return main(["plan", "--workers", "1", "--no-html", "--quiet", "--out", str(out)])


def test_the_figures_are_drawn_by_another_process_and_result_json_is_unchanged(
    stored: PlanningResult, plain: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assert not stored.feasible  # exit 1: the run's best trade-off is not certified
    assert _plan(monkeypatch, stored, tmp_path / "run") == 1
    figures = sorted((tmp_path / "run" / "figures").iterdir())
    assert [p.name for p in figures] == [
        "best_tradeoffs.png",
        "hypervolume_history.png",
        "joint_motion_nsga2.png",
        "pareto_matrix.png",
        "tool_path_nsga2.png",
    ]
    writers = {int(p.read_text().split()[1]) for p in figures}
    assert os.getpid() not in writers
    for name in ("result.json", "front.csv", "best_trajectory.csv"):
        assert (tmp_path / "run" / name).read_bytes() == (plain / name).read_bytes()
    assert not (tmp_path / "run" / "run.json").exists()  # marked complete


def test_an_error_of_the_figure_process_is_reported_and_the_run_not_completed(
    stored: PlanningResult,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    full = OSError(28, "No space left on device", "joint_motion_nsga2.png")
    code = _plan(monkeypatch, stored, tmp_path / "run", joint_motion=_fake("j", full))
    assert code == 2
    err = capsys.readouterr().err
    assert re.search(r"adept-traj: error: .*No space left on device.*joint_motion_nsga2", err)
    assert (tmp_path / "run" / "result.json").is_file()  # written meanwhile
    assert (tmp_path / "run" / "run.json").is_file()  # not marked complete


def test_the_result_is_saved_when_the_figures_cannot_start(
    stored: PlanningResult, plain: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def no_fork(*_args, **_kwargs):
        raise OSError(12, "Cannot allocate memory (fork)")

    monkeypatch.setattr(all_figures, "BackgroundFigures", no_fork)
    # no finish helper either (no fork): else a helper whose imports are done (all of
    # them already imported by earlier tests) writes the figures, and nothing fails
    monkeypatch.setattr(report, "start_finisher", no_fork)
    assert _plan(monkeypatch, stored, tmp_path / "run") == 2
    saved = (tmp_path / "run" / "result.json").read_bytes()
    assert saved == (plain / "result.json").read_bytes()
    assert (tmp_path / "run" / "run.json").is_file()  # not marked complete
