"""The optimisation loop: determinism, exact resume after an interruption, algorithms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import adept_traj as at
from adept_traj import TrajectoryProblem
from adept_traj.errors import ConfigurationError
from adept_traj.optimise import (
    ALGORITHMS,
    FastEndSearch,
    KinematicTimeRepair,
    PlanningInterrupted,
    RampSampling,
    kinematic_time,
    make_algorithm,
    optimise,
)


@pytest.mark.parametrize("name", ["nsga2", "mode"])
def test_same_seed_same_population(problem: TrajectoryProblem, name: str) -> None:
    runs = [optimise(problem, make_algorithm(name, 16, 3)[0], 3, seed=7) for _ in range(2)]
    np.testing.assert_array_equal(runs[0].X, runs[1].X)
    np.testing.assert_array_equal(runs[0].F, runs[1].F)
    other = optimise(problem, make_algorithm(name, 16, 3)[0], 3, seed=8)
    assert not np.array_equal(other.X, runs[0].X)
    assert runs[0].n_evaluations == 16 * 3
    assert runs[0].n_generations == 3
    assert 0 < runs[0].evaluation_s <= runs[0].total_s


@pytest.mark.parametrize("name", ["nsga2", "mode"])
def test_interrupted_run_resumes_exactly(
    problem: TrajectoryProblem, name: str, tmp_path: Path
) -> None:
    fingerprint = {"algorithm": name, "seed": 3}
    full = optimise(problem, make_algorithm(name, 12, 5)[0], 5, seed=3)

    def interrupt(info) -> None:
        if info.generation == 2:
            raise KeyboardInterrupt

    with pytest.raises(PlanningInterrupted, match="after generation 2"):
        optimise(
            problem,
            make_algorithm(name, 12, 5)[0],
            5,
            seed=3,
            checkpoint=tmp_path,
            fingerprint=fingerprint,
            progress=interrupt,
        )
    resumed = optimise(
        problem,
        make_algorithm(name, 12, 5)[0],
        5,
        seed=3,
        checkpoint=tmp_path,
        resume=True,
        fingerprint=fingerprint,
    )
    np.testing.assert_array_equal(resumed.X, full.X)
    np.testing.assert_array_equal(resumed.F, full.F)
    assert resumed.n_evaluations == full.n_evaluations
    assert [h["generation"] for h in resumed.history] == [1, 2, 3, 4, 5]
    with pytest.raises(ConfigurationError, match="another run"):
        optimise(
            problem,
            make_algorithm(name, 12, 5)[0],
            5,
            seed=4,
            checkpoint=tmp_path,
            resume=True,
            fingerprint={"algorithm": name, "seed": 4},
        )


def test_resume_without_checkpoint(problem: TrajectoryProblem, tmp_path: Path) -> None:
    with pytest.raises(ConfigurationError, match="no checkpoint"):
        optimise(problem, make_algorithm("nsga2", 8, 2)[0], 2, 1, checkpoint=tmp_path, resume=True)


def test_kinematic_time_repair_meets_the_limits(problem: TrajectoryProblem) -> None:
    x = RampSampling().do(problem, 30, random_state=np.random.default_rng(1)).get("X")
    t_kin = kinematic_time(problem, x)
    x[:, 0] = t_kin * (1 + 1e-9)
    b = problem.trajectory.bounds(x)
    lim = problem.robot.limits
    ratios = np.stack(
        [b.qd_abs_max / lim.velocity, b.qdd_abs_max / lim.acceleration, b.qddd_abs_max / lim.jerk]
    )
    assert np.all(ratios <= 1.0)
    assert np.allclose(ratios.max(axis=(0, 2)), 1.0, atol=1e-6)  # tight: one limit is active
    assert np.all(t_kin >= problem.lower_bound.T_min * (1 - 1e-9))  # never beats the bound


def test_paper_settings_and_names() -> None:
    alg, settings = make_algorithm("NSGA-II")
    assert (settings.name, settings.pop_size, settings.n_gen) == ("nsga2", 100, 100)
    assert settings.params["crossover_prob"] == 0.7
    assert settings.params["mutation_prob_var"] == 0.01
    assert alg.mating.mutation.prob_var.value == 0.01
    assert alg.mating.crossover.eta.value == 10.0
    _, mode = make_algorithm("mode")
    assert (mode.pop_size, mode.params["CR"], mode.params["F"]) == (500, 0.9, 0.5)
    for name in ALGORITHMS:
        make_algorithm(name, pop_size=12, n_gen=1)
    with pytest.raises(ConfigurationError, match="unknown algorithm 'cmaes'"):
        make_algorithm("cmaes")
    with pytest.raises(ConfigurationError, match=r"pop_size must be an integer in \[2, ∞\]; got 1"):
        make_algorithm("nsga2", pop_size=1)
    with pytest.raises(ConfigurationError, match="unknown parameter"):
        make_algorithm("mode", eta=3)


@pytest.mark.parametrize("name", ["nsga3", "smsemoa"])
def test_other_pymoo_algorithms_run(problem: TrajectoryProblem, name: str) -> None:
    state = optimise(problem, make_algorithm(name, 12, 2)[0], 2, seed=1)
    assert state.n_generations == 2
    assert state.X.shape[1] == problem.n_var


def test_settings_are_checked_with_the_library_error(problem: TrajectoryProblem) -> None:
    """Every setting of the optimiser goes through adept_traj.validation: booleans, strings,
    NaN and out-of-range values raise ConfigurationError naming the setting; numpy numbers
    are accepted."""
    _, settings = make_algorithm("nsga2", pop_size=np.int64(10), n_gen=np.int32(2))
    assert (settings.pop_size, settings.n_gen) == (10, 2)
    assert type(settings.pop_size) is int
    _, settings = make_algorithm("mode", F=np.float32(0.25), CR=1)
    assert (settings.params["F"], settings.params["CR"]) == (0.25, 1.0)
    bad = [
        (lambda: make_algorithm("nsga2", pop_size=True), "pop_size"),
        (lambda: make_algorithm("nsga2", n_gen=2.0), "n_gen"),
        (lambda: make_algorithm("mode", F=float("nan")), "mode parameter F"),
        (lambda: make_algorithm("mode", CR="0.9"), "mode parameter CR"),
        (lambda: FastEndSearch(None, fraction=True), "fast_end fraction"),
        (lambda: FastEndSearch(None, n_elite=2.0), "n_elite"),
        (lambda: FastEndSearch(None, sigma=(0.0, 0.1)), "sigma"),
        (lambda: RampSampling(detour="x"), "detour"),
        (lambda: RampSampling(min_window=0.0), "min_window"),
        (lambda: RampSampling(detour_prob=1.5), "detour_prob"),
        (lambda: KinematicTimeRepair(snap=float("inf")), "snap"),
        (lambda: at.plan(problem, max_certify=0, pop_size=4, n_gen=1), "max_certify"),
        (lambda: at.plan(problem, seed=1.0, pop_size=4, n_gen=1), "seed"),
    ]
    for call, name in bad:
        with pytest.raises(ConfigurationError, match=name):
            call()
