"""``adept-traj verify DIR``: re-run the dense verification of a saved result and audit
every stored number that can be recomputed.

This is the one command that rebuilds the full problem (``result.problem()``, with its
collision checker): re-certification needs it. Exit status (:mod:`adept_traj.cli.status`):
0 if the best trade-off is feasible and the folder holds what its decision vectors give,
1 (:data:`~adept_traj.cli.status.NOT_CERTIFIED`) if the best trade-off is not feasible,
3 (:data:`~adept_traj.cli.status.MISMATCH`) if a stored value differs from its
recomputation (:func:`~adept_traj.certification.audit.audit`; one ``mismatch:`` line each), whatever
the verdict.

``--robot URDF [--params TOML] [--srdf FILE] [--tool-frame NAME] [--package-dir DIR]``
give the robot instead of the recorded files (moved, or meshes elsewhere); it must be the
recorded robot (:mod:`adept_traj.cli.result_robot`), else exit status 2.

One line per limit kind gives the worst ratio over the joints that have the limit and its
bound (position: fraction of the range beyond the nearer limit, bound 0; the others:
ratio to the limit, bound 1); joints without the limit (an infinite one, e.g. no
acceleration or jerk limit in the robot's files) are listed as ``no limit``.

``DIR`` may also be the output folder of ``adept-traj cycle`` (it holds ``cycle.json``):
then every move of every pass is certified again at its start time on the scene clock,
and every dwell (:func:`~adept_traj.cycle.verify_cycle`): exit status 0 all certified,
1 not, 3 the record's clock arithmetic does not hold. With ``--workers N`` (a local Dask
cluster of N worker processes) or ``--scheduler ADDRESS`` (a running one), as for
``adept-traj cycle``, the moves are certified as Dask tasks: the same verdicts.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from adept_traj.analysis import PAPER_WEIGHTS
from adept_traj.certification import LimitCheck, certify, check_certificate_memory
from adept_traj.certification.audit import audit
from adept_traj.cli import status
from adept_traj.cli.arguments import check_rate, floats, scene_from_argument
from adept_traj.cli.result_robot import add_result_robot_arguments, result_robot
from adept_traj.errors import ConfigurationError
from adept_traj.results import PlanningResult
from adept_traj.results.unchecked import unchecked_of
from adept_traj.robot import JointLimits
from adept_traj.scene import scene_notes
from adept_traj.validation import as_integer

__all__ = ["add_parser", "run"]


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``verify`` and its options."""
    p = sub.add_parser("verify", help="re-run the dense verification of a saved result")
    p.add_argument(
        "folder", type=Path, help="result folder (result.json) or cycle folder (cycle.json)"
    )
    p.add_argument("--rate", type=float, default=1000.0, help="verification rate [Hz]")
    p.add_argument(
        "--weights",
        type=floats,
        default=list(PAPER_WEIGHTS),
        help="w1,...,w6 for f_c as given to plan (default: the paper's)",
    )
    p.add_argument(
        "--scene",
        help="a shipped scene (paper, detour) or the scene TOML file the run was planned on, "
        "compared with the stored scene (default: the shipped scene of the stored name)",
    )
    add_result_robot_arguments(p)
    p.add_argument(
        "--workers",
        type=int,
        help="cycle folders: certify the moves as Dask tasks on N local worker processes",
    )
    p.add_argument(
        "--scheduler",
        help="cycle folders: certify the moves as Dask tasks on a running Dask scheduler "
        "(tcp://host:8786)",
    )
    return p


def _limit_line(check: LimitCheck, limits: JointLimits) -> str:
    """``worst W (bound B)`` over the joints with a finite limit; ``no limit`` for the rest."""
    if check.kind == "position":
        limited = np.ones(len(limits.names), dtype=bool)  # position limits are finite
    else:
        limited = np.isfinite(limits.bound(check.kind))
    free = [name for name, has in zip(limits.names, limited) if not has]
    if not limited.any():
        return "no limit"
    text = f"worst {np.max(check.worst[limited]):.4f} (bound {check.bound:g})"
    return f"{text}; no limit: {', '.join(free)}" if free else text


def run(args: argparse.Namespace) -> int:
    """Run ``verify``; return the exit status (0 feasible and no mismatch, 1 not feasible,
    3 a mismatch)."""
    rate = check_rate(args.rate)
    folder = Path(args.folder)
    if args.workers is not None:
        as_integer(args.workers, "--workers", minimum=1, maximum=1024)
    if (folder / "cycle.json").is_file() and not (folder / "result.json").exists():
        return _verify_cycle(folder, args.workers, args.scheduler)
    if args.workers is not None or args.scheduler is not None:
        raise ConfigurationError(
            f"{folder}: --workers and --scheduler apply to a cycle folder (cycle.json) only"
        )
    result = PlanningResult.load(args.folder)
    scene = None
    if args.scene is not None:
        scene = scene_from_argument(args.scene)
    problem = result.problem(result_robot(args, result))
    try:
        check_certificate_memory(problem, rate, float(result.best_x[0]), option="--rate")
        t0 = time.perf_counter()
        found = audit(result, weights=args.weights, scene=scene, problem=problem)
        cert = found.certificate
        if rate != cert.rate_hz:
            cert = certify(problem, result.best_x, rate_hz=rate)
        elapsed = time.perf_counter() - t0
        limits = problem.robot.limits
    finally:
        problem.close()
    print(
        f"{args.folder}: re-verified at {rate:g} Hz ({cert.n_samples} samples): "
        f"{'FEASIBLE' if cert.feasible else 'NOT FEASIBLE'}"
        f"; min distance {cert.min_distance:.4f} m (margin {cert.margin} m)"
    )
    t_start = result.problem_settings.start_time
    if t_start:
        print(f"  scene clock: certified at scene times t0 + t, t0 = {t_start:g} s")
    for check in cert.checks:
        print(f"  {check.kind:<13} {_limit_line(check, limits)}")
    for violation in cert.violations:
        print(f"  violation: {violation}")
    for note in scene_notes(problem.scene):
        print(f"  obstacle {note}")
    if result.self_pairs is not None:
        for line in result.self_pairs.lines():
            print(f"  self-collision: {line}")
    for item in unchecked_of(result):
        print(f"  unchecked: {item}")
    if cert.feasible != result.certificate.feasible:
        print("  note: the saved certificate said otherwise")
    for mismatch in found.mismatches:
        print(f"  mismatch: {mismatch}")
    for item in found.not_checked:
        print(f"  not checked: {item}")
    n = len(found.mismatches)
    verdict = (
        "no mismatch"
        if found.ok
        else f"{n} mismatch{'es' if n > 1 else ''}: the folder does not hold what its "
        "decision vectors give"
    )
    print(
        f"  audit: {found.n_values} values in {found.n_fields} fields recomputed and compared "
        f"({elapsed:.2f} s): {verdict}"
    )
    if not found.ok:
        return status.MISMATCH
    return status.OK if cert.feasible else status.NOT_CERTIFIED


def _verify_cycle(folder: Path, workers: int | None, scheduler: str | None) -> int:
    """``verify`` of a cycle's output folder (:func:`~adept_traj.cycle.verify_cycle`; on
    Dask with ``workers`` or ``scheduler``)."""
    from adept_traj.cycle.cycle_verify import verify_cycle

    found = verify_cycle(folder, workers=workers, scheduler=scheduler)
    print(f"{folder}: cycle re-certified, {found.n_moves} moves on the scene clock:")
    for line in found.lines:
        print(f"  {line}")
    for mismatch in found.mismatches:
        print(f"  mismatch: {mismatch}")
    print(f"  {'every move and dwell certified' if found.certified else 'NOT all certified'}")
    if found.mismatches:
        return status.MISMATCH
    return status.OK if found.certified else status.NOT_CERTIFIED
