"""The loop writes its checkpoint at most every checkpoint_interval seconds, after the last
generation and on Ctrl-C; a run killed outright resumes from an older generation to the
same result."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from adept_traj import TrajectoryProblem
from adept_traj.errors import ConfigurationError
from adept_traj.optimise import PlanningInterrupted, load_checkpoint, make_algorithm, optimise
from adept_traj.optimise.search import loop as loop_module

_GENS = 6


def _run(problem: TrajectoryProblem, folder: Path | None = None, **kwargs):
    return optimise(
        problem, make_algorithm("nsga2", 10, _GENS)[0], _GENS, seed=2, checkpoint=folder,
        fingerprint={"seed": 2}, **kwargs,
    )  # fmt: skip


@pytest.fixture(scope="module")
def full(problem: TrajectoryProblem):
    return _run(problem)


def _writes(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """The generation of every checkpoint written from now on."""
    written: list[int] = []
    original = loop_module.write_checkpoint

    def recording(folder, arrays):
        written.append(int(arrays["n_iter"]) - 1)
        original(folder, arrays)

    monkeypatch.setattr(loop_module, "write_checkpoint", recording)
    return written


def test_every_generation_with_interval_0_only_the_last_with_a_long_one(
    problem: TrajectoryProblem, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    written = _writes(monkeypatch)
    _run(problem, tmp_path / "a", checkpoint_interval=0.0)
    assert written == list(range(1, _GENS + 1))
    written.clear()
    _run(problem, tmp_path / "b", checkpoint_interval=1e9)
    assert written == [_GENS]
    with pytest.raises(ConfigurationError, match="checkpoint_interval"):
        _run(problem, tmp_path / "c", checkpoint_interval=-1.0)


def test_ctrl_c_writes_the_last_finished_generation(
    problem: TrajectoryProblem, full, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    written = _writes(monkeypatch)

    def interrupt(info) -> None:
        if info.generation == 4:
            raise KeyboardInterrupt

    with pytest.raises(PlanningInterrupted, match="after generation 4"):
        _run(problem, tmp_path, checkpoint_interval=1e9, progress=interrupt)
    assert written == [4]  # nothing by time; the generation Ctrl-C came after
    assert load_checkpoint(tmp_path)[0]["n_iter"] == 5
    resumed = _run(problem, tmp_path, resume=True)
    np.testing.assert_array_equal(resumed.X, full.X)
    np.testing.assert_array_equal(resumed.F, full.F)
    assert resumed.history == full.history


def test_a_kill_resumes_from_an_older_generation_to_the_same_result(
    problem: TrajectoryProblem, full, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The wall clock advances 0.6 s per generation (a fake clock): with an interval of 1 s
    generation 3 is written (1.2 s after the start); killed (no Ctrl-C handling) after
    generation 4, the run resumes from generation 3 and computes 4 again, then 5 and 6."""
    now = [0.0]
    monkeypatch.setattr(loop_module.time, "perf_counter", lambda: now[0])
    written = _writes(monkeypatch)

    def tick(info) -> None:
        now[0] += 0.6
        if info.generation == 4:
            raise SystemExit("killed")  # not caught by the loop: nothing more is written

    with pytest.raises(SystemExit):
        _run(problem, tmp_path, checkpoint_interval=1.0, progress=tick)
    assert written == [3]
    monkeypatch.undo()
    resumed = _run(problem, tmp_path, resume=True)
    np.testing.assert_array_equal(resumed.X, full.X)
    np.testing.assert_array_equal(resumed.F, full.F)
    assert resumed.history == full.history
    assert resumed.n_evaluations == full.n_evaluations
