"""``adept-traj plan``: plan on a scene, verify the best trade-off densely, save the result.

While running, ``DIR/checkpoint/`` holds the last finished generation and ``DIR/run.json``
the arguments; Ctrl-C stops the run (exit 130) and ``--resume DIR`` continues it. Both are
removed when the run completes.

``--ros FILE`` exports the best trade-off for a robot controller only when its dense
certificate is feasible; otherwise the result folder is still written, nothing is
exported and the exit status is 1 (``--allow-infeasible`` exports it anyway). A ``FILE``
that cannot be written (a folder, a path through a file, a file of the result folder) is
refused before the run starts.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
from pathlib import Path

from adept_traj.cli import status
from adept_traj.cli.arguments import add_problem_arguments, problem_from_arguments
from adept_traj.cli.progress import ProgressReporter
from adept_traj.cli.report import save_figures, summary
from adept_traj.errors import ConfigurationError, InvalidInputError
from adept_traj.optimise import ALGORITHMS, PlanningInterrupted, plan
from adept_traj.results import (
    FRONT_FILE,
    RESULT_FILE,
    TRAJECTORY_FILE,
    PlanningResult,
    Replay,
    save_ros_joint_trajectory,
)

__all__ = ["RUN_FILE", "add_parser", "run"]

#: The arguments of a run in progress, in its result folder (removed when it completes).
RUN_FILE = "run.json"

#: The files of the result folder that ``--ros`` must not overwrite.
_RESULT_FILES = (RESULT_FILE, FRONT_FILE, TRAJECTORY_FILE, "playback.html", RUN_FILE)
_CHECKPOINT = "checkpoint"

#: The options saved in :data:`RUN_FILE` and restored by ``--resume``.
_SAVED = (
    "scene", "start", "goal", "seed", "weights", "rate", "algorithm", "pop", "gens",
    "workers", "no_html", "no_plots", "ros", "allow_infeasible",
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
    p.add_argument("--ros", type=Path, help="also export the certified best trajectory as ROS JSON")
    p.add_argument(
        "--allow-infeasible",
        action="store_true",
        help="with --ros: export the best trajectory even if its certificate failed",
    )
    return p


def _restore(args: argparse.Namespace) -> Path:
    """Load the arguments of the interrupted run in ``--resume DIR`` into ``args``."""
    if args.out is not None and args.out != args.resume:
        raise ConfigurationError("--resume DIR continues in DIR; do not give another --out")
    run_file = args.resume / RUN_FILE
    if not run_file.is_file():
        raise ConfigurationError(f"{args.resume}: no interrupted run here ({RUN_FILE})")
    saved = json.loads(run_file.read_text())
    allow_infeasible = args.allow_infeasible  # may be given again when resuming
    for key, value in saved.items():
        setattr(args, key, Path(value) if key == "ros" and value is not None else value)
    args.allow_infeasible = bool(args.allow_infeasible) or allow_infeasible
    return args.resume


def _check_ros_path(path: Path, folder: Path) -> None:
    """Refuse a ``--ros`` file that cannot be written, before the run starts."""
    if "\0" in str(path):
        raise InvalidInputError(f"--ros {str(path)!r} is not a valid path (NUL character)")
    if path.is_dir():
        raise InvalidInputError(f"--ros {path} is a folder; give a file, e.g. {path}/best.json")
    parent = path.parent
    while not parent.exists():  # the export creates missing folders
        parent = parent.parent
    if not parent.is_dir():
        raise InvalidInputError(f"--ros {path}: {parent} is not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InvalidInputError(f"--ros {path}: cannot write in {parent}")
    target, root = path.resolve(), folder.resolve()
    if target in {root / name for name in _RESULT_FILES} or root / _CHECKPOINT in target.parents:
        raise InvalidInputError(f"--ros {path} is a file of the result folder {folder}")


def _save_arguments(args: argparse.Namespace, folder: Path) -> None:
    saved = {k: getattr(args, k) for k in _SAVED}
    saved["scene"] = str(saved["scene"])
    saved["ros"] = None if saved["ros"] is None else str(saved["ros"])
    (folder / RUN_FILE).write_text(json.dumps(saved, indent=1))


def run(args: argparse.Namespace) -> int:
    """Run ``plan``; return the exit status (:mod:`adept_traj.cli.status`: 0 done, 1 the
    ``--ros`` export refused, 130 interrupted)."""
    resume = args.resume is not None
    if resume:
        folder = _restore(args)
    elif args.out is None:
        raise ConfigurationError("give --out DIR (or --resume DIR)")
    else:
        folder = args.out
    if args.ros is not None:
        _check_ros_path(args.ros, folder)
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
                checkpoint=folder / _CHECKPOINT,
                resume=resume,
                progress=progress,
                rate_hz=args.rate,
            )
    except PlanningInterrupted as exc:
        sys.stderr.write(f"{exc}: adept-traj plan --resume {folder}\n")
        return status.INTERRUPTED
    finally:
        problem.close()
    result.save(folder)
    # The views are built from one Replay of the run's own robot and scene (nothing reloaded).
    replay = Replay.of(result, robot=problem.robot, scene=problem.scene)
    if not args.no_html:
        from adept_traj.viz import meshcat_scene

        meshcat_scene.static_html(result, folder / "playback.html", replay=replay)
    if not args.no_plots:
        save_figures({args.algorithm: result}, folder / "figures", {args.algorithm: replay})
    shutil.rmtree(folder / _CHECKPOINT, ignore_errors=True)
    (folder / RUN_FILE).unlink(missing_ok=True)
    print(summary(result, folder))
    if args.ros is not None:
        return _export_ros(result, args.ros, args.allow_infeasible, replay)
    return status.OK


def _export_ros(result: PlanningResult, path: Path, allow_infeasible: bool, replay: Replay) -> int:
    """Write the ROS file unless the best trade-off is uncertified and not allowed."""
    if not (result.feasible or allow_infeasible):
        print(
            f"adept-traj: error: the best trade-off is not verified feasible; {path} was not "
            "written (it is meant for a robot controller; --allow-infeasible exports it "
            "anyway)",
            file=sys.stderr,
        )
        return status.NOT_CERTIFIED
    save_ros_joint_trajectory(result, path, allow_infeasible=allow_infeasible, replay=replay)
    print(f"ROS JointTrajectory written to {path}")
    return status.OK
