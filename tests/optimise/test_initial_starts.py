"""The global stage's starts in the evolutionary search's initial population (issue #24):
:func:`~adept_traj.optimise.initial_starts` (the relaxed problem's optimum where the fixed
obstacles block the straight move) and
:class:`~adept_traj.optimise.SeededInitialization` (put there as given, not repaired).

References: the kinematic-time repair's own snap (a repaired start would sit at its
path's kinematic minimum T), the relaxed optimum computed directly, the evaluator."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import adept_traj as at
from adept_traj.errors import ConfigurationError
from adept_traj.optimise import (
    GLOBAL_GAP,
    MAX_BASINS,
    KinematicTimeRepair,
    PlanningInterrupted,
    initial_starts,
    kinematic_time,
    make_algorithm,
    optimise,
    plan,
    relaxed_optimum,
)
from adept_traj.optimise.local import multi_start
from adept_traj.optimise.local.multi_start import made_relaxed_optima


@pytest.fixture(scope="module")
def paper() -> at.TrajectoryProblem:
    scene = at.Scene.paper()
    return at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal, workers=1)


@pytest.fixture(scope="module")
def detour() -> at.TrajectoryProblem:
    scene = at.Scene.shipped("detour")
    return at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal, workers=1)


def _slow_moves(problem: at.TrajectoryProblem) -> np.ndarray:
    """Three different paths, each at 1.5 × its kinematic minimum T (the repair's snap
    would lower every one of them)."""
    traj = problem.trajectory
    base = traj.straight_line(problem.xu[0])
    moves = np.repeat(base[None], 3, axis=0)
    moves[:, 1:] += np.linspace(-0.05, 0.05, 3)[:, None] * np.sin(
        np.linspace(0, np.pi, base.size - 1)
    )
    moves = np.clip(moves, problem.xl, problem.xu)
    moves[:, 0] = np.minimum(1.5 * kinematic_time(problem, moves), problem.xu[0])
    return moves


def test_the_starts_enter_the_initial_population_as_given(paper) -> None:
    starts = _slow_moves(paper)
    alg, settings = make_algorithm("nsga2", 12, 1, starts=starts)
    alg.repair = alg.initialization.repair = KinematicTimeRepair(snap=1.0)  # snaps every row
    alg.setup(paper, seed=3)
    x = alg.infill().get("X")
    np.testing.assert_array_equal(x[1:4], starts)
    # the repair would have moved them: each to its path's kinematic minimum T
    repaired = KinematicTimeRepair(snap=1.0)._do(
        paper, starts, random_state=np.random.default_rng(0)
    )
    np.testing.assert_allclose(repaired[:, 0], kinematic_time(paper, starts), rtol=1e-6)
    assert np.all(repaired[:, 0] < starts[:, 0])
    assert settings.params["initial_starts"] == 3
    _, plain = make_algorithm("nsga2", 12, 1)
    assert "initial_starts" not in plain.params  # without starts: the settings as before


def test_the_rest_of_the_population_is_the_unseeded_one(paper) -> None:
    starts = _slow_moves(paper)
    seeded, _ = make_algorithm("nsga2", 12, 1, starts=starts)
    plain, _ = make_algorithm("nsga2", 12, 1)
    seeded.setup(paper, seed=5)
    plain.setup(paper, seed=5)
    a, b = seeded.infill().get("X"), plain.infill().get("X")
    np.testing.assert_array_equal(a[[0, *range(4, 12)]], b[[0, *range(4, 12)]])


def test_starts_of_the_wrong_width_are_refused(paper) -> None:
    alg, _ = make_algorithm("nsga2", 12, 1, starts=np.zeros((2, paper.n_var + 1)))
    alg.setup(paper, seed=1)
    with pytest.raises(ConfigurationError, match=f"n_var = {paper.n_var}"):
        alg.infill()


def test_no_initial_starts_where_the_relaxed_optimum_is_near_the_bound(paper) -> None:
    """The paper scene: its relaxed problem's optimum (the cubes alone) lies within
    GLOBAL_GAP of the kinematic lower bound, so the paper's runs are left as they were;
    without moving obstacles there is no relaxed problem."""
    relaxed, floor = relaxed_optimum(paper, n_starts=MAX_BASINS)
    assert len(relaxed) == len(multi_start.STRETCHES)
    assert floor <= paper.lower_bound.T_min * (1.0 + GLOBAL_GAP)
    assert initial_starts(paper).shape == (0, paper.n_var)
    still = paper.replace(scene=dataclasses.replace(paper.scene, obstacles=paper.scene.fixed))
    assert initial_starts(still).shape == (0, still.n_var)
    assert made_relaxed_optima(still) == {}  # nothing was computed


@pytest.mark.slow  # ~5–10 s: the relaxed problem's time-optimal mode on detour
def test_detour_seeds_the_relaxed_optimum_made_once_and_handed_over(detour, monkeypatch) -> None:
    """The detour scene's post puts the relaxed optimum 3 % above the bound: the starts
    are the relaxed optimum at STRETCHES × its T, made once (the polish asks for the
    same), and a fresh copy of the problem given the made optima (as the polisher's
    process is) does not make them again; seeded, the first generation already holds an
    evaluator-feasible move within 1.25 × the relaxed floor, on every seed tried."""
    starts = initial_starts(detour)
    relaxed, floor = relaxed_optimum(detour, n_starts=MAX_BASINS)
    assert starts is relaxed
    assert starts.shape == (len(multi_start.STRETCHES), detour.n_var)
    np.testing.assert_allclose(starts[:, 0], floor * np.asarray(multi_start.STRETCHES))
    made = made_relaxed_optima(detour)
    assert len(made) == 1
    copy = detour.replace()
    monkeypatch.setattr(multi_start, "_relaxed_optimum", _never)
    for key, value in made.items():
        copy.derived(key, lambda _p, value=value: value)
    assert initial_starts(copy) is relaxed
    for seed in (1, 2, 3):
        alg, _ = make_algorithm("nsga2", 20, 1, starts=starts)
        state = optimise(detour, alg, 1, seed)
        ok = np.all(np.asarray(state.G) <= 0.0, axis=1)
        assert ok.any()
        assert np.asarray(state.X)[ok, 0].min() <= 1.25 * floor


def _never(*_args, **_kwargs):
    raise AssertionError("the relaxed optimum was made again")


@pytest.mark.slow  # ~10–20 s: the relaxed optimum once, then three short runs on detour
def test_a_seeded_run_interrupted_and_resumed_is_the_uninterrupted_one(detour, tmp_path) -> None:
    """plan() seeds the initial population on detour; killed after generation 2 (its
    checkpoint) and resumed, it gives the front of the run never interrupted, the same
    settings (the resumed run computes the same starts: its fingerprint matches)."""
    budget = {"pop_size": 12, "n_gen": 4, "polish": "off", "max_certify": 2}
    full = plan(detour, "nsga2", seed=4, **budget)
    assert full.algorithm_settings["initial_starts"] == 3

    def interrupt(info) -> None:
        if info.generation == 2:
            raise KeyboardInterrupt

    folder = tmp_path / "checkpoint"
    with pytest.raises(PlanningInterrupted):
        plan(detour, "nsga2", seed=4, checkpoint=folder, progress=interrupt, **budget)
    resumed = plan(detour, "nsga2", seed=4, checkpoint=folder, resume=True, **budget)
    np.testing.assert_array_equal(resumed.front.x, full.front.x)
    np.testing.assert_array_equal(resumed.front.objectives, full.front.objectives)
    assert resumed.algorithm_settings == full.algorithm_settings


def test_a_bad_gap_is_refused_before_any_work(paper, monkeypatch) -> None:
    """``time_optimal``'s ``gap`` is a positive fraction: 0, −0.01, NaN and a string are
    refused with the library's error naming it, before any start is made."""
    monkeypatch.setattr(multi_start, "_starts", _never)
    for bad in (0.0, -0.01, float("nan"), "0.05"):
        with pytest.raises(ConfigurationError, match="gap"):
            multi_start.time_optimal(paper, 1, 2, gap=bad)


@pytest.mark.slow  # ~3–6 s: the relaxed problem's search on a fresh copy of detour
def test_the_relaxed_search_ends_at_its_first_move_within_the_relaxed_gap(
    detour, monkeypatch
) -> None:
    """On detour the relaxed problem's fastest screened move lies 2.9 % above T_lb: more
    than GLOBAL_GAP (the problem's own searches would go on), less than RELAXED_GAP, so
    its search ends there — no full refinement and no via-point start of the relaxed
    problem — with a certified floor inside the relaxed gap."""
    fresh = detour.replace()
    fixed = multi_start.relaxed_problem(fresh)
    calls: list[str] = []
    for name in ("refine_starts", "via_point_starts"):
        real = getattr(multi_start, name)

        def spy(problem, *args, _real=real, _name=name, **kwargs):
            if problem is fixed:
                calls.append(_name)
            return _real(problem, *args, **kwargs)

        monkeypatch.setattr(multi_start, name, spy)
    relaxed, floor = relaxed_optimum(fresh)
    t_lb = fresh.lower_bound.T_min
    assert t_lb * (1.0 + GLOBAL_GAP) < floor <= t_lb * (1.0 + multi_start.RELAXED_GAP)
    assert calls == []
    assert len(relaxed) == len(multi_start.STRETCHES)
    summary = at.certify(fixed, relaxed[0])
    assert summary.feasible
