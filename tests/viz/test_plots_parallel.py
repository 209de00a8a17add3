"""save_all draws its figures on several processes: the same files, in the same order, as
one process; an error of a figure in a worker process is raised in the caller with the
worker's traceback, a killed worker's figures are drawn again by the caller.
start_save_all draws them in a forked process while the caller goes on: the same files;
its error is raised by wait(); cancel stops it. The drawing functions are replaced by
cheap fakes (forked processes inherit them)."""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path

import pytest

import adept_traj as at
from adept_traj.errors import InvalidInputError, WorkerError
from adept_traj.process_pool import children
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


def test_an_error_of_a_figure_in_a_worker_is_raised_here(
    result: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _patch(monkeypatch, joint_motion=_fake("joint_motion", fails_in_child=True))
    with pytest.raises(ValueError, match="joint_motion failed in process") as caught:
        plots.save_all(result, tmp_path, processes=2)
    assert f"in process {os.getpid()}" not in str(caught.value)  # the worker's error
    (note,) = caught.value.__notes__
    assert "forked process" in note
    assert "in draw" in note  # the worker's traceback
    assert children() == []  # every worker reaped


def _killed_outside(parent: int, name: str):
    """A fake figure ``name`` whose drawing kills its process unless it is ``parent``."""

    def draw(_results, path, **_kwargs):
        if os.getpid() != parent:
            os.kill(os.getpid(), signal.SIGKILL)
        return _fake(name)(_results, path)

    return draw


def test_a_killed_worker_has_its_figures_drawn_here(
    result: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    parent = os.getpid()
    _patch(monkeypatch, joint_motion=_killed_outside(parent, "joint_motion"))
    paths = plots.save_all(result, tmp_path, processes=2)
    assert _writers(paths)["joint_motion_nsga2.png"] == parent
    assert children() == []


def test_an_error_of_a_figure_is_raised_here(
    result: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _patch(monkeypatch, joint_motion=_fake("joint_motion", fails=True))
    with pytest.raises(ValueError, match="joint_motion failed in process"):
        plots.save_all(result, tmp_path, processes=2)


def test_processes_must_be_a_positive_integer(result: PlanningResult, tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match=r"processes must be an integer in \[1, ∞\]"):
        plots.save_all(result, tmp_path, processes=0)


# ---------------------------------------------------------------- start_save_all
def _waits_for(go: Path, name: str, pid_file: Path | None = None):
    """A drawing that, in a forked process, waits (at most 20 s) for the file ``go``."""

    def draw(_results, path, **_kwargs):
        if pid_file is not None:
            pid_file.write_text(str(os.getpid()))
        for _ in range(2000):
            if go.exists():
                Path(path).write_text(f"{name} {os.getpid()}")
                return Path(path)
            time.sleep(0.01)
        raise TimeoutError(f"{go} never appeared")

    return draw


def test_start_save_all_returns_at_once_and_writes_the_files_of_save_all(
    result: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    go = tmp_path / "go"
    _patch(monkeypatch, pareto_matrix=_waits_for(go, "pareto_matrix"))
    go.touch()
    one = plots.save_all(result, tmp_path / "one", processes=1)
    go.unlink()
    with plots.start_save_all(result, tmp_path / "two") as drawing:
        # the Pareto matrix cannot be drawn before this process goes on and makes `go`
        assert not (tmp_path / "two" / "pareto_matrix.png").exists()
        go.touch()
        two = drawing.wait()
    assert [p.name for p in two] == [p.name for p in one] == [p.name for p in drawing.paths]
    assert os.getpid() not in _writers(two).values()  # all drawn by forked processes


def test_an_error_of_the_forked_process_is_raised_by_wait(
    result: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _patch(monkeypatch, joint_motion=_fake("joint_motion", fails_in_child=True))
    drawing = plots.start_save_all(result, tmp_path, processes=1)
    with pytest.raises(ValueError, match="joint_motion failed in process") as caught:
        drawing.wait()
    assert f"in process {os.getpid()}" not in str(caught.value)  # not drawn again here
    (note,) = caught.value.__notes__
    assert "forked process" in note
    assert "Traceback" in note
    assert "in draw" in note  # the forked process' traceback


class _Unpicklable(Exception):
    def __init__(self, a: int, b: int) -> None:  # pickles, but does not unpickle
        super().__init__(f"unpicklable {a} {b}")


def test_an_error_that_does_not_unpickle_is_raised_as_its_text(
    result: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def draw(_results, path, **_kwargs):
        raise _Unpicklable(1, 2)

    _patch(monkeypatch, best_tradeoffs=draw)
    with pytest.raises(
        WorkerError, match=r"(?s)in a forked process.*_Unpicklable: unpicklable 1 2"
    ):
        plots.start_save_all(result, tmp_path, processes=1).wait()


def test_a_killed_forked_process_has_its_figures_drawn_here(
    result: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    parent = os.getpid()
    _patch(monkeypatch, tool_path_3d=_killed_outside(parent, "tool_path_3d"))
    paths = plots.start_save_all(result, tmp_path, processes=1).wait()
    assert _writers(paths)["tool_path_nsga2.png"] == parent


def test_cancel_stops_the_forked_process(
    result: PlanningResult, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pid_file = tmp_path / "pid"
    _patch(monkeypatch, pareto_matrix=_waits_for(tmp_path / "never", "p", pid_file))
    with plots.start_save_all(result, tmp_path / "figs", processes=1):
        for _ in range(2000):  # until the drawing has started
            if pid_file.exists() and pid_file.read_text():
                break
            time.sleep(0.01)
    with pytest.raises(ProcessLookupError):  # stopped and waited for by the with block
        os.kill(int(pid_file.read_text()), 0)
    assert not (tmp_path / "figs" / "pareto_matrix.png").exists()


def test_start_save_all_checks_its_arguments_first(result: PlanningResult, tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match=r"processes must be an integer in \[1, ∞\]"):
        plots.start_save_all(result, tmp_path, processes=0)


def test_drawing_keeps_a_caller_s_frozen_heap_frozen_and_leaves_none_frozen_itself() -> None:
    import gc

    seen: list[int] = []
    jobs = [(1.0, lambda: seen.append(gc.get_freeze_count()))]
    before = gc.get_freeze_count()
    all_figures.draw_jobs(jobs, 1)
    assert gc.get_freeze_count() == before  # its own freeze undone
    assert seen[0] > before  # the heap was frozen while drawing
    keep = [object() for _ in range(10)]
    gc.freeze()
    try:
        frozen = gc.get_freeze_count()
        all_figures.draw_jobs(jobs, 1)
        assert gc.get_freeze_count() == frozen  # the caller's freeze kept
        assert seen[1] == frozen
    finally:
        gc.unfreeze()
    assert keep
