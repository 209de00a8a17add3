r"""Seed studies: NSGA-II against MODE over many seeds, each run a Dask task.

The paper drew its conclusions (Tables 3–5) from one run of each algorithm.
:func:`run_seed_study` plans the same problem with both algorithms for every seed (each
run a task of :func:`~adept_traj.cycle.run_planning_tasks`, saved at once in
``out/runs/ALGORITHM-seedN/``); :func:`study_statistics` gives, per metric, the median and
the interquartile range of each algorithm and the two-sided Mann–Whitney U (rank-sum) test
of NSGA-II against MODE (``scipy.stats.mannwhitneyu``), and says whether the paper's
single-run ordering holds: *confirmed* when the better median is the paper's winner and
:math:`p < 0.05`, *contradicted* when it is the other algorithm and :math:`p < 0.05`,
*not significant* otherwise.

F_avg, f_c and HV of every run use common bounds: the extremes over the feasible fronts
and the best trade-offs of all runs of the study (as ``adept-traj compare`` does for two).
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.analysis import (
    PAPER_WEIGHTS,
    average_fitness,
    combined_objective,
    normalised_hypervolume,
    objective_bounds,
)
from adept_traj.cycle.cycle_file import MoveSpec
from adept_traj.cycle.move_task import MoveTask
from adept_traj.cycle.runner import run_planning_tasks
from adept_traj.cycle.summary import fastest_certified
from adept_traj.errors import ConfigurationError
from adept_traj.problem import OBJECTIVES
from adept_traj.results import PlanningResult
from adept_traj.robot import RobotSource
from adept_traj.scene import Scene
from adept_traj.validation import as_vector

__all__ = [
    "ALGORITHM_PAIR",
    "METRICS",
    "RUNS_FOLDER",
    "Metric",
    "parse_seeds",
    "run_metrics",
    "run_seed_study",
    "study_statistics",
]

#: The two algorithms compared (the paper's), in table order.
ALGORITHM_PAIR = ("nsga2", "mode")
#: Sub-folder of a study's output folder with one result folder per run.
RUNS_FOLDER = "runs"
#: Significance level of the rank-sum test.
ALPHA = 0.05
#: Most seeds of one study.
MAX_SEEDS = 10_000


@dataclass(frozen=True)
class Metric:
    """One metric of the study: its key, label, whether lower is better (``None``: not a
    quality, e.g. the evaluations a budget allows: no algorithm is called better), and the
    paper's single-run winner (``None`` when the paper prints no comparable value)."""

    key: str
    label: str
    lower_is_better: bool | None
    paper_winner: str | None


#: Tables 3–5 of the paper (best trade-off z1…z6, F_avg; f_c, T_run, N_eval, AE; SSM, RNI,
#: OO) plus HV and the fastest certified T. Paper winners read from its printed values.
METRICS = (
    *(
        Metric(o.name, f"{o.name} {o.quantity} [{o.unit}]", not o.maximised, winner)
        for o, winner in zip(OBJECTIVES, ("mode", "nsga2", None, "mode", "mode", "mode"))
    ),
    Metric("F_avg", "F_avg", False, "mode"),
    Metric("f_c", "f_c", True, "mode"),
    Metric("T_run", "T_run [s]", True, None),
    Metric("N_eval", "N_eval", None, None),
    Metric("AE", "AE [s]", True, "mode"),
    Metric("SSM", "SSM", True, "nsga2"),
    Metric("RNI", "RNI", False, "nsga2"),
    Metric("OO", "OO", True, "mode"),
    Metric("HV", "HV (common bounds)", False, None),
    Metric("fastest_T", "fastest certified T [s]", True, None),
)


def parse_seeds(text: str) -> tuple[int, ...]:
    """Seeds from ``"1-20"``, ``"1,5,9"`` or a mix (``"1-3,10"``); distinct, in order,
    each in [0, 2³²−1], at most :data:`MAX_SEEDS`; ConfigurationError otherwise."""
    seeds: list[int] = []
    for part in str(text).split(","):
        m = re.fullmatch(r"\s*(\d+)\s*(?:-\s*(\d+)\s*)?", part)
        if m is None or (m[2] is not None and int(m[2]) < int(m[1])):
            raise ConfigurationError(
                f"--seeds must be like '1-20' or '1,5,9' (integers ≥ 0, ranges low-high); "
                f"got {text!r}"
            )
        low, high = int(m[1]), int(m[2] if m[2] is not None else m[1])
        if high > 2**32 - 1 or high - low + 1 + len(seeds) > MAX_SEEDS:
            raise ConfigurationError(
                f"--seeds must hold at most {MAX_SEEDS} seeds in [0, 2^32 - 1]; got {text!r}"
            )
        seeds.extend(range(low, high + 1))
    if len(set(seeds)) != len(seeds):
        raise ConfigurationError(f"--seeds must not repeat a seed; got {text!r}")
    return tuple(seeds)


def run_seed_study(
    scene: Scene,
    start: object,
    goal: object,
    seeds: Sequence[int],
    out: str | os.PathLike[str],
    *,
    populations: dict[str, int | None] | None = None,
    n_gen: int | None = None,
    weights: Sequence[float] = PAPER_WEIGHTS,
    rate_hz: float = 1000.0,
    robot: RobotSource | None = None,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
) -> dict[str, list[PlanningResult]]:
    """Both algorithms of :data:`ALGORITHM_PAIR` over ``seeds`` on Dask.

    Parameters
    ----------
    scene, start, goal: the problem (``start``/``goal`` (nq,) [rad | m]).
    seeds: the seeds (e.g. :func:`parse_seeds`).
    out: output folder (``out/runs/ALGORITHM-seedN/``).
    populations: population per algorithm (``None``: the paper's); n_gen: generations.
    weights: (6,) weights of f_c; rate_hz: certificate rate [Hz].
    robot: where workers load the robot (default: the shipped AdeptOne XL).
    workers, scheduler, resume, progress: as :func:`~adept_traj.cycle.run_cycle`.

    Returns
    -------
    ``{algorithm: [result per seed]}``.
    """
    w = tuple(float(v) for v in as_vector(weights, "weights", 6))
    pops = populations or {}
    tasks = [
        MoveTask(
            move=MoveSpec(
                index=k,
                name=f"{alg}-seed{seed}",
                start="start",
                goal="goal",
                algorithm=alg,
                seed=int(seed),
                pop_size=pops.get(alg),
                n_gen=n_gen,
                weights=w,
            ),
            start=as_vector(start, "start", len(np.atleast_1d(start))),
            goal=as_vector(goal, "goal", len(np.atleast_1d(goal))),
            robot=robot or RobotSource(),
            scene=scene,
            rate_hz=float(rate_hz),
        )
        for k, (alg, seed) in enumerate((a, s) for a in ALGORITHM_PAIR for s in seeds)
    ]
    results = run_planning_tasks(
        tasks,
        Path(out) / RUNS_FOLDER,
        workers=workers,
        scheduler=scheduler,
        resume=resume,
        progress=progress,
    )
    n = len(seeds)
    return {alg: results[i * n : (i + 1) * n] for i, alg in enumerate(ALGORITHM_PAIR)}


def run_metrics(
    runs: dict[str, list[PlanningResult]], weights: Sequence[float] = PAPER_WEIGHTS
) -> dict[str, dict[str, list[float | None]]]:
    """``{algorithm: {metric key: value per run}}`` (:data:`METRICS`; ``None`` where a run
    has no value, e.g. HV without a feasible member), on the study's common bounds."""
    every = [r for rs in runs.values() for r in rs]
    fronts = [r.feasible_front.objectives for r in every if r.feasible_front.x.size]
    bests = np.array([r.best_objectives for r in every])
    lo, hi = objective_bounds(np.vstack([*fronts, bests]))
    out: dict[str, dict[str, list[float | None]]] = {}
    for alg, rs in runs.items():
        b = np.array([r.best_objectives for r in rs])
        f_avg = average_fitness(b, lo, hi)
        f_c = combined_objective(b, weights, lo, hi)
        values: dict[str, list[float | None]] = {f"z{j + 1}": list(b[:, j]) for j in range(6)}
        values["F_avg"], values["f_c"] = list(f_avg), list(f_c)
        values["T_run"] = [r.timing.total_s for r in rs]
        values["N_eval"] = [float(r.timing.n_evaluations) for r in rs]
        values["AE"] = [r.metrics.ae for r in rs]
        values["SSM"] = [r.metrics.ssm for r in rs]
        values["RNI"] = [r.metrics.rni for r in rs]
        values["OO"] = [r.metrics.oo for r in rs]
        values["HV"] = [
            normalised_hypervolume(r.feasible_front.objectives, lo, hi)
            if r.feasible_front.x.size
            else None
            for r in rs
        ]
        values["fastest_T"] = [fastest_certified(r) for r in rs]
        out[alg] = {k: [None if v is None else float(v) for v in vs] for k, vs in values.items()}
    return out


def _quartiles(values: list[float | None]) -> dict[str, Any]:
    x = np.array([v for v in values if v is not None], dtype=float)
    if not x.size:
        return {"n": 0, "median": None, "q25": None, "q75": None, "iqr": None}
    q25, med, q75 = np.percentile(x, [25, 50, 75])
    return {"n": int(x.size), "median": med, "q25": q25, "q75": q75, "iqr": q75 - q25}


def study_statistics(metrics: dict[str, dict[str, list[float | None]]]) -> list[dict[str, Any]]:
    """Per metric of :data:`METRICS`: median, quartiles and IQR of each algorithm, the
    two-sided Mann–Whitney U test (``U``, ``p``; ``None`` with fewer than one value per
    algorithm), the better algorithm by median and the verdict on the paper's ordering."""
    from scipy.stats import mannwhitneyu

    a, b = ALGORITHM_PAIR
    rows = []
    for m in METRICS:
        xa = [v for v in metrics[a][m.key] if v is not None]
        xb = [v for v in metrics[b][m.key] if v is not None]
        row: dict[str, Any] = {"metric": m.key, "label": m.label, "paper_winner": m.paper_winner}
        row[a], row[b] = _quartiles(metrics[a][m.key]), _quartiles(metrics[b][m.key])
        row["U"] = row["p"] = row["better"] = None
        if xa and xb:
            test = mannwhitneyu(xa, xb, alternative="two-sided")
            row["U"], row["p"] = float(test.statistic), float(test.pvalue)
            ma, mb = row[a]["median"], row[b]["median"]
            if ma != mb and m.lower_is_better is not None:
                row["better"] = a if (ma < mb) == m.lower_is_better else b
        row["verdict"] = _verdict(row, m)
        rows.append({k: _plain(v) for k, v in row.items()})
    return rows


def _verdict(row: dict[str, Any], metric: Metric) -> str:
    if metric.lower_is_better is None:
        return "not a quality measure"
    significant = row["p"] is not None and np.isfinite(row["p"]) and row["p"] < ALPHA
    if not significant or row["better"] is None:
        return "not significant"
    if metric.paper_winner is None:
        return f"{row['better']} better (paper: no comparison)"
    return "confirmed" if row["better"] == metric.paper_winner else "contradicted"


def _plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, np.generic):
        return value.item()
    return value
