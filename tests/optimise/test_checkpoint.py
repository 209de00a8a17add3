"""Checkpoints: the contract with pymoo's internals, the file format, exact resume.

The ``test_pymoo_*`` tests pin exactly what :mod:`adept_traj.optimise.search.checkpoint` relies on
in pymoo (private methods, attributes, per-individual fields, the order of its bookkeeping),
on a small two-objective problem with pymoo's own NSGA-II. If a pymoo upgrade breaks one,
its message says what changed; adapt ``adept_traj/optimise/search/checkpoint.py`` (and
``docs/engine.md``), nothing else.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.core.evaluator import Evaluator
from pymoo.core.population import Population
from pymoo.core.problem import Problem
from pymoo.core.repair import Repair
from pymoo.operators.sampling.rnd import FloatRandomSampling

from adept_traj.errors import CheckpointFormatError, ConfigurationError
from adept_traj.optimise import (
    CHECKPOINT_VERSION,
    PlanningInterrupted,
    load_checkpoint,
    make_algorithm,
    optimise,
    restore_algorithm,
    save_checkpoint,
)

STORED = Path(__file__).parents[1] / "data" / "checkpoint_v1"
UPGRADE = "pymoo changed; adapt adept_traj/optimise/search/checkpoint.py: "


class Toy(Problem):
    """Two objectives over [0, 1]^4, one constraint that about half of the box meets, and a
    count of evaluated points."""

    def __init__(self) -> None:
        super().__init__(n_var=4, n_obj=2, n_ieq_constr=1, xl=0.0, xu=1.0)
        self.n_points = 0

    def _evaluate(self, x, out, *args, **kwargs) -> None:
        self.n_points += len(x)
        out["F"] = np.column_stack([x[:, 0], 1.0 - np.sqrt(x[:, 0]) + x[:, 1:].sum(axis=1)])
        out["G"] = (x[:, 1] + x[:, 2] - 0.8)[:, None]


def generations(algorithm, problem, n: int) -> None:
    """``n`` generations by pymoo's public ask/tell, as the loop runs them."""
    for _ in range(n):
        infills = algorithm.ask()
        algorithm.evaluator.eval(problem, infills, algorithm=algorithm)
        algorithm.tell(infills=infills)


def set_up(n_gen: int = 6, seed: int = 1, **kwargs) -> tuple[NSGA2, Toy]:
    problem = Toy()
    algorithm = NSGA2(pop_size=10, **kwargs)
    algorithm.setup(problem, seed=seed, termination=("n_gen", n_gen), verbose=False)
    return algorithm, problem


# ----------------------------------------------------------------- the contract with pymoo


def test_pymoo_counters_after_a_generation() -> None:
    algorithm, problem = set_up(n_gen=6)
    assert isinstance(algorithm.random_state, np.random.Generator), UPGRADE + (
        "Algorithm.random_state is no numpy Generator after setup(seed=...)"
    )
    assert algorithm.is_initialized is False, UPGRADE + "is_initialized before the first tell"
    generations(algorithm, problem, 2)
    assert algorithm.is_initialized is True, UPGRADE + "is_initialized after the first tell"
    assert algorithm.n_iter == 3, UPGRADE + (
        f"n_iter after 2 generations is {algorithm.n_iter}, expected 3 (the next one)"
    )
    assert algorithm.evaluator.n_eval == 20 == problem.n_points, UPGRADE + (
        f"evaluator.n_eval is {algorithm.evaluator.n_eval}, expected 20 evaluations"
    )
    # progress is set from n_iter before pymoo counts the generation: 2 of 6 done
    assert algorithm.termination.perc == pytest.approx(2 / 6), UPGRADE + (
        f"termination progress after 2 of 6 generations is {algorithm.termination.perc}"
    )
    algorithm.n_iter = 5
    algorithm.termination.update(algorithm)
    assert algorithm.termination.perc == pytest.approx(5 / 6), UPGRADE + (
        "termination.update(algorithm) no longer reads the progress from n_iter"
    )


def test_pymoo_initialize_and_set_optimum() -> None:
    algorithm, problem = set_up()
    generations(algorithm, problem, 3)
    pop, optimum = algorithm.pop, algorithm.opt.get("X")
    algorithm._initialize()
    assert (algorithm.n_iter, len(algorithm.pop), algorithm.opt) == (1, 0, None), UPGRADE + (
        "Algorithm._initialize() no longer resets n_iter to 1, pop to empty and opt to None"
    )
    algorithm.pop = pop
    algorithm._set_optimum()
    assert np.array_equal(algorithm.opt.get("X"), optimum), UPGRADE + (
        "Algorithm._set_optimum() no longer recomputes opt from pop (and its data) alone"
    )


def test_pymoo_per_individual_data() -> None:
    algorithm, problem = set_up()
    generations(algorithm, problem, 3)
    data = [ind.data for ind in algorithm.pop]
    assert all(isinstance(d, dict) for d in data), UPGRADE + "Individual.data is no dict"
    ranked = [d for d in data if "rank" in d]
    assert ranked, UPGRADE + "NSGA-II keeps its ranks no longer in Individual.data"
    assert all("crowding" in d for d in ranked), UPGRADE + "crowding not beside rank in data"
    pop = Population.new(X=np.zeros((3, 4)))
    pop.set("rank", np.array([2, 0, 1]))
    assert [ind.data["rank"] for ind in pop] == [2, 0, 1], UPGRADE + (
        "Population.set(key, values) no longer stores a non-field key in Individual.data"
    )
    pop[np.array([True, False, True])].set("crowding", np.array([0.5, 1.5]))
    assert ["crowding" in ind.data for ind in pop] == [True, False, True], UPGRADE + (
        "a masked Population view no longer sets the individuals of the population"
    )


def test_pymoo_skips_individuals_marked_evaluated() -> None:
    problem = Toy()
    pop = Population.new(X=np.full((4, 4), 0.25))
    assert all(ind.evaluated == set() for ind in pop), UPGRADE + "Individual.evaluated"
    for ind in pop[:3]:
        ind.evaluated.update({"F", "G", "H"})
    evaluator = Evaluator()
    evaluator.eval(problem, pop)
    assert (problem.n_points, evaluator.n_eval) == (1, 1), UPGRADE + (
        "the evaluator evaluates individuals whose Individual.evaluated holds F, G and H"
    )


def test_pymoo_operators_draw_from_the_algorithm_generator() -> None:
    """Exact resume restores one generator: every operator must draw from it (pymoo passes
    ``random_state`` to sampling, mating, repair and survival). FastEndSearch and
    KinematicTimeRepair read the same keyword."""
    seen = []

    class Recording(Repair):
        def _do(self, problem, X, random_state=None, **kwargs):
            seen.append(random_state)
            return X

    algorithm, problem = set_up(repair=Recording())
    generations(algorithm, problem, 3)
    assert len(seen) >= 3, UPGRADE + "the repair is not called every generation"
    assert all(rs is algorithm.random_state for rs in seen), UPGRADE + (
        "the repair does not get the algorithm's random_state"
    )
    mating = algorithm.mating
    received = []

    def spy(*args, random_state=None, **kwargs):
        received.append(random_state)
        return type(mating).do(mating, *args, random_state=random_state, **kwargs)

    mating.do = spy
    generations(algorithm, problem, 1)
    assert received == [algorithm.random_state], UPGRADE + (
        "the mating is not called with random_state=algorithm.random_state"
    )


# ------------------------------------------------------------------ format and exact resume


def test_files_and_keys(tmp_path: Path) -> None:
    algorithm, problem = set_up()
    generations(algorithm, problem, 2)
    meta = {"fingerprint": {"a": 1}, "total_s": 1.5, "evaluation_s": 1.0, "history": []}
    save_checkpoint(tmp_path, algorithm, meta, {"extra": np.arange(3.0)})
    assert [p.name for p in tmp_path.iterdir()] == ["checkpoint.npz"]  # one file, one rename
    with np.load(tmp_path / "checkpoint.npz", allow_pickle=False) as data:
        assert {"X", "F", "G", "CV", "n_iter", "meta", "loop.extra"} <= set(data.files)
        stored = json.loads(str(data["meta"]))
    assert stored["format"] == "adept_traj.checkpoint"
    assert stored["version"] == CHECKPOINT_VERSION == 2
    assert (stored["n_iter"], stored["n_eval"]) == (3, 20)
    loaded, arrays = load_checkpoint(tmp_path)
    assert loaded == stored
    np.testing.assert_array_equal(arrays["X"], algorithm.pop.get("X"))
    np.testing.assert_array_equal(arrays["CV"], algorithm.pop.get("CV"))
    np.testing.assert_array_equal(arrays["loop.extra"], [0.0, 1.0, 2.0])
    assert int(arrays["n_iter"]) == 3
    assert "meta" not in arrays


def test_a_version_1_checkpoint_is_replaced_by_one_file(tmp_path: Path) -> None:
    """Resuming a version-1 checkpoint (two files) writes version 2 and removes the old
    metadata file, so the folder never holds two generations' files."""
    shutil.copytree(STORED, tmp_path, dirs_exist_ok=True)
    meta, _ = load_checkpoint(tmp_path)
    assert meta["version"] == 1
    algorithm, problem = set_up()
    generations(algorithm, problem, 1)
    save_checkpoint(tmp_path, algorithm, {k: meta[k] for k in ("fingerprint", "history")} | {
        "total_s": 0.0, "evaluation_s": 0.0})  # fmt: skip
    assert [p.name for p in tmp_path.iterdir()] == ["checkpoint.npz"]
    assert load_checkpoint(tmp_path)[0]["version"] == 2


def test_an_interrupted_write_keeps_the_previous_checkpoint(tmp_path: Path, monkeypatch) -> None:
    """Ctrl-C while the checkpoint is written: the previous one stays whole and no
    temporary file is left behind."""
    algorithm, problem = set_up()
    generations(algorithm, problem, 1)
    meta = {"fingerprint": {}, "total_s": 0.0, "evaluation_s": 0.0, "history": []}
    save_checkpoint(tmp_path, algorithm, meta)
    before = (tmp_path / "checkpoint.npz").read_bytes()
    generations(algorithm, problem, 1)

    def torn(fh, **arrays):
        fh.write(b"PK half a file")
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez", torn)
    with pytest.raises(KeyboardInterrupt):
        save_checkpoint(tmp_path, algorithm, meta)
    assert [p.name for p in tmp_path.iterdir()] == ["checkpoint.npz"]
    assert (tmp_path / "checkpoint.npz").read_bytes() == before
    assert load_checkpoint(tmp_path)[0]["n_iter"] == 2


def test_restore_continues_exactly(tmp_path: Path) -> None:
    """A fresh algorithm restored from a checkpoint draws the same next generation."""
    algorithm, problem = set_up(n_gen=6, seed=4)
    generations(algorithm, problem, 2)
    meta = {"fingerprint": {}, "total_s": 0.0, "evaluation_s": 0.0, "history": []}
    save_checkpoint(tmp_path, algorithm, meta)
    fresh, fresh_problem = set_up(n_gen=6, seed=99)  # another seed: all state is restored
    restore_algorithm(fresh, *load_checkpoint(tmp_path))
    generations(algorithm, problem, 1)
    generations(fresh, fresh_problem, 1)
    np.testing.assert_array_equal(fresh.pop.get("X"), algorithm.pop.get("X"))
    assert fresh.n_iter == algorithm.n_iter == 4
    assert fresh.evaluator.n_eval == algorithm.evaluator.n_eval == 30
    assert fresh_problem.n_points == 10  # the restored members were not evaluated again


def test_stored_checkpoint_of_the_flat_layout_resumes(problem, tmp_path: Path) -> None:
    """``tests/data/checkpoint_v1`` was written by the code before the checkpoint module
    (NSGA-II, population 8, interrupted after generation 2 of 4, seed 5): it still loads and
    a run resumes from it to the end."""
    meta, arrays = load_checkpoint(STORED)
    assert (meta["n_iter"], meta["n_eval"], arrays["X"].shape) == (3, 16, (8, problem.n_var))
    shutil.copytree(STORED, tmp_path / "run")
    state = optimise(
        problem,
        make_algorithm("nsga2", 8, 4)[0],
        4,
        seed=5,
        checkpoint=tmp_path / "run",
        resume=True,
        fingerprint=meta["fingerprint"],
    )
    assert [h["generation"] for h in state.history] == [1, 2, 3, 4]
    assert state.n_evaluations == 32
    assert state.X.shape == (8, problem.n_var)


def test_load_refuses_a_foreign_or_torn_checkpoint(tmp_path: Path) -> None:
    shutil.copytree(STORED, tmp_path, dirs_exist_ok=True)
    meta = json.loads((tmp_path / "checkpoint.json").read_text())
    (tmp_path / "checkpoint.json").write_text(json.dumps({**meta, "n_iter": 2}))
    with pytest.raises(ConfigurationError, match="disagree; cannot resume exactly"):
        load_checkpoint(tmp_path)
    (tmp_path / "checkpoint.json").write_text(json.dumps({**meta, "version": 2}))
    with pytest.raises(ConfigurationError, match="not an adept_traj checkpoint of version 1"):
        load_checkpoint(tmp_path)
    del meta["rng"]
    (tmp_path / "checkpoint.json").write_text(json.dumps(meta))
    with pytest.raises(CheckpointFormatError, match=r"checkpoint\.json: damaged checkpoint: "
                       r"missing the values \['rng'\]"):  # fmt: skip
        load_checkpoint(tmp_path)
    (tmp_path / "checkpoint.json").unlink()
    with pytest.raises(
        CheckpointFormatError, match=r"\(array 'meta'\): missing, and no checkpoint\.json"
    ):
        load_checkpoint(tmp_path)
    (tmp_path / "checkpoint.npz").write_bytes(b"PK torn")
    with pytest.raises(
        CheckpointFormatError, match=r"not an \.npz archive \(it starts with b'PK t'"
    ):
        load_checkpoint(tmp_path)


def _with_meta(folder: Path, text: str) -> None:
    """Replace the metadata inside ``folder``'s checkpoint.npz by ``text``."""
    with np.load(folder / "checkpoint.npz", allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["meta"] = np.array(text)
    with (folder / "checkpoint.npz").open("wb") as fh:
        np.savez(fh, **arrays)


@pytest.mark.parametrize(
    ("tamper", "match"),
    [
        (lambda t: t.replace('"total_s": 1.5', '"total_s": NaN'), r"NaN is not a JSON number"),
        (lambda t: t.replace('"total_s": 1.5', '"total_s": 1e400'), r"number 1e400 is not finite"),
        (lambda t: t.replace('"history": []', '"history": ' + "[" * 100_000 + "]" * 100_000),
         r"nested 100001 levels deep, more than the limit of 64"),
    ],
)  # fmt: skip
def test_load_refuses_non_finite_or_deep_metadata(tmp_path: Path, tamper, match: str) -> None:
    algorithm, problem = set_up()
    generations(algorithm, problem, 2)
    meta = {"fingerprint": {"a": 1}, "total_s": 1.5, "evaluation_s": 1.0, "history": []}
    save_checkpoint(tmp_path, algorithm, meta)
    with np.load(tmp_path / "checkpoint.npz", allow_pickle=False) as data:
        text = str(data["meta"])
    assert tamper(text) != text
    _with_meta(tmp_path, tamper(text))
    with pytest.raises(ConfigurationError, match=r"checkpoint\.npz \(meta\): (the )?" + match):
        load_checkpoint(tmp_path)


def test_load_refuses_a_version_1_metadata_file_with_nan(tmp_path: Path) -> None:
    shutil.copytree(STORED, tmp_path, dirs_exist_ok=True)
    meta = json.loads((tmp_path / "checkpoint.json").read_text())
    (tmp_path / "checkpoint.json").write_text(json.dumps({**meta, "total_s": float("nan")}))
    with pytest.raises(ConfigurationError, match=r"checkpoint\.json: NaN is not a JSON number"):
        load_checkpoint(tmp_path)


def test_resume_restores_the_fronts_of_every_generation(tmp_path: Path) -> None:
    """The per-generation fronts (for the hypervolume history) survive an interruption."""
    full = optimise(Toy(), NSGA2(pop_size=10), 5, seed=3)
    with pytest.raises(PlanningInterrupted):
        optimise(
            Toy(), NSGA2(pop_size=10), 5, seed=3, checkpoint=tmp_path, progress=_interrupt_at(2)
        )
    resumed = optimise(Toy(), NSGA2(pop_size=10), 5, seed=3, checkpoint=tmp_path, resume=True)
    assert len(resumed.fronts) == len(full.fronts) == 5
    for a, b in zip(resumed.fronts, full.fronts):
        np.testing.assert_array_equal(a, b)


class StoppedWhileEvaluating(Toy):
    """Ctrl-C during the first evaluation (the first generation)."""

    def _evaluate(self, x, out, *args, **kwargs) -> None:
        raise KeyboardInterrupt


def test_ctrl_c_in_the_first_generation_names_no_checkpoint(tmp_path: Path) -> None:
    with pytest.raises(PlanningInterrupted, match="nothing checkpointed") as caught:
        optimise(StoppedWhileEvaluating(), NSGA2(pop_size=10), 3, seed=1, checkpoint=tmp_path)
    assert caught.value.checkpoint is None
    assert list(tmp_path.iterdir()) == []


def _interrupt_at(generation: int):
    def progress(info) -> None:
        if info.generation == generation:
            raise KeyboardInterrupt

    return progress


@pytest.mark.parametrize("name", ["nsga2", "mode"])
def test_resume_from_a_population_of_feasible_and_infeasible_members(
    name: str, tmp_path: Path
) -> None:
    """NSGA-II ranks only the feasible members; their ranks and crowding distances are
    checkpointed too (resuming once failed with a TypeError in the tournament)."""
    settings = {"sampling": FloatRandomSampling(), "repair": False, "fast_end": 0}

    def algorithm():
        return make_algorithm(name, 10, 6, **settings)[0]

    full = optimise(Toy(), algorithm(), 6, seed=2)
    with pytest.raises(PlanningInterrupted):
        optimise(Toy(), algorithm(), 6, seed=2, checkpoint=tmp_path, progress=_interrupt_at(2))
    _, arrays = load_checkpoint(tmp_path)
    feasible = arrays["CV"][:, 0] <= 0
    assert 0 < feasible.sum() < len(feasible)  # a mixed population is checkpointed
    resumed = optimise(Toy(), algorithm(), 6, seed=2, checkpoint=tmp_path, resume=True)
    np.testing.assert_array_equal(resumed.X, full.X)
    np.testing.assert_array_equal(resumed.F, full.F)


def test_resume_after_the_last_generation_runs_no_further_one(tmp_path: Path) -> None:
    full = optimise(Toy(), NSGA2(pop_size=10), 3, seed=1)
    with pytest.raises(PlanningInterrupted, match="after generation 3"):
        optimise(
            Toy(), NSGA2(pop_size=10), 3, seed=1, checkpoint=tmp_path, progress=_interrupt_at(3)
        )
    resumed = optimise(Toy(), NSGA2(pop_size=10), 3, seed=1, checkpoint=tmp_path, resume=True)
    assert resumed.n_generations == 3
    assert resumed.n_evaluations == full.n_evaluations == 30
    np.testing.assert_array_equal(resumed.X, full.X)
