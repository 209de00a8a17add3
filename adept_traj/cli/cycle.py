"""``adept-traj cycle FILE --out DIR``: plan every move of a cycle file on Dask.

Each move is a Dask task (:func:`~adept_traj.cycle.run_cycle`): by default on a local
cluster of ``--workers`` single-threaded worker processes (default: one per core) that the
command starts and stops; ``--scheduler ADDRESS`` uses a running cluster instead. Every
finished move is saved at once in ``DIR/moves/NAME/``; ``--resume`` keeps those already
saved for the same task. At the end ``DIR/cycle.json``, ``DIR/cycle.md`` and
``DIR/cycle_gantt.png`` (unless ``--no-plots``) report each move and the cycle time, and
``DIR/playback.html`` (unless ``--no-playback``) plays the whole cycle in a browser.
``DIR`` is held by one ``adept-traj`` process at a time: a second one on it (e.g. the same
``--resume`` started twice) is refused before it writes anything.

Exit status 0 when every move's reported solution is certified, 1 otherwise
(:data:`~adept_traj.cli.status.NOT_CERTIFIED`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

from tqdm import tqdm

from adept_traj.cli import status
from adept_traj.cli._run_folder import as_path, folder_lock
from adept_traj.cycle import (
    MAX_PHASES,
    PLAYBACK_FILE,
    chosen_member,
    cycle_html,
    plan_on_clock,
    plan_phase_grid,
    read_cycle_file,
    run_cycle,
    write_cycle_report,
)
from adept_traj.errors import CycleError
from adept_traj.validation import as_integer

__all__ = ["add_parser", "run"]


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``cycle`` and its options."""
    p = sub.add_parser("cycle", help="plan every move of a cycle file (TOML) on Dask")
    p.add_argument("file", type=Path, help="cycle file (docs/cycles.md)")
    p.add_argument("--out", type=str, required=True, help="output folder")
    p.add_argument("--workers", type=int, help="local worker processes (default: one per core)")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786)")
    p.add_argument("--resume", action="store_true", help="keep the moves already saved")
    p.add_argument("--no-plots", action="store_true", help="no cycle_gantt.png")
    p.add_argument("--no-playback", action="store_true", help="no playback.html")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.add_argument(
        "--phase-grid",
        type=int,
        metavar="N",
        help="periodic moving obstacles: plan every move at N start phases at once and "
        "choose the sequence of least pass time (dynamic programming; docs/cycles.md)",
    )
    p.add_argument(
        "--max-phases",
        type=int,
        metavar="M",
        help="with --phase-grid: where no schedule is certified, the grid is refined (2N, "
        f"4N, … phases) up to M phases (default {MAX_PHASES}; N: no refinement)",
    )
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``cycle``; return the exit status."""
    if args.workers is not None:
        as_integer(args.workers, "--workers", minimum=1, maximum=1024)
    if args.max_phases is not None and args.phase_grid is None:
        raise CycleError(f"--max-phases {args.max_phases}: it refines a --phase-grid N grid")
    out = as_path(args.out, "--out")
    cycle = read_cycle_file(args.file)  # every location solved before any task starts
    with folder_lock(out):  # no second process writing into the folder meanwhile
        return _run(args, cycle, out)


def _run(args: argparse.Namespace, cycle: Any, out: Path) -> int:
    """The moves of ``cycle`` and their report, with ``out`` held (:func:`run`)."""
    if cycle.scene.moving:
        return _run_on_clock(args, cycle, out)
    results = _with_bar(args, cycle, out, run_cycle)
    summary = write_cycle_report(cycle, results, out, figure=not args.no_plots)
    if not args.no_playback:
        names = [m.name for m in cycle.moves]
        robot, page = cycle.robot.load(), out / PLAYBACK_FILE
        rows = [chosen_member(r, m) for r, m in zip(results, cycle.moves)]
        cycle_html(
            results, names, page, robot=robot, scene=cycle.scene, title=cycle.name, members=rows
        )
    print((out / "cycle.md").read_text(encoding="utf-8"))
    return status.OK if summary["all_certified"] else status.NOT_CERTIFIED


def _with_bar(args: argparse.Namespace, cycle: Any, out: Path, planner: Any) -> Any:
    """``planner(cycle, out, …)`` with the command's Dask options and a progress bar of
    the moves (one step per move chosen)."""
    with tqdm(
        total=len(cycle.moves), desc="moves", unit="move", disable=args.quiet, file=sys.stderr
    ) as bar:
        return planner(
            cycle,
            out,
            workers=args.workers,
            scheduler=args.scheduler,
            resume=args.resume,
            progress=lambda name: bar.update(1),
        )


def _run_on_clock(args: argparse.Namespace, cycle: Any, out: Path) -> int:
    """A scene with moving obstacles: the moves planned in the order they run, each at its
    start time on the scene clock (:func:`~adept_traj.cycle.plan_on_clock`)."""
    if args.phase_grid is not None:
        with tqdm(desc="plans", unit="plan", disable=args.quiet, file=sys.stderr) as bar:

            def refining(m: int) -> None:
                if not args.quiet:
                    bar.write(f"phase grid: no certified schedule; refined to {m} phases",
                              file=sys.stderr)  # fmt: skip

            clock, passes, report = plan_phase_grid(
                cycle,
                out,
                phases=args.phase_grid,
                max_phases=args.max_phases,
                workers=args.workers,
                scheduler=args.scheduler,
                resume=args.resume,
                progress=lambda name: bar.update(1),
                refining=refining,
            )
        best, naive = report["optimised"], report["naive"]
        gain = "" if naive is None else f", gain {100 * (1 - best / naive):.1f} %"
        how = "every pass back to back" if clock.period is None else "periodic passes"
        sizes = report["grid_sizes"]
        refined = "" if len(sizes) == 1 else f", refined to {sizes[-1]}"
        print(
            f"phase grid of {args.phase_grid}{refined} ({sum(report['plans'])} plans): cycle time "
            f"{best:.3f} s ({how}), naive back-to-back {_seconds(naive)} s{gain}; periodic "
            f"{_seconds(report['periodic'])} s"
            f"{'' if report['periodic_certified'] else ' (not re-certified)'}, back to back "
            f"{_seconds(report['back_to_back'])} s"
            + ("" if report["back_to_back_note"] is None else f" ({report['back_to_back_note']})"),
            file=sys.stderr,
        )
        return _report_on_clock(args, cycle, out, clock, passes)
    clock, passes = _with_bar(args, cycle, out, plan_on_clock)
    if clock.choice:
        print(f"schedule: {clock.choice}", file=sys.stderr)
    return _report_on_clock(args, cycle, out, clock, passes)


def _seconds(value: float | None) -> str:
    return "–" if value is None else f"{value:.3f}"


def _report_on_clock(
    args: argparse.Namespace, cycle: Any, out: Path, clock: Any, passes: Any
) -> int:
    """The report, the playback and the exit status of a cycle on the scene clock."""
    summary = write_cycle_report(cycle, passes[0], out, figure=not args.no_plots, clock=clock)
    if not args.no_playback:
        robot, page = cycle.robot.load(), out / PLAYBACK_FILE
        names = [m.name for m in cycle.moves]
        cycle_html(
            passes[0],
            names,
            page,
            robot=robot,
            scene=cycle.scene,
            title=cycle.name,
            clock=clock,
            passes=passes,
        )
    print((out / "cycle.md").read_text(encoding="utf-8"))
    return status.OK if summary["all_certified"] else status.NOT_CERTIFIED
