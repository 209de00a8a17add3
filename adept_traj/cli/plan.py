"""``adept-traj plan``: plan on a scene, verify the best trade-off densely, save the result.

While running, ``DIR/checkpoint/`` holds the last finished generation and ``DIR/run.json``
the arguments; Ctrl-C stops the run (exit 130) and ``--resume DIR`` continues it, from the
last checkpoint, to the same result as an uninterrupted run (also after a kill, at any
instant: :mod:`adept_traj.cli._run_folder` says how a folder tells its state). Both are
removed when the run completes; ``--resume`` of a complete run says so and changes nothing.

``--out DIR`` refuses a folder that holds files of an earlier run unless ``--overwrite`` is
given, which removes those files (only those ``plan`` writes) before the run; every option
and output path is checked before anything is written.

``--ros FILE`` exports the best trade-off for a robot controller only when its dense
certificate is feasible; otherwise the result folder is still written, nothing is
exported and the exit status is 1 (``--allow-infeasible`` exports it anyway). A ``FILE``
that cannot be written (a folder, a path through a file, a file of the result folder) is
refused before the run starts.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from adept_traj.cli import status
from adept_traj.cli._run_folder import (
    CHECKPOINT,
    HTML_FILE,
    RUN_FILE,
    as_path,
    check_folder,
    check_ros_path,
    commit,
    folder_lock,
    is_complete,
    read_arguments,
    remove_written,
    write_arguments,
)
from adept_traj.cli.arguments import add_problem_arguments, problem_from_task, task_from_arguments
from adept_traj.cli.limits import check_run_options
from adept_traj.cli.progress import ProgressReporter
from adept_traj.cli.report import (
    figures_line,
    finish_figures,
    finishers_for,
    save_collision_matrix,
    start_figures,
    summary,
    write_page,
)
from adept_traj.errors import ConfigurationError, PlanningInterrupted
from adept_traj.optimise import ALGORITHMS, POLISH_MODES, TIME_OPTIMAL
from adept_traj.problem import TrajectoryProblem
from adept_traj.results import RESULT_FILE, PlanningResult, Replay, save_ros_joint_trajectory
from adept_traj.scene import SHIPPED_SCENES, scene_notes
from adept_traj.validation import as_integer
from adept_traj.viz.finisher import Finisher

if TYPE_CHECKING:
    from adept_traj.optimise import Polisher

__all__ = ["RUN_FILE", "add_parser", "run"]

#: The options saved in :data:`RUN_FILE` and restored by ``--resume``.
_SAVED = (
    "scene", "start", "goal", "start_pose", "goal_pose", "elbow", "seed", "weights", "rate",
    "algorithm", "pop", "gens", "workers", "no_html", "no_plots", "ros", "allow_infeasible",
    "no_polish", "polish", "start_time",
    "robot", "params", "tool_frame", "srdf", "package_dir", "locked_joint",
)  # fmt: skip
#: Saved options that may be given anew when resuming (they change nothing in the result).
_FREE_ON_RESUME = ("workers", "allow_infeasible")
#: Written into :data:`RUN_FILE` since ``--algorithm time-optimal --weights`` is the
#: weighted-sum mode: a time-optimal run file without it was written by an earlier version,
#: whose time-optimal mode ignored the (saved, default) weights — it resumes as minimum T.
_WEIGHTED_MODE_KEY = "time_optimal_weights"


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``plan`` and its options."""
    p = sub.add_parser("plan", help="plan a trajectory and save a verified result")
    add_problem_arguments(p, start_time=True)
    p.add_argument(
        "--algorithm",
        default="nsga2",
        help=f"one of {', '.join(ALGORITHMS)} (default nsga2), or {TIME_OPTIMAL} (one "
        "fastest move by multi-start SLSQP, no evolutionary search; with --weights the move "
        "of least weighted sum of z1..z6, scaled by the straight move's values)",
    )
    p.add_argument(
        "--polish",
        choices=POLISH_MODES,
        default="front",
        help="gradient-based polish after the evolutionary search: off, fastest (the "
        "fastest member, SLSQP), front (default: also the best trade-off and members "
        "spread over the front, within a quarter of the search's evaluations), all (every "
        "front member)",
    )
    p.add_argument("--no-polish", action="store_true", help="the same as --polish off")
    p.add_argument("--pop", type=int, help="population size (default: the paper's)")
    p.add_argument("--gens", type=int, help="generations (default: the paper's, 100)")
    p.add_argument("--out", type=str, help="result folder")
    p.add_argument(
        "--overwrite",
        action="store_true",
        help="replace the files of an earlier run in --out (only the files plan writes)",
    )
    p.add_argument("--resume", type=str, help="continue an interrupted run in this folder")
    p.add_argument(
        "--no-html", action="store_true", help="do not write playback.html (static meshcat)"
    )
    p.add_argument("--no-plots", action="store_true", help="do not write figures/*.png")
    p.add_argument("--ros", type=str, help="also export the certified best trajectory as ROS JSON")
    p.add_argument(
        "--allow-infeasible",
        action="store_true",
        help="with --ros: export the best trajectory even if its certificate failed",
    )
    # An option left out is None, so that --resume tells it from one given (even with its
    # default value); the defaults fill it in for a new run.
    p.set_defaults(plan_defaults={k: p.get_default(k) for k in _SAVED}, **dict.fromkeys(_SAVED))
    return p


def _option(key: str) -> str:
    return "--" + key.replace("_", "-")


def _comparable(key: str, value: Any) -> Any:
    """``value`` of option ``key`` in the form run.json keeps (absolute paths)."""
    if value is None or (key == "scene" and value in SHIPPED_SCENES):
        return value
    if key in ("robot", "srdf") and str(value).startswith("package://"):
        return str(value)  # found in the package folders, wherever the run starts
    if key in ("scene", "ros", "robot", "params", "srdf"):
        return str(Path(value).resolve())
    if key == "package_dir":
        return [str(Path(v).resolve()) for v in value]
    if key in ("start", "goal", "weights", "start_pose", "goal_pose"):
        return [float(x) for x in value]
    return value


def _shown(value: Any) -> str:
    if value is None:
        return "not given"
    if isinstance(value, bool):
        return "on" if value else "off"
    if isinstance(value, list):
        return ",".join(str(x) for x in value)  # every digit: the values differ somewhere
    return str(value)


def _resumed_options(saved: dict[str, Any], given: dict[str, Any], folder: Path) -> dict:
    """The options of the run in ``folder``; an option given again must equal its saved
    value (except :data:`_FREE_ON_RESUME`), else :class:`ConfigurationError` naming both."""
    options = dict(saved)
    for key, value in given.items():
        if key in _FREE_ON_RESUME:
            options[key] = value
            continue
        old, new = saved.get(key), _comparable(key, value)
        if new != _comparable(key, old):
            raise ConfigurationError(
                f"{_option(key)} {_shown(new)} conflicts with the run being resumed in "
                f"{folder} ({_option(key)} {_shown(old)}); leave it out to continue that "
                "run, or start a new one with --out"
            )
    return options


def _options(args: argparse.Namespace) -> tuple[argparse.Namespace, Path, bool]:
    """(the run's options, its folder, whether it resumes), checked; nothing is written."""
    given = {k: getattr(args, k) for k in _SAVED if getattr(args, k) is not None}
    if "ros" in given:
        given["ros"] = as_path(given["ros"], "--ros")
    out, resume = as_path(args.out, "--out"), as_path(args.resume, "--resume")
    if resume is None:
        if out is None:
            raise ConfigurationError("give --out DIR (or --resume DIR)")
        folder, options = out, {**args.plan_defaults, **given}
        if options["algorithm"] == TIME_OPTIMAL and "weights" not in given:
            options["weights"] = None  # minimum T (saved so: a restart stays minimum T)
        for key in ("scene", "ros", "robot", "params", "srdf", "package_dir"):
            options[key] = _comparable(key, options[key])
    else:
        folder = resume
        if out is not None and out != folder:
            raise ConfigurationError("--resume DIR continues in DIR; do not give another --out")
        if args.overwrite:
            raise ConfigurationError("--overwrite starts a new run; it does not go with --resume")
        saved = read_arguments(folder)
        marked = saved.pop(_WEIGHTED_MODE_KEY, False)
        if saved.get("algorithm") == TIME_OPTIMAL and not marked:
            saved["weights"] = None  # an earlier version's minimum-T run (see the key's note)
        options = _resumed_options(saved, given, folder)
    options = {**args.plan_defaults, **options}
    opts = argparse.Namespace(**{**vars(args), **options})
    opts.ros = None if opts.ros is None else Path(opts.ros)
    return opts, folder, resume is not None


def run(args: argparse.Namespace) -> int:
    """Run ``plan``; return the exit status (:mod:`adept_traj.cli.status`: 0 done with a
    certified best trade-off (or ``--resume`` of a complete run), 1 the run finished and
    its result folder is written but no certified move was found (the best trade-off's
    certificate failed; the ``--ros`` export refused), 130 interrupted)."""
    resume = as_path(args.resume, "--resume")
    if resume is not None and is_complete(resume):
        print(
            f"adept-traj: {resume}: the run is already complete ({RESULT_FILE}); nothing to resume",
            file=sys.stderr,
        )
        return status.OK
    opts, folder, resume = _options(args)
    if opts.ros is not None:
        check_ros_path(opts.ros, folder)
    if not resume:
        check_folder(
            folder, overwrite=args.overwrite, html=not opts.no_html, figures=not opts.no_plots
        )
    as_integer(opts.seed, "--seed", minimum=0, error=ConfigurationError)
    if opts.no_polish and opts.polish != "off" and args.polish is not None:
        raise ConfigurationError(f"--no-polish conflicts with --polish {opts.polish}")
    if opts.algorithm != TIME_OPTIMAL:
        from adept_traj.optimise import make_algorithm  # pymoo: an evolutionary run's

        make_algorithm(opts.algorithm, opts.pop, opts.gens)  # refuses bad settings now
    task = task_from_arguments(opts)
    # the finishers need the robot and scene only: their imports overlap the problem's build
    time_optimal = opts.algorithm == TIME_OPTIMAL
    outputs = {"figures": not opts.no_plots, "html": not opts.no_html}
    with finishers_for(task.robot, task.scene, **outputs, time_optimal=time_optimal) as (
        drawer,
        pager,
    ):
        problem = problem_from_task(opts, task)
        try:
            # memory of the population and dense certificate, before anything is written
            check_run_options(problem, opts.algorithm, opts.pop, opts.gens, opts.rate)
            with folder_lock(folder):  # no second process writing into the folder meanwhile
                if not resume:
                    remove_written(folder)  # only with --overwrite: check_folder refused
                    saved = {k: getattr(opts, k) for k in _SAVED}
                    ros = _comparable("ros", opts.ros)
                    saved = {**saved, "ros": ros, _WEIGHTED_MODE_KEY: True}
                    if saved["start_time"] is None:  # not given: run.json as before it
                        del saved["start_time"]
                    write_arguments(folder, saved)
                with _polisher_for(problem, opts) as polisher:
                    return _run(opts, problem, folder, resume, (drawer, pager), polisher)
        finally:
            problem.close()


def _polisher_for(problem: TrajectoryProblem, opts: argparse.Namespace) -> Any:
    """The helper process that will polish the search's result while this one certifies
    (:func:`adept_traj.optimise.start_polisher`), in a context that stops it; an empty
    context (``None``) without a polish or a search, or when no process can be forked."""
    if opts.no_polish or opts.polish == "off" or opts.algorithm == TIME_OPTIMAL:
        return contextlib.nullcontext(None)
    from adept_traj.optimise import start_polisher

    try:
        return start_polisher(problem)
    except OSError:  # e.g. no memory to fork: the polish runs in this process
        return contextlib.nullcontext(None)


def _run(
    opts: argparse.Namespace,
    problem: TrajectoryProblem,
    folder: Path,
    resume: bool,
    finishers: tuple[Finisher | None, Finisher | None] = (None, None),
    polisher: Polisher | None = None,
) -> int:
    """Plan, save and mark the run complete; on Ctrl-C say how to resume."""
    # imported once the finishers are forked (they need none of it): their imports and
    # these overlap
    from adept_traj.optimise import has_checkpoint, plan

    checkpoint = folder / CHECKPOINT
    try:
        with ProgressReporter(opts.algorithm, quiet=opts.quiet) as progress:
            result = plan(
                problem,
                opts.algorithm,
                seed=opts.seed,
                pop_size=opts.pop,
                n_gen=opts.gens,
                weights=opts.weights,
                checkpoint=checkpoint,
                # Interrupted before its first checkpoint: the run starts again.
                resume=resume and has_checkpoint(checkpoint),
                progress=progress,
                rate_hz=opts.rate,
                polish="off" if opts.no_polish else opts.polish,
                polisher=polisher,
            )
        return _finish(result, problem, folder, opts, *finishers)
    except PlanningInterrupted as exc:
        if exc.checkpoint is None:
            sys.stderr.write(
                f"{exc}; adept-traj plan --resume {folder} starts the run again (same result)\n"
            )
        else:
            sys.stderr.write(f"{exc}: adept-traj plan --resume {folder}\n")
        return status.INTERRUPTED
    except KeyboardInterrupt:
        sys.stderr.write(
            "interrupted after the last generation (checkpointed), while certifying or "
            f"saving; finish with: adept-traj plan --resume {folder}\n"
        )
        return status.INTERRUPTED


def _finish(
    result: PlanningResult,
    problem: TrajectoryProblem,
    folder: Path,
    opts: argparse.Namespace,
    drawer: Finisher | None = None,
    pager: Finisher | None = None,
) -> int:
    """Write every output of the run, then mark it complete (the last step). The figures
    are drawn by ``drawer`` and ``playback.html`` written by ``pager`` (the helper
    processes started with the run, if they are ready; without ``pager``, ``drawer``
    writes both), else the figures in a forked process and the page here, while this
    process writes ``result.json``; an error of theirs is raised here, before the run is
    marked complete."""
    # The views are built from one Replay of the run's own robot and scene (nothing reloaded).
    replay = Replay.of(result, robot=problem.robot, scene=problem.scene)
    results = {opts.algorithm: result}
    figures = None if opts.no_plots else folder / "figures"
    html = None if opts.no_html else folder / HTML_FILE
    drawing, its_page = None, html if pager is None else None  # the drawer's page
    try:
        drawn = drawer is not None and (figures or its_page) is not None
        drawn = drawn and drawer.start(results, figures=figures, html=its_page)
        paged = html is not None and pager is not None and pager.start(results, html=html)
        if figures is not None and not drawn:  # drawn in a forked process meanwhile
            drawing = start_figures(results, figures, {opts.algorithm: replay})
    except BaseException:  # e.g. no fork possible: the result is saved all the same
        result.save(folder)
        raise
    try:
        result.save(folder)
        if html is not None and not (paged or (drawn and its_page is not None)):
            write_page(result, folder / HTML_FILE, replay)
        if paged:
            pager.wait()
        paths = drawer.wait() if drawn else None
        if figures is not None and paths is not None:
            print(figures_line(paths, figures, results))
        elif figures is not None:
            finish_figures(drawing, figures, results)
    finally:  # stops the helpers and the drawing if anything above failed (else no-ops)
        for helper in (drawer, pager, drawing):
            if helper is not None:
                helper.cancel()
    print(summary(result, folder))
    for note in scene_notes(problem.scene):
        print(f"  obstacle {note}")
    save_collision_matrix(problem, folder)  # made for a robot without SRDF: reusable
    code = status.OK if result.feasible else status.NOT_CERTIFIED
    if opts.ros is not None:
        code = max(code, _export_ros(result, opts.ros, opts.allow_infeasible, replay))
    commit(folder)
    return code


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
