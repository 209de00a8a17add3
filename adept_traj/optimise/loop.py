"""The optimisation loop: ask/tell with timings, progress, checkpoints and exact resume.

:func:`optimise` runs a pymoo algorithm on a problem generation by generation. After every
generation it can write a checkpoint folder (``checkpoint.json`` + ``checkpoint.npz``, no
pickle): the population with every per-individual attribute the algorithm keeps (F, G, CV,
rank, crowding, …), the generation and evaluation counters, the state of the algorithm's
random generator and the timings so far. :func:`optimise` with ``resume=True`` restores all
of it, so an interrupted run continues **exactly** as an uninterrupted one with the same
seed (tested). Ctrl-C (``KeyboardInterrupt``) during a generation leaves the last finished
generation on disk and raises :class:`PlanningInterrupted`.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from pymoo.core.population import Population

from adept_traj.analysis.indicators import non_dominated
from adept_traj.errors import ConfigurationError, PlanningInterrupted
from adept_traj.files import write_atomic

__all__ = ["GenerationInfo", "PlanningInterrupted", "RunState", "optimise"]

_CHECKPOINT_VERSION = 1


@dataclass(frozen=True)
class GenerationInfo:
    """Progress of one finished generation (passed to the progress callback)."""

    generation: int
    n_gen: int
    n_evaluations: int
    n_feasible: int
    best_time: float | None  # smallest z1 [s] among feasible individuals, if any
    elapsed_s: float


@dataclass(frozen=True)
class RunState:
    """Final population and bookkeeping of a run.

    ``X`` (pop, n_var), ``F`` (pop, n_obj) as pymoo sees them (z4 negated), ``G``
    (pop, n_constr), ``CV`` (pop,) total constraint violation.
    """

    X: np.ndarray
    F: np.ndarray
    G: np.ndarray
    CV: np.ndarray
    n_generations: int
    n_evaluations: int
    total_s: float
    evaluation_s: float
    history: list[dict[str, Any]] = field(default_factory=list)
    #: Per generation of this session (not restored on resume): the objectives (pymoo's
    #: sense) of the population's feasible non-dominated members, for hypervolume history.
    fronts: list[np.ndarray] = field(default_factory=list)


def _population_arrays(pop: Population, n_iter: int) -> dict[str, np.ndarray]:
    """Numeric per-individual attributes of ``pop`` as arrays (for the checkpoint), with the
    generation counter so that the two checkpoint files can be checked against each other."""
    out = {"X": pop.get("X"), "F": pop.get("F"), "G": pop.get("G"), "CV": pop.get("CV")}
    out["n_iter"] = np.array(n_iter)
    for key in pop[0].data if len(pop) else ():
        values = pop.get(key)
        if values.dtype != object and key not in out:
            out[f"data.{key}"] = values
    return out


def _restore_population(arrays: dict[str, np.ndarray]) -> Population:
    pop = Population.new(X=arrays["X"])
    pop.set("F", arrays["F"], "G", arrays["G"], "CV", arrays["CV"])
    for key, values in arrays.items():
        if key.startswith("data."):  # (n_iter is checked by load_checkpoint, not stored)
            pop.set(key[5:], values)
    for ind in pop:
        ind.evaluated.update({"F", "G", "H"})
    return pop


def _json_state(rng: np.random.Generator) -> dict[str, Any]:
    state = rng.bit_generator.state
    return json.loads(json.dumps(state, default=int))


def _save_checkpoint(folder: Path, algorithm: Any, meta: dict[str, Any]) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    arrays = _population_arrays(algorithm.pop, int(algorithm.n_iter))

    def write_npz(path: Path) -> None:
        with path.open("wb") as fh:
            np.savez(fh, **arrays)

    write_atomic(folder / "checkpoint.npz", write_npz)
    state = {
        "format": "adept_traj.checkpoint",
        "version": _CHECKPOINT_VERSION,
        "n_iter": int(algorithm.n_iter),
        "n_eval": int(algorithm.evaluator.n_eval),
        "rng": _json_state(algorithm.random_state),
        **meta,
    }
    write_atomic(folder / "checkpoint.json", lambda p: p.write_text(json.dumps(state, indent=1)))


def load_checkpoint(folder: Path) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """Read a checkpoint folder: (metadata, population arrays)."""
    meta_path, npz_path = folder / "checkpoint.json", folder / "checkpoint.npz"
    if not meta_path.is_file() or not npz_path.is_file():
        raise ConfigurationError(f"{folder}: no checkpoint to resume (checkpoint.json/.npz)")
    try:
        meta = json.loads(meta_path.read_text())
        with np.load(npz_path, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
    except (OSError, ValueError) as exc:
        raise ConfigurationError(f"{folder}: unreadable checkpoint: {exc}") from None
    version = _CHECKPOINT_VERSION
    if meta.get("format") != "adept_traj.checkpoint" or meta.get("version") != version:
        raise ConfigurationError(f"{meta_path}: not an adept_traj checkpoint of version {version}")
    needed = {"n_iter", "n_eval", "rng", "fingerprint", "total_s", "evaluation_s", "history"}
    missing = sorted(needed - set(meta)) + sorted({"X", "F", "G", "CV", "n_iter"} - set(arrays))
    if missing:
        raise ConfigurationError(f"{folder}: incomplete checkpoint, missing {missing}")
    if int(arrays["n_iter"]) != meta["n_iter"]:
        # Interrupted between the two atomic renames: the files are from two generations.
        raise ConfigurationError(
            f"{folder}: checkpoint.npz (generation {int(arrays['n_iter']) - 1}) and "
            f"checkpoint.json (generation {meta['n_iter'] - 1}) disagree; cannot resume exactly"
        )
    return meta, arrays


def optimise(
    problem: Any,
    algorithm: Any,
    n_gen: int,
    seed: int,
    *,
    checkpoint: str | Path | None = None,
    resume: bool = False,
    fingerprint: dict[str, Any] | None = None,
    progress: Callable[[GenerationInfo], None] | None = None,
) -> RunState:
    """Run ``algorithm`` on ``problem`` for ``n_gen`` generations with ``seed``.

    Parameters
    ----------
    checkpoint:
        Folder for per-generation checkpoints (none if ``None``).
    resume:
        Continue from the checkpoint in ``checkpoint``; its ``fingerprint`` (problem and
        algorithm settings) must equal this run's, else :class:`ConfigurationError`.
    fingerprint:
        JSON-ready description of the run, stored in and compared with the checkpoint.
    progress:
        Called after every generation with a :class:`GenerationInfo`.
    """
    folder = Path(checkpoint) if checkpoint is not None else None
    fingerprint = fingerprint or {}
    algorithm.setup(problem, seed=seed, termination=("n_gen", n_gen), verbose=False)
    spent_total = spent_eval = 0.0
    history: list[dict[str, Any]] = []
    if resume:
        if folder is None:
            raise ConfigurationError("resume needs a checkpoint folder")
        meta, arrays = load_checkpoint(folder)
        if meta.get("fingerprint") != json.loads(json.dumps(fingerprint)):
            raise ConfigurationError(
                f"{folder}: the checkpoint belongs to another run (problem, algorithm, seed "
                "or budget differ); start a new run or pass the same settings"
            )
        algorithm._initialize()
        algorithm.pop = _restore_population(arrays)
        algorithm.is_initialized = True
        algorithm.n_iter = meta["n_iter"]
        algorithm.evaluator.n_eval = meta["n_eval"]
        algorithm.random_state.bit_generator.state = meta["rng"]
        algorithm._set_optimum()
        spent_total, spent_eval = meta["total_s"], meta["evaluation_s"]
        history = meta["history"]
    start = time.perf_counter() - spent_total
    evaluation_s = spent_eval
    fronts: list[np.ndarray] = []
    try:
        while algorithm.has_next():
            infills = algorithm.ask()
            if infills is not None:
                t0 = time.perf_counter()
                algorithm.evaluator.eval(problem, infills, algorithm=algorithm)
                evaluation_s += time.perf_counter() - t0
            algorithm.tell(infills=infills)
            pop = algorithm.pop
            cv = pop.get("CV")[:, 0]
            feasible = cv <= 0.0
            best_t = float(pop.get("X")[feasible, 0].min()) if feasible.any() else None
            if feasible.any():
                F = pop.get("F")[feasible]
                fronts.append(F[non_dominated(F, maximised=False)])
            else:
                fronts.append(np.empty((0, pop.get("F").shape[1])))
            info = GenerationInfo(
                generation=len(history) + 1,
                n_gen=n_gen,
                n_evaluations=int(algorithm.evaluator.n_eval),
                n_feasible=int(feasible.sum()),
                best_time=best_t,
                elapsed_s=time.perf_counter() - start,
            )
            history.append(
                {
                    "generation": info.generation,
                    "n_evaluations": info.n_evaluations,
                    "n_feasible": info.n_feasible,
                    "best_time": best_t,
                }
            )
            if folder is not None:
                meta = {
                    "fingerprint": fingerprint,
                    "total_s": time.perf_counter() - start,
                    "evaluation_s": evaluation_s,
                    "history": history,
                }
                _save_checkpoint(folder, algorithm, meta)
            if progress is not None:
                progress(info)
    except KeyboardInterrupt:
        where = f"; resume from {folder}" if folder is not None else " (no checkpoint folder)"
        raise PlanningInterrupted(
            f"interrupted after generation {len(history)}{where}", folder
        ) from None
    pop = algorithm.pop
    return RunState(
        X=pop.get("X"),
        F=pop.get("F"),
        G=pop.get("G"),
        CV=pop.get("CV")[:, 0],
        n_generations=len(history),
        n_evaluations=int(algorithm.evaluator.n_eval),
        total_s=time.perf_counter() - start,
        evaluation_s=evaluation_s,
        history=history,
        fronts=fronts,
    )
