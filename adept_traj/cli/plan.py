"""``adept-traj plan``: plan on a scene, verify the best trade-off densely, save the result.

While running, ``DIR/checkpoint/`` holds the last finished generation and ``DIR/run.json``
the arguments; Ctrl-C stops the run (exit 130) and ``--resume DIR`` continues it. Both are
removed when the run completes.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
from pathlib import Path

from adept_traj.cli.arguments import add_problem_arguments, problem_from_arguments
from adept_traj.cli.progress import ProgressReporter
from adept_traj.cli.report import save_figures, summary
from adept_traj.errors import ConfigurationError
from adept_traj.optimise import ALGORITHMS, PlanningInterrupted, plan

__all__ = ["RUN_FILE", "add_parser", "run"]

#: The arguments of a run in progress, in its result folder (removed when it completes).
RUN_FILE = "run.json"

#: The options saved in :data:`RUN_FILE` and restored by ``--resume``.
_SAVED = (
    "scene", "start", "goal", "seed", "weights", "rate", "algorithm", "pop", "gens",
    "workers", "no_html", "no_plots", "ros",
)  # fmt: skip


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``plan`` and its options."""
    p = sub.add_parser("plan", help="plan a trajectory and save a verified result")
    add_problem_arguments(p)
    p.add_argument(
        "--algorithm", default="nsga2", help=f"one of {', '.join(ALGORITHMS)} (default nsga2)"
    )
    p.add_argument("--pop", type=int, help="population size (default: the paper's)")
    p.add_argument("--gens", type=int, help="generations (default: the paper's, 100)")
    p.add_argument("--out", type=Path, help="result folder")
    p.add_argument("--resume", type=Path, help="continue an interrupted run in this folder")
    p.add_argument(
        "--no-html", action="store_true", help="do not write playback.html (static meshcat)"
    )
    p.add_argument("--no-plots", action="store_true", help="do not write figures/*.png")
    p.add_argument("--ros", type=Path, help="also export the best trajectory as ROS JSON")
    return p


def _restore(args: argparse.Namespace) -> Path:
    """Load the arguments of the interrupted run in ``--resume DIR`` into ``args``."""
    if args.out is not None and args.out != args.resume:
        raise ConfigurationError("--resume DIR continues in DIR; do not give another --out")
    run_file = args.resume / RUN_FILE
    if not run_file.is_file():
        raise ConfigurationError(f"{args.resume}: no interrupted run here ({RUN_FILE})")
    saved = json.loads(run_file.read_text())
    for key, value in saved.items():
        setattr(args, key, Path(value) if key == "ros" and value is not None else value)
    return args.resume


def _save_arguments(args: argparse.Namespace, folder: Path) -> None:
    saved = {k: getattr(args, k) for k in _SAVED}
    saved["scene"] = str(saved["scene"])
    saved["ros"] = None if saved["ros"] is None else str(saved["ros"])
    (folder / RUN_FILE).write_text(json.dumps(saved, indent=1))


def run(args: argparse.Namespace) -> int:
    """Run ``plan``; return the exit status (0 done, 130 interrupted)."""
    resume = args.resume is not None
    if resume:
        folder = _restore(args)
    elif args.out is None:
        raise ConfigurationError("give --out DIR (or --resume DIR)")
    else:
        folder = args.out
    problem = problem_from_arguments(args)
    folder.mkdir(parents=True, exist_ok=True)
    if not resume:
        _save_arguments(args, folder)
    try:
        with ProgressReporter(args.algorithm, quiet=args.quiet) as progress:
            result = plan(
                problem,
                args.algorithm,
                seed=args.seed,
                pop_size=args.pop,
                n_gen=args.gens,
                weights=args.weights,
                checkpoint=folder / "checkpoint",
                resume=resume,
                progress=progress,
                rate_hz=args.rate,
            )
    except PlanningInterrupted as exc:
        sys.stderr.write(f"{exc}: adept-traj plan --resume {folder}\n")
        return 130
    finally:
        problem.close()
    result.save(folder)
    if not args.no_html:
        from adept_traj.viz import meshcat_view

        meshcat_view.static_html(result, folder / "playback.html")
    if not args.no_plots:
        save_figures({args.algorithm: result}, folder / "figures")
    if args.ros is not None:
        from adept_traj.results import save_ros_joint_trajectory

        save_ros_joint_trajectory(result, args.ros, allow_infeasible=not result.feasible)
        print(f"ROS JointTrajectory written to {args.ros}")
    shutil.rmtree(folder / "checkpoint", ignore_errors=True)
    (folder / RUN_FILE).unlink(missing_ok=True)
    print(summary(result, folder))
    return 0
