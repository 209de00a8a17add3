"""The phase grid's refinement (:func:`adept_traj.cycle.plan_phase_grid`), its loop alone:
the planning tasks, the Dask client, the rest and move certificates are stand-ins with a
known answer (a plan is certified wherever it runs only if it was planned at a phase
halfway between the 2-phase grid's), so that the 2-phase grid has no certified schedule
and its refinement to 4 phases has one; the schedules are chosen by the real code."""

from __future__ import annotations

import contextlib
import math
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

import adept_traj.cycle.phase_grid as phase_grid
from adept_traj.cycle import plan_phase_grid, read_cycle_file, scene_period
from adept_traj.errors import CycleError
from adept_traj.scene import Scene
from adept_traj.testing.cycle_files import HOME, PLACE, cycle_text, write_cycle

CYCLE = cycle_text(
    "detour",
    scene="detour",
    repeat=3,
    plan={"pop_size": 8, "n_gen": 3, "seed": 3},
    locations={"a": {"joints": HOME}, "b": {"joints": PLACE}},
    moves=[("a", "b"), ("b", "a")],
)
#: Travel time of every stand-in plan, as a share of the period: its arrivals' phases are
#: then never a multiple of P / 4.
T_SHARE = 0.3


def _good(phase: float, period: float) -> bool:
    """A stand-in plan is certified wherever it runs iff planned at P/4 or 3P/4."""
    return any(math.isclose(phase, f * period, abs_tol=1e-9) for f in (0.25, 0.75))


@pytest.fixture
def stand_ins(monkeypatch: pytest.MonkeyPatch) -> dict[str, Any]:
    period = scene_period(Scene.shipped("detour"))
    seen: dict[str, Any] = {"tasks": [], "progress": [], "refining": []}

    def run_planning_tasks(tasks, where, **kwargs):
        out = []
        for t in tasks:
            seen["tasks"].append((t.move.name, t.start_time))
            if kwargs["progress"] is not None:
                kwargs["progress"](t.move.name)
            front = SimpleNamespace(
                objectives=np.array([[T_SHARE * period, 1, 1, 1, 1, 1]]),
                feasible=np.array([True]),
                x=np.zeros((1, 3)),
            )
            out.append(SimpleNamespace(front=front, best=SimpleNamespace(index=0)))
        return out

    class MoveCertifier:
        def __init__(self, robot, scene, rate_hz, plans, client=None):
            self.plans = [list(row) for row in plans]

        def add(self, k: int, plans) -> None:
            self.plans[k].extend(plans)

        def __call__(self, k: int, i: int, start: float) -> bool:
            return _good(self.plans[k][i].planned_at, period)

        def prefetch(self, queries) -> None:
            pass

    class Rests:
        def __init__(self, *args, **kwargs):
            pass

        def __call__(self, k, start, duration):
            return SimpleNamespace(certified=True)

    profile = SimpleNamespace(allows=lambda start, duration: True)
    monkeypatch.setattr(phase_grid, "run_planning_tasks", run_planning_tasks)
    monkeypatch.setattr(phase_grid, "MoveCertifier", MoveCertifier)
    monkeypatch.setattr(phase_grid, "RestCertifier", Rests)
    monkeypatch.setattr(phase_grid, "RestProfile", SimpleNamespace(at=lambda *a, **k: profile))
    monkeypatch.setattr(phase_grid, "dask_client", lambda *a: contextlib.nullcontext())
    seen["period"] = period
    return seen


def test_a_grid_without_a_certified_schedule_is_refined_once(
    stand_ins: dict[str, Any], tmp_path: Path
) -> None:
    """2 phases: no plan is certified where it runs; refined to 4 (the phases P/4, 3P/4
    of every move, named NAME.phJof4, after the grid's and the arrivals' plans): every
    pass back to back on the refined plans, the grid's sizes and the refinement said."""
    P = stand_ins["period"]
    cycle = read_cycle_file(write_cycle(tmp_path, CYCLE, scenes={}))
    clock, results, report = plan_phase_grid(
        cycle,
        tmp_path / "out",
        phases=2,
        progress=stand_ins["progress"].append,
        refining=stand_ins["refining"].append,
    )
    names = [name for name, _ in stand_ins["tasks"]]
    assert names[:4] == ["a-b.ph0", "a-b.ph1", "b-a.ph0", "b-a.ph1"]
    refined = [(n, s) for n, s in stand_ins["tasks"] if "of" in n]
    assert [n for n, _ in refined] == ["a-b.ph1of4", "a-b.ph3of4", "b-a.ph1of4", "b-a.ph3of4"]
    np.testing.assert_allclose([s for _, s in refined], [P / 4, 3 * P / 4] * 2, atol=1e-12)
    arrivals = [n for n in names if ".x" in n]
    assert arrivals == [f"b-a.x{i}" for i in range(len(arrivals))]  # one counter, no clash
    assert len(set(names)) == len(names)
    assert stand_ins["refining"] == [4]
    assert stand_ins["progress"] == names  # each plan as it is saved
    assert report["grid_sizes"] == [2, 4]
    np.testing.assert_allclose(report["phases"], P * np.arange(4) / 4, atol=1e-12)
    assert sum(report["plans"]) == len(names)
    assert clock.period is None  # every pass back to back
    moves = [m for row in clock.passes for m in row]
    assert len(moves) == 2 * cycle.repeat
    assert all(m.folder.endswith("of4") and m.move_certified for m in moves)
    assert clock.certified
    assert [len(row) for row in results] == [2] * cycle.repeat  # each pass's plans


def test_refinement_stops_at_max_phases_and_names_the_grids(
    stand_ins: dict[str, Any], tmp_path: Path
) -> None:
    """``max_phases = 2`` (no refinement) and ``3`` (4 is beyond it): refused, naming the
    grid tried and the bound, with no refined plan made."""
    cycle = read_cycle_file(write_cycle(tmp_path, CYCLE, scenes={}))
    for most in (2, 3):
        with pytest.raises(CycleError, match=rf"a grid of 2 phases \(max_phases = {most}\)"):
            plan_phase_grid(cycle, tmp_path / f"out{most}", phases=2, max_phases=most)
    assert not any("of" in name for name, _ in stand_ins["tasks"])
    assert stand_ins["refining"] == []


def test_a_certified_grid_is_not_refined(stand_ins: dict[str, Any], tmp_path: Path) -> None:
    """4 phases from the start: certified at once, nothing refined (the same tasks as a
    grid without refinement: the grid's, then the arrivals')."""
    cycle = read_cycle_file(write_cycle(tmp_path, CYCLE, scenes={}))
    clock, _, report = plan_phase_grid(
        cycle, tmp_path / "out", phases=4, refining=stand_ins["refining"].append
    )
    names = [name for name, _ in stand_ins["tasks"]]
    assert names[:8] == [f"{m}.ph{j}" for m in ("a-b", "b-a") for j in range(4)]
    assert all((".ph" in n and "of" not in n) or ".x" in n for n in names)
    assert report["grid_sizes"] == [4]
    assert stand_ins["refining"] == []
    assert clock.certified
