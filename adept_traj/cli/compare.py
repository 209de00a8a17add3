"""``adept-traj compare``: NSGA-II and MODE on the same problem and seed, with the paper's
Tables 3–5 beside ours in ``DIR/comparison.md``.

``--seeds 1-20`` runs both algorithms for every seed instead, each run a Dask task
(:func:`~adept_traj.cycle.run_seed_study`; ``--workers`` local worker processes, or
``--scheduler ADDRESS``; ``--resume`` keeps the runs already saved), and writes the median,
interquartile range and rank-sum test of every metric to ``DIR/study.md`` and
``DIR/study.json``, with box plots in ``DIR/figures/study_boxplots.png``.

``--out DIR`` is held by one ``adept-traj`` process at a time (a second one on it is
refused), and a folder holding the files of an earlier ``compare`` (``comparison.md``, the
runs in ``nsga2/`` and ``mode/``, their figures) is refused unless ``--overwrite`` is given,
which removes those files (and only those) first; a seed study's folder must be empty
unless ``--resume`` keeps its saved runs.

F_avg, f_c and HV are computed on common bounds: the extremes over both feasible fronts
and both best trade-offs.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from adept_traj.analysis import (
    average_fitness,
    combined_objective,
    normalised_hypervolume,
    objective_bounds,
)
from adept_traj.cli import status
from adept_traj.cli._run_folder import (
    FIGURES,
    as_path,
    folder_lock,
    remove_written,
    written_files,
)
from adept_traj.cli.arguments import add_problem_arguments, problem_from_arguments
from adept_traj.cli.limits import check_run_options
from adept_traj.cli.progress import ProgressReporter
from adept_traj.cli.report import figures_line, finisher_for, save_figures, summary
from adept_traj.cli.robot_options import source_from_arguments
from adept_traj.cycle import (
    parse_seeds,
    run_metrics,
    run_seed_study,
    study_statistics,
    write_study_report,
)
from adept_traj.errors import ConfigurationError, InvalidInputError
from adept_traj.optimise import PlanningInterrupted, plan
from adept_traj.results import PlanningResult, Replay

__all__ = ["add_parser", "comparison_markdown", "run"]


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``compare`` and its options."""
    p = sub.add_parser("compare", help="NSGA-II vs MODE: the paper's Tables 3-5")
    add_problem_arguments(p)
    p.add_argument("--gens", type=int, help="generations of both (default 100)")
    p.add_argument("--pop-nsga2", type=int, help="NSGA-II population (default 100)")
    p.add_argument("--pop-mode", type=int, help="MODE population (default 500)")
    p.add_argument("--out", type=str, required=True, help="output folder")
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the files of an earlier compare in --out (only the files compare writes)",
    )
    p.add_argument("--no-plots", action="store_true", help="do not write figures/*.png")
    p.add_argument(
        "--seeds",
        help="seed study: '1-20' or '1,5,9'; each run a Dask task (--workers: worker processes)",
    )
    p.add_argument("--scheduler", help="with --seeds: address of a running Dask scheduler")
    p.add_argument("--resume", action="store_true", help="with --seeds: keep the saved runs")
    return p


#: The comparison table ``compare`` writes at the top of ``--out``.
COMPARISON_FILE = "comparison.md"
#: The run folders ``compare`` writes in ``--out``, one per algorithm.
_RUN_FOLDERS = ("nsga2", "mode")


def compare_files(folder: Path) -> list[Path]:
    """The files of ``folder`` that a ``compare`` (without ``--seeds``) writes and that
    exist, sorted: :data:`COMPARISON_FILE`, each run folder's files
    (:func:`~adept_traj.cli._run_folder.written_files`) and the figures in
    ``figures/``."""
    found = [folder / COMPARISON_FILE] if (folder / COMPARISON_FILE).exists() else []
    for name in _RUN_FOLDERS:
        found += written_files(folder / name)
    found += [p for p in written_files(folder) if p.parent == folder / FIGURES]
    return sorted(found)


def _check_out(folder: Path, overwrite: bool) -> None:
    """Refuse ``folder`` before any work if it holds an earlier compare's files and
    ``overwrite`` is false (:class:`~adept_traj.errors.ConfigurationError`; a file in its
    place: :class:`~adept_traj.errors.InvalidInputError`, as ``plan`` says it)."""
    if folder.exists() and not folder.is_dir():
        raise InvalidInputError(f"--out {folder} is a file, not a folder")
    found = compare_files(folder)
    if found and not overwrite:
        names = ", ".join(str(p.relative_to(folder)) for p in found)
        raise ConfigurationError(
            f"--out {folder} holds files of an earlier compare ({names}); --overwrite "
            "replaces them, or choose another folder"
        )


def _remove_earlier(folder: Path) -> None:
    """Remove an earlier compare's files from ``folder`` (only those: see
    :func:`compare_files`)."""
    (folder / COMPARISON_FILE).unlink(missing_ok=True)
    for name in _RUN_FOLDERS:
        remove_written(folder / name)
    for path in compare_files(folder):  # what is left: the figures
        path.unlink()


#: The paper's Tables 3–5, as printed (strings keep their printed digits).
_PAPER_TABLES = {
    "nsga2": {
        "z": ("0.898", "9178597.575731", "0.0", "0.048277", "163.237956", "156.112759"),
        "F_avg": "0.683650",
        "f_c": "0.497040",
        "T_run": "2",
        "N_eval": "87",
        "AE": "0.02299",
        "SSM": "0.01023",
        "RNI": "0.32",
        "OO": "0.0769",
    },
    "mode": {
        "z": ("0.848", "9468839.987070", "0.0", "0.157367", "119.843157", "107.837977"),
        "F_avg": "0.852519",
        "f_c": "0.467136",
        "T_run": "2",
        "N_eval": "124",
        "AE": "0.01575",
        "SSM": "0.02356",
        "RNI": "0.24",
        "OO": "0.0324",
    },
}


def _fmt(value: Any) -> str:
    if value is None:
        return "–"
    if isinstance(value, str):
        return value
    if isinstance(value, int | np.integer):
        return str(value)
    return f"{value:.6g}"


def comparison_markdown(results: dict[str, PlanningResult], weights: Sequence[float]) -> str:
    """The text of ``DIR/comparison.md``: the paper's Tables 3–5 beside ``results`` (keyed
    ``"nsga2"`` and ``"mode"``), f_c with ``weights`` (6,), all on common bounds."""
    fronts = [r.feasible_front.objectives for r in results.values() if r.feasible_front.x.size]
    bests = np.array([r.best_objectives for r in results.values()])
    pool = np.vstack([*fronts, bests]) if fronts else bests
    lo, hi = objective_bounds(pool)
    f_avg = average_fitness(bests, lo, hi)
    f_c = combined_objective(bests, weights, lo, hi)
    out = [
        "# NSGA-II vs MODE on the paper scenario",
        "",
        "Paper values as printed (its Tables 3–5; Table 4 is garbled, see docs) beside ours.",
        "Our F_avg, f_c and HV use common bounds: the extremes over both feasible fronts.",
        "",
        "## Table 3 — best trade-offs",
        "",
        "| | z1 [s] | z2 | z3 | z4 [m²] | z5 | z6 | F_avg |",
        "|---|---|---|---|---|---|---|---|",
        "| Z_max (ours) | " + " | ".join(_fmt(v) for v in hi) + " | – |",
        "| Z_min (ours) | " + " | ".join(_fmt(v) for v in lo) + " | – |",
    ]
    for k, (name, result) in enumerate(results.items()):
        paper = _PAPER_TABLES[name]
        out.append(
            f"| {name} (paper) | " + " | ".join(_fmt(v) for v in paper["z"])
            + f" | {_fmt(paper['F_avg'])} |"
        )  # fmt: skip
        out.append(
            f"| {name} (ours) | " + " | ".join(_fmt(v) for v in result.best_objectives)
            + f" | {_fmt(float(f_avg[k]))} |"
        )  # fmt: skip
    out += [
        "",
        "## Table 4 — combined objective and algorithm effort",
        "",
        "| | f_c | T_run [s] | N_eval | AE [s] |",
        "|---|---|---|---|---|",
    ]
    for k, (name, result) in enumerate(results.items()):
        paper = _PAPER_TABLES[name]
        out.append(
            f"| {name} (paper) | {_fmt(paper['f_c'])} | {paper['T_run']} | {paper['N_eval']}"
            f" | {_fmt(paper['AE'])} |"
        )
        out.append(
            f"| {name} (ours) | {_fmt(float(f_c[k]))} | {_fmt(result.timing.total_s)} | "
            f"{result.timing.n_evaluations} | {_fmt(result.metrics.ae)} |"
        )
    out += [
        "",
        "## Table 5 — front quality",
        "",
        "| | SSM | RNI | OO | HV |",
        "|---|---|---|---|---|",
    ]
    for name, result in results.items():
        paper = _PAPER_TABLES[name]
        front = result.feasible_front.objectives
        hv = normalised_hypervolume(front, lo, hi) if front.size else None
        out.append(
            f"| {name} (paper) | {_fmt(paper['SSM'])} | {_fmt(paper['RNI'])} | "
            f"{_fmt(paper['OO'])} | – |"
        )
        m = result.metrics
        out.append(f"| {name} (ours) | {_fmt(m.ssm)} | {_fmt(m.rni)} | {_fmt(m.oo)} | {_fmt(hv)} |")
    out += ["", "Verified (1 kHz certificate) best trade-offs:", ""]
    for name, result in results.items():
        out.append(
            f"- {name}: {'feasible' if result.feasible else 'NOT feasible'}, "
            f"T = {result.best_objectives[0]:.3f} s, gap to the kinematic lower bound "
            f"{result.gap:.2f}×"
        )
    return "\n".join(out) + "\n"


def _run_study(args: argparse.Namespace) -> int:
    """``compare --seeds``: the seed study on Dask and its report."""
    seeds = parse_seeds(args.seeds)
    if args.overwrite:
        raise ConfigurationError(
            "--overwrite does not go with --seeds: a seed study needs an empty --out, or "
            "--resume to keep its saved runs"
        )
    problem = problem_from_arguments(args)
    problem.close()
    for name, pop in (("nsga2", args.pop_nsga2), ("mode", args.pop_mode)):
        check_run_options(problem, name, pop, args.gens, args.rate, pop_option=f"--pop-{name}")
    with folder_lock(args.out):  # no second process writing into the folder meanwhile
        return _study(args, problem, seeds)


def _study(args: argparse.Namespace, problem: Any, seeds: list[int]) -> int:
    """The seed study of :func:`_run_study`, with ``--out`` held."""
    with tqdm(
        total=2 * len(seeds), desc="runs", unit="run", disable=args.quiet, file=sys.stderr
    ) as bar:
        runs = run_seed_study(
            problem.scene,
            problem.start,
            problem.goal,
            seeds,
            args.out,
            populations={"nsga2": args.pop_nsga2, "mode": args.pop_mode},
            n_gen=args.gens,
            weights=args.weights,
            rate_hz=args.rate,
            robot=source_from_arguments(args, args.scene),
            workers=args.workers,
            scheduler=args.scheduler,
            resume=args.resume,
            progress=lambda name: bar.update(1),
        )
    metrics = run_metrics(runs, args.weights)
    rows = study_statistics(metrics)
    print(write_study_report(rows, metrics, seeds, args.out, figure=not args.no_plots))
    return status.OK


def run(args: argparse.Namespace) -> int:
    """Run ``compare``; return the exit status (0, or 130 when interrupted)."""
    args = argparse.Namespace(**{**vars(args), "out": as_path(args.out, "--out")})
    if args.seeds is not None:
        return _run_study(args)
    if args.scheduler is not None or args.resume:
        raise ConfigurationError("--scheduler and --resume need --seeds")
    _check_out(args.out, args.overwrite)
    problem = problem_from_arguments(args)
    runs = (("nsga2", args.pop_nsga2), ("mode", args.pop_mode))
    results = {}
    with contextlib.ExitStack() as stack:
        try:
            for name, pop in runs:  # both refused before either starts
                check_run_options(
                    problem, name, pop, args.gens, args.rate, pop_option=f"--pop-{name}"
                )
            stack.enter_context(folder_lock(args.out))  # one process writes into it
            _check_out(args.out, args.overwrite)  # again, now that no other one can write
            _remove_earlier(args.out)  # only with --overwrite: refused above otherwise
            # the figures' helper imports matplotlib while the runs go on (at nice 19)
            finisher = stack.enter_context(
                finisher_for(problem.robot, problem.scene, figures=not args.no_plots, html=False)
            )
            _plan_both(args, problem, runs, results)
        except PlanningInterrupted as exc:  # no checkpoint: the finished runs are saved
            print(f"{exc}", file=sys.stderr)
            return status.INTERRUPTED
        finally:
            problem.close()
        if not args.no_plots:
            figures = args.out / "figures"
            if finisher is not None and finisher.start(results, figures=figures):
                print(figures_line(finisher.wait(), figures, results))
            else:
                replays = {
                    name: Replay.of(r, robot=problem.robot, scene=problem.scene)
                    for name, r in results.items()
                }
                save_figures(results, figures, replays)
    text = comparison_markdown(results, args.weights)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "comparison.md").write_text(text)
    print(text)
    return status.OK


def _plan_both(args: argparse.Namespace, problem: Any, runs: tuple, results: dict) -> None:
    """Run NSGA-II and MODE in turn into ``results``, each saved and summarised."""
    for name, pop in runs:
        with ProgressReporter(name, quiet=args.quiet) as progress:
            results[name] = plan(
                problem,
                name,
                seed=args.seed,
                pop_size=pop,
                n_gen=args.gens,
                weights=args.weights,
                progress=progress,
                rate_hz=args.rate,
            )
        results[name].save(args.out / name)
        print(summary(results[name], args.out / name))
