"""The ``adept-traj`` command.

Sub-commands:

- ``adept-traj plan --out DIR`` — plan on a scene (default: the paper's), verify the best
  trade-off densely and save the result folder; Ctrl-C checkpoints, ``--resume DIR``
  continues.
- ``adept-traj compare --out DIR`` — NSGA-II and MODE on the same problem, with the paper's
  Tables 3–5 beside ours (``DIR/comparison.md``).
- ``adept-traj verify DIR`` — re-run the dense verification of a saved result.
- ``adept-traj show DIR`` — play a saved result in the browser (meshcat, 127.0.0.1).
- ``adept-traj robot`` — the robot-model demo (torques and manipulability along a move).
- ``adept-traj build-urdf PARAMS --output URDF`` — regenerate a URDF from a parameter file.

Bad input never prints a traceback: the command exits with status 2 and a one-line reason.
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.analysis.certificate import certify
from adept_traj.analysis.decision import PAPER_WEIGHTS, average_fitness, combined_objective
from adept_traj.analysis.indicators import normalised_hypervolume, objective_bounds
from adept_traj.errors import AdeptTrajError, ConfigurationError, InvalidInputError
from adept_traj.optimise.algorithms import ALGORITHMS
from adept_traj.optimise.loop import GenerationInfo, PlanningInterrupted
from adept_traj.optimise.planner import plan
from adept_traj.problem.trajectory_problem import TrajectoryProblem
from adept_traj.results.record import PlanningResult
from adept_traj.robot.robot import Robot
from adept_traj.robot.urdf_builder import build_urdf
from adept_traj.scene.scene import Scene

__all__ = ["main"]

_RUN_FILE = "run.json"


def _floats(text: str) -> list[float]:
    try:
        return [float(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected comma-separated numbers, got {text!r}"
        ) from None


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="adept-traj", description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)

    def problem_args(p: argparse.ArgumentParser) -> None:
        p.add_argument("--scene", default="paper", help="'paper' or a scene TOML file")
        p.add_argument("--start", type=_floats, help="q1,...,q4 [rad|m] (default: the scene's)")
        p.add_argument("--goal", type=_floats, help="q1,...,q4 [rad|m] (default: the scene's)")
        p.add_argument("--seed", type=int, default=1, help="random seed (default 1)")
        p.add_argument(
            "--weights", type=_floats, default=list(PAPER_WEIGHTS), help="w1,...,w6 for f_c"
        )
        p.add_argument("--rate", type=float, default=1000.0, help="verification rate [Hz]")
        p.add_argument("--quiet", action="store_true", help="no progress bar")
        p.add_argument(
            "--workers", type=int, default=1, help="processes evaluating in parallel (default 1)"
        )

    p_plan = sub.add_parser("plan", help="plan a trajectory and save a verified result")
    problem_args(p_plan)
    p_plan.add_argument(
        "--algorithm", default="nsga2", help=f"one of {', '.join(ALGORITHMS)} (default nsga2)"
    )
    p_plan.add_argument("--pop", type=int, help="population size (default: the paper's)")
    p_plan.add_argument("--gens", type=int, help="generations (default: the paper's, 100)")
    p_plan.add_argument("--out", type=Path, help="result folder")
    p_plan.add_argument("--resume", type=Path, help="continue an interrupted run in this folder")

    p_cmp = sub.add_parser("compare", help="NSGA-II vs MODE: the paper's Tables 3-5")
    problem_args(p_cmp)
    p_cmp.add_argument("--gens", type=int, help="generations of both (default 100)")
    p_cmp.add_argument("--pop-nsga2", type=int, help="NSGA-II population (default 100)")
    p_cmp.add_argument("--pop-mode", type=int, help="MODE population (default 500)")
    p_cmp.add_argument("--out", type=Path, required=True, help="output folder")
    p_cmp.add_argument("--no-plots", action="store_true", help="do not write figures/*.png")

    p_plan.add_argument(
        "--no-html", action="store_true", help="do not write playback.html (static meshcat)"
    )
    p_plan.add_argument("--no-plots", action="store_true", help="do not write figures/*.png")
    p_plan.add_argument("--ros", type=Path, help="also export the best trajectory as ROS JSON")

    p_show = sub.add_parser("show", help="play a saved result in the browser (meshcat)")
    p_show.add_argument("folder", type=Path, help="result folder (with result.json)")
    p_show.add_argument("--speed", type=float, default=1.0, help="playback speed factor")
    p_show.add_argument("--closest", action="store_true", help="draw the closest-point segment")
    p_show.add_argument("--open", action="store_true", help="open the page in a web browser")

    p_ver = sub.add_parser("verify", help="re-run the dense verification of a saved result")
    p_ver.add_argument("folder", type=Path, help="result folder (with result.json)")
    p_ver.add_argument("--rate", type=float, default=1000.0, help="verification rate [Hz]")

    robot = sub.add_parser("robot", help="robot-model demo: torques and manipulability")
    robot.add_argument("--urdf", type=Path, help="URDF file (default: the AdeptOne XL)")
    robot.add_argument("--params", type=Path, help="parameter file for --urdf")
    robot.add_argument("--start", type=_floats, help="q1,...,qn [rad|m] (default: paper's)")
    robot.add_argument("--goal", type=_floats, help="q1,...,qn [rad|m] (default: paper's)")
    robot.add_argument("--duration", type=float, default=1.1, help="move time T [s]")
    robot.add_argument("--samples", type=int, default=1001, help="samples along the move")

    build = sub.add_parser("build-urdf", help="write a URDF from a robot parameter file")
    build.add_argument("params", type=Path, help="parameter file (TOML)")
    build.add_argument("--output", "-o", type=Path, help="URDF path (default: stdout)")
    return parser


# ---------------------------------------------------------------------------------- helpers
def _progress_bar(label: str, quiet: bool):
    if quiet:
        return None

    def show(info: GenerationInfo) -> None:
        width = 30
        done = int(width * info.generation / info.n_gen)
        best = f"{info.best_time:.3f} s" if info.best_time is not None else "-"
        sys.stderr.write(
            f"\r{label} [{'#' * done}{'.' * (width - done)}] gen {info.generation}/{info.n_gen}"
            f"  evals {info.n_evaluations}  feasible {info.n_feasible}  best T {best}"
            f"  {info.elapsed_s:.1f} s "
        )
        if info.generation == info.n_gen:
            sys.stderr.write("\n")
        sys.stderr.flush()

    return show


def _problem(args: argparse.Namespace) -> TrajectoryProblem:
    scene = Scene.paper() if args.scene == "paper" else Scene.from_file(args.scene)
    start = args.start if args.start is not None else scene.start
    goal = args.goal if args.goal is not None else scene.goal
    if start is None or goal is None:
        raise ConfigurationError(
            f"scene '{scene.name}' has no [task] start/goal: give --start and --goal"
        )
    weights = np.asarray(args.weights, dtype=float)
    if weights.shape != (6,) or not np.all(np.isfinite(weights)) or (weights < 0).any():
        raise InvalidInputError(
            f"--weights must be 6 finite numbers ≥ 0; got {','.join(map(str, args.weights))}"
        )
    if weights.sum() <= 0:
        raise InvalidInputError("--weights must not all be 0")
    if not (np.isfinite(args.rate) and args.rate >= 100):
        raise InvalidInputError(f"--rate must be ≥ 100 Hz; got {args.rate}")
    return TrajectoryProblem(Robot.adept_one_xl(), scene, start, goal, workers=args.workers)


def _summary(result: PlanningResult, folder: Path) -> str:
    z = result.best_objectives
    cert = result.certificate
    lines = [
        f"{result.algorithm}: {result.timing.n_evaluations} evaluations in "
        f"{result.timing.total_s:.1f} s ({result.timing.evaluation_s:.1f} s evaluating); "
        f"front of {len(result.front)}",
        f"best trade-off: T = {z[0]:.3f} s (lower bound {result.lower_bound.T_min:.3f} s, "
        f"gap {result.gap:.2f}x), z2 = {z[1]:.4g}, z3 = {z[2]:.4g}, z4 = {z[3]:.4g} m², "
        f"z5 = {z[4]:.4g}, z6 = {z[5]:.4g}",
        f"verified at {cert.rate_hz:g} Hz: {'FEASIBLE' if cert.feasible else 'NOT FEASIBLE'}"
        f" (min distance {cert.min_distance:.4f} m, margin {cert.margin} m)",
    ]
    lines += [f"  violation: {v}" for v in cert.violations]
    if result.warning:
        lines.append(f"warning: {result.warning}")
    lines.append(f"saved to {folder}/result.json")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------- commands
def _plan(args: argparse.Namespace) -> int:
    if args.resume is not None:
        if args.out is not None and args.out != args.resume:
            raise ConfigurationError("--resume DIR continues in DIR; do not give another --out")
        run_file = args.resume / _RUN_FILE
        if not run_file.is_file():
            raise ConfigurationError(f"{args.resume}: no interrupted run here ({_RUN_FILE})")
        saved = json.loads(run_file.read_text())
        folder, resume = args.resume, True
        for key, value in saved.items():
            setattr(args, key, Path(value) if key == "ros" and value is not None else value)
    else:
        if args.out is None:
            raise ConfigurationError("give --out DIR (or --resume DIR)")
        folder, resume = args.out, False
    problem = _problem(args)
    folder.mkdir(parents=True, exist_ok=True)
    if not resume:
        keys = ("scene", "start", "goal", "seed", "weights", "rate", "algorithm", "pop", "gens")
        keys = (*keys, "workers", "no_html", "no_plots", "ros")
        saved = {k: getattr(args, k) for k in keys}
        saved["scene"] = str(saved["scene"])
        saved["ros"] = None if saved["ros"] is None else str(saved["ros"])
        (folder / _RUN_FILE).write_text(json.dumps(saved, indent=1))
    try:
        result = plan(
            problem,
            args.algorithm,
            seed=args.seed,
            pop_size=args.pop,
            n_gen=args.gens,
            weights=args.weights,
            checkpoint=folder / "checkpoint",
            resume=resume,
            progress=_progress_bar(args.algorithm, args.quiet),
            rate_hz=args.rate,
        )
    except PlanningInterrupted as exc:
        sys.stderr.write(f"\n{exc}: adept-traj plan --resume {folder}\n")
        return 130
    finally:
        problem.close()
    result.save(folder)
    if not args.no_html:
        from adept_traj.viz import meshcat_view

        meshcat_view.static_html(result, folder / "playback.html")
    if not args.no_plots:
        _figures({args.algorithm: result}, folder / "figures")
    if args.ros is not None:
        from adept_traj.results.ros_export import save_ros_joint_trajectory

        save_ros_joint_trajectory(result, args.ros, allow_infeasible=not result.feasible)
        print(f"ROS JointTrajectory written to {args.ros}")
    shutil.rmtree(folder / "checkpoint", ignore_errors=True)
    (folder / _RUN_FILE).unlink(missing_ok=True)
    print(_summary(result, folder))
    return 0


def _figures(results: dict[str, PlanningResult], folder: Path) -> None:
    """The paper's figures as PNGs (matplotlib, the ``plot`` extra)."""
    try:
        from adept_traj.viz import plots

        paths = plots.save_all(results, folder)
    except ImportError as exc:
        print(f"note: figures skipped ({exc}); install the 'plot' extra", file=sys.stderr)
        return
    print(f"{len(paths)} figures in {folder}")


def _show(args: argparse.Namespace) -> int:
    from adept_traj.viz import meshcat_view

    result = PlanningResult.load(args.folder)
    vis = meshcat_view.show(
        result, speed=args.speed, show_closest=args.closest, open_browser=args.open
    )
    try:  # the URL is printed inside: a Ctrl-C right after it must still stop cleanly
        print(f"playing {args.folder} at {vis.url()} (Ctrl-C to stop)", flush=True)
        while True:
            time.sleep(1.0)
    except KeyboardInterrupt:
        return 0
    finally:
        vis.close()


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


def _comparison_markdown(results: dict[str, PlanningResult], weights: Sequence[float]) -> str:
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


def _compare(args: argparse.Namespace) -> int:
    problem = _problem(args)
    results = {}
    for name, pop in (("nsga2", args.pop_nsga2), ("mode", args.pop_mode)):
        results[name] = plan(
            problem,
            name,
            seed=args.seed,
            pop_size=pop,
            n_gen=args.gens,
            weights=args.weights,
            progress=_progress_bar(name, args.quiet),
            rate_hz=args.rate,
        )
        results[name].save(args.out / name)
        print(_summary(results[name], args.out / name))
    problem.close()
    if not args.no_plots:
        _figures(results, args.out / "figures")
    text = _comparison_markdown(results, args.weights)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "comparison.md").write_text(text)
    print(text)
    return 0


def _verify(args: argparse.Namespace) -> int:
    if not (np.isfinite(args.rate) and args.rate >= 100):
        raise InvalidInputError(f"--rate must be ≥ 100 Hz; got {args.rate}")
    result = PlanningResult.load(args.folder)
    problem = result.problem()
    t0 = time.perf_counter()
    cert = certify(problem, result.best_x, rate_hz=args.rate)
    print(
        f"{args.folder}: re-verified at {args.rate:g} Hz ({cert.n_samples} samples, "
        f"{time.perf_counter() - t0:.2f} s): {'FEASIBLE' if cert.feasible else 'NOT FEASIBLE'}"
        f"; min distance {cert.min_distance:.4f} m (margin {cert.margin} m)"
    )
    for check in cert.checks:
        print(f"  {check.kind:<13} worst {np.max(check.worst):.4f} (bound {check.bound:g})")
    for violation in cert.violations:
        print(f"  violation: {violation}")
    if cert.feasible != result.certificate.feasible:
        print("  note: the saved certificate said otherwise")
    return 0 if cert.feasible else 1


def _quintic_move(
    start: np.ndarray, goal: np.ndarray, duration: float, n: int
) -> tuple[np.ndarray, ...]:
    """Rest-to-rest quintic move: t (n,), q, v, a (n, nq)."""
    tau = np.linspace(0.0, 1.0, n)
    s = 10 * tau**3 - 15 * tau**4 + 6 * tau**5
    sd = (30 * tau**2 - 60 * tau**3 + 30 * tau**4) / duration
    sdd = (60 * tau - 180 * tau**2 + 120 * tau**3) / duration**2
    delta = goal - start
    return tau * duration, start + s[:, None] * delta, sd[:, None] * delta, sdd[:, None] * delta


def _robot_demo(args: argparse.Namespace) -> int:
    robot = Robot.adept_one_xl() if args.urdf is None else Robot.from_urdf(args.urdf, args.params)
    paper = Scene.paper()  # its [task]: the paper's start and goal (docs/paper-scenario.md)
    start = robot.limits.check_position(
        paper.start if args.start is None else args.start, "--start"
    )
    goal = robot.limits.check_position(paper.goal if args.goal is None else args.goal, "--goal")
    if not (np.isfinite(args.duration) and args.duration > 0):
        raise InvalidInputError(f"--duration must be a positive number [s]; got {args.duration}")
    if args.samples < 2:
        raise InvalidInputError(f"--samples must be at least 2; got {args.samples}")
    t, q, v, a = _quintic_move(start, goal, args.duration, args.samples)
    u = robot.inverse_dynamics(q, v, a)
    lim = robot.limits
    print(f"{robot.name}: quintic rest-to-rest move in T = {args.duration:g} s")
    print(f"  start {np.array2string(start, precision=4)}")
    print(f"  goal  {np.array2string(goal, precision=4)}")
    print(f"  {'joint':<8}{'peak |q̇|':>16}{'peak |q̈|':>17}{'peak |u|':>14}{'UC':>6}{'|u|/UC':>8}")
    for k, name in enumerate(robot.joint_names):
        unit = lim.units[k]
        force = "N" if unit == "m" else "N·m"
        peak_u = np.abs(u[:, k]).max()
        print(
            f"  {name:<8}{np.abs(v[:, k]).max():>9.3f} {unit + '/s':<6}"
            f"{np.abs(a[:, k]).max():>9.3f} {unit + '/s²':<7}{peak_u:>9.2f} {force:<4}"
            f"{lim.torque[k]:>6.0f}{peak_u / lim.torque[k]:>8.3f}"
        )
    dt = np.diff(t)
    energy = np.sum(0.5 * ((u[1:] ** 2).sum(1) + (u[:-1] ** 2).sum(1)) * dt)
    print(f"  ∫ Σ u² dt (paper z2) = {energy:.2f} [N²·m²·s]")
    if robot.task_rows is not None:
        w = robot.manipulability(q)
        print(f"  manipulability (paper z4): min {w.min():.5f}, max {w.max():.5f} [m²]")
    return 0


def _build_urdf(args: argparse.Namespace) -> int:
    text = build_urdf(args.params)
    if args.output is None:
        sys.stdout.write(text)
    else:
        args.output.write_text(text)
        print(f"wrote {args.output}")
    return 0


_COMMANDS = {
    "plan": _plan,
    "show": _show,
    "compare": _compare,
    "verify": _verify,
    "robot": _robot_demo,
    "build-urdf": _build_urdf,
}


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``adept-traj``; returns the exit status."""
    args = _parser().parse_args(argv)
    try:
        return _COMMANDS[args.command](args)
    except (AdeptTrajError, OSError, json.JSONDecodeError) as exc:
        print(f"adept-traj: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
