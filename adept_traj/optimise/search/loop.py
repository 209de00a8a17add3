"""The generation loop: ask/tell with timings, progress, checkpoints and exact resume.

:func:`optimise` runs a pymoo algorithm on a problem generation by generation, through
pymoo's public ask/tell interface only. It can keep a checkpoint folder
(:mod:`adept_traj.optimise.search.checkpoint`: ``checkpoint.npz``, no pickle): the population with
every per-individual attribute the algorithm keeps (F, G, CV, rank, crowding, …), the
generation and evaluation counters, the state of the algorithm's random generator, the
feasible front of every generation so far and the timings. The checkpoint of every
finished generation is made in memory; it is written (and flushed to disk) at most every
``checkpoint_interval`` seconds, after the last generation, and on Ctrl-C — a write per
generation cost more than the bookkeeping of pymoo's survival on fast disks, and tens of
milliseconds each on slow ones. :func:`optimise` with ``resume=True`` restores all of it,
so an interrupted run continues **exactly** as an uninterrupted one with the same seed
(tested, killed at every generation): a run killed outright resumes from the last
checkpoint written and computes the generations after it again, the same ones. Ctrl-C
(``KeyboardInterrupt``) during a generation writes the last finished generation and raises
:class:`PlanningInterrupted` (whose ``checkpoint`` is ``None`` if no generation was
finished yet).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.analysis.indicators import non_dominated
from adept_traj.errors import CheckpointFormatError, ConfigurationError, PlanningInterrupted
from adept_traj.optimise.operators.population import (
    ArrayEvaluator,
    cache_violations,
    population_values,
)
from adept_traj.optimise.search.checkpoint import (
    CHECKPOINT_FILE,
    CapturedCheckpoint,
    capture_checkpoint,
    load_checkpoint,
    restore_algorithm,
    write_checkpoint,
)
from adept_traj.optimise.search.run_records import GenerationInfo, RunState
from adept_traj.validation import as_scalar

__all__ = ["CHECKPOINT_INTERVAL", "optimise"]

#: Shortest wall time [s] between two checkpoint writes (each one flushed to disk).
CHECKPOINT_INTERVAL = 1.0


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
    checkpoint_interval: float = CHECKPOINT_INTERVAL,
) -> RunState:
    """Run ``algorithm`` on ``problem`` for ``n_gen`` generations with ``seed``.

    Parameters
    ----------
    problem:
        A pymoo problem (e.g. :class:`~adept_traj.problem.TrajectoryProblem`).
    algorithm:
        A pymoo algorithm, not yet set up (e.g. from
        :func:`~adept_traj.optimise.make_algorithm`); it is set up here.
    n_gen:
        Generations in total (a resumed run counts the checkpointed ones).
    seed:
        Seed of the algorithm's random generator.
    checkpoint:
        Folder for per-generation checkpoints (none if ``None``).
    resume:
        Continue from the checkpoint in ``checkpoint``; its ``fingerprint`` (problem and
        algorithm settings) must equal this run's, else :class:`ConfigurationError`.
    fingerprint:
        JSON-ready description of the run, stored in and compared with the checkpoint.
    progress:
        Called after every generation with a :class:`GenerationInfo`.
    checkpoint_interval:
        Shortest wall time [s] between two checkpoint writes, ≥ 0 (default
        :data:`CHECKPOINT_INTERVAL`; 0 writes every generation). The last generation is
        always written, and on Ctrl-C the last finished one (kept in memory after every
        generation). A run killed outright resumes from an earlier generation and computes
        the same later ones again: the same result, at most this much work lost.

    Returns
    -------
    RunState
        The final population and the timings.

    Raises
    ------
    ConfigurationError
        ``resume`` without a usable checkpoint, or a checkpoint of another run.
    PlanningInterrupted
        On Ctrl-C; the last finished generation is in ``checkpoint`` (if given; its
        ``checkpoint`` attribute is ``None`` when nothing was checkpointed yet).
    """
    folder = Path(checkpoint) if checkpoint is not None else None
    fingerprint = fingerprint or {}
    interval = as_scalar(
        checkpoint_interval, "checkpoint_interval", "[s]", minimum=0.0, error=ConfigurationError
    )
    algorithm.setup(problem, seed=seed, termination=("n_gen", n_gen), verbose=False)
    spent_total = spent_eval = 0.0
    history: list[dict[str, Any]] = []
    fronts: list[np.ndarray] = []
    if resume:
        if folder is None:
            raise ConfigurationError("resume needs a checkpoint folder")
        meta, arrays = load_checkpoint(folder)
        if meta.get("fingerprint") != json.loads(json.dumps(fingerprint)):
            raise ConfigurationError(
                f"{folder}: the checkpoint belongs to another run (problem, algorithm, seed "
                "or budget differ); start a new run or pass the same settings"
            )
        file = folder / CHECKPOINT_FILE
        fronts = _restored_fronts(arrays, meta, problem.n_obj, file)  # checked first
        restore_algorithm(algorithm, meta, arrays, file)
        spent_total, spent_eval = meta["total_s"], meta["evaluation_s"]
        history = meta["history"]
    start = time.perf_counter() - spent_total
    evaluation_s = spent_eval
    # The checkpoint of the last finished generation not yet on disk (captured, with its
    # loop metadata and number of fronts), and when one was last written.
    unwritten: tuple[CapturedCheckpoint, dict[str, Any], int] | None = None
    written_at = time.perf_counter()
    try:
        while algorithm.has_next():
            infills = algorithm.ask()
            if infills is not None:
                t0 = time.perf_counter()
                algorithm.evaluator.eval(problem, infills, algorithm=algorithm)
                evaluation_s += time.perf_counter() - t0
                if not isinstance(algorithm.evaluator, ArrayEvaluator):  # (it sets them)
                    cache_violations(infills)  # what the survival reads, at once
            algorithm.tell(infills=infills)
            # one pass over the members: CV, travel time T and objectives
            members = [(ind.CV[0], ind.X[0], ind.F) for ind in algorithm.pop]
            feasible = np.array([m[0] for m in members]) <= 0.0
            T = np.array([m[1] for m in members])
            best_t = float(T[feasible].min()) if feasible.any() else None
            F = np.array([m[2] for m in members])[feasible]
            fronts.append(F[non_dominated(F, maximised=False)] if len(F) else F)
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
                    "history": list(history),
                }
                unwritten = (capture_checkpoint(algorithm), meta, len(fronts))
                if time.perf_counter() - written_at >= interval or not algorithm.has_next():
                    _write(folder, unwritten, fronts)
                    unwritten, written_at = None, time.perf_counter()
            if progress is not None:
                progress(info)
    except KeyboardInterrupt:
        if folder is not None and unwritten is not None:
            _write(folder, unwritten, fronts)  # the last finished generation
        if folder is None:
            where, saved = " (no checkpoint folder)", None
        elif not history:
            where, saved = " (no generation finished: nothing checkpointed)", None
        else:
            where, saved = f"; resume from {folder}", folder
        raise PlanningInterrupted(
            f"interrupted after generation {len(history)}{where}", saved
        ) from None
    pop = algorithm.pop
    return RunState(
        X=population_values(pop, "X"),
        F=population_values(pop, "F"),
        G=population_values(pop, "G"),
        CV=population_values(pop, "CV")[:, 0],
        n_generations=len(history),
        n_evaluations=int(algorithm.evaluator.n_eval),
        total_s=time.perf_counter() - start,
        evaluation_s=evaluation_s,
        history=history,
        fronts=fronts,
    )


def _write(
    folder: Path,
    unwritten: tuple[CapturedCheckpoint, dict[str, Any], int],
    fronts: list[np.ndarray],
) -> None:
    """Write a captured checkpoint with its loop metadata and its generations' fronts (the
    first ``unwritten[2]`` of ``fronts``)."""
    captured, meta, n_fronts = unwritten
    write_checkpoint(folder, captured.arrays(meta, _stored_fronts(fronts[:n_fronts])))


def _stored_fronts(fronts: list[np.ndarray]) -> dict[str, np.ndarray]:
    """The fronts of every generation as two arrays for the checkpoint: ``fronts`` (the rows
    of all fronts, (k, n_obj)) and ``front_sizes`` (n_gen,)."""
    return {"fronts": np.concatenate(fronts), "front_sizes": np.array([len(F) for F in fronts])}


def _restored_fronts(
    arrays: dict[str, np.ndarray], meta: dict[str, Any], n_obj: int, file: Path
) -> list[np.ndarray]:
    """The per-generation fronts of a checkpoint (``file``): of its last generations (all
    of them, or none for a version-1 checkpoint, or those after a version-1 checkpoint was
    resumed). ``loop.fronts`` must be float64 (k, n_obj), ``loop.front_sizes`` integers
    (at most one per generation) summing to k; a version-2 checkpoint has both."""
    have = [key in arrays for key in ("loop.fronts", "loop.front_sizes")]
    if not any(have) and meta["version"] == 1:
        return []
    if not all(have):
        name = "loop.front_sizes" if have[0] else "loop.fronts"
        raise CheckpointFormatError(file, name, "missing")
    rows, sizes = arrays["loop.fronts"], arrays["loop.front_sizes"]
    if rows.dtype != np.float64 or rows.ndim != 2 or rows.shape[1] != n_obj:
        raise CheckpointFormatError(
            file,
            "loop.fronts",
            f"dtype {rows.dtype.str}, shape {rows.shape} where float64 (k, {n_obj}) is stored",
        )
    n_generations = len(meta["history"])
    if (
        sizes.dtype.kind not in "iu"
        or sizes.ndim != 1
        or len(sizes) > n_generations
        or (sizes < 0).any()
        or sizes.sum() != len(rows)
    ):
        raise CheckpointFormatError(
            file,
            "loop.front_sizes",
            f"dtype {sizes.dtype.str}, shape {sizes.shape} where the sizes of at most "
            f"{n_generations} fronts (integers ≥ 0, their sum the {len(rows)} rows of "
            "loop.fronts) are stored",
        )
    return np.split(rows, np.cumsum(sizes)[:-1]) if len(sizes) else []
