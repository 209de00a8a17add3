"""``adept-traj export DIR``: write a front member's move for a robot controller.

``--member N`` (default: the best trade-off; the index of ``adept-traj front DIR``),
``--format csv|ros-json|ros-yaml`` (default ``csv``), ``--dt DT`` the fixed time step [s]
(default 0.001; every step exactly DT but the last, the move's last sample at T), and
``--output FILE`` (default ``DIR/member_N.csv``, ``.json`` or ``.yaml``; ``-``: standard
output). The CSV of the best trade-off at the default step is the folder's
``best_trajectory.csv``, byte for byte (one mechanism: :mod:`adept_traj.results.fixed_step`).
An uncertified member is refused (exit status 2) unless ``--allow-uncertified``.
Reads ``result.json`` only: no robot file is loaded (:mod:`adept_traj.export`).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from adept_traj.cli import status
from adept_traj.cli.result_options import add_member_option, add_result_folder

__all__ = ["add_parser", "run"]

_SUFFIX = {"csv": ".csv", "ros-json": ".json", "ros-yaml": ".yaml"}


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``export`` and its options."""
    p = sub.add_parser("export", help="write a front member for a controller (CSV, ROS)")
    add_result_folder(p)
    add_member_option(p, "export")
    p.add_argument("--format", choices=list(_SUFFIX), default="csv", help="default: csv")
    p.add_argument("--dt", type=float, default=0.001, help="time step [s] (default: 0.001)")
    p.add_argument(
        "--output",
        help="file to write (default: DIR/member_N.csv|.json|.yaml; '-': standard output)",
    )
    p.add_argument(
        "--allow-uncertified",
        action="store_true",
        help="export the member even if it is not certified",
    )
    return p


def run(args: argparse.Namespace) -> int:
    """Write the file and print its path; exit status 0."""
    from adept_traj import export
    from adept_traj.results import PlanningResult

    result = PlanningResult.load(args.folder)
    tr = export.sample_member(
        result, args.member, dt=args.dt, allow_uncertified=args.allow_uncertified
    )
    text = export.WRITERS[args.format](tr)
    if args.output == "-":
        sys.stdout.write(text)
        return status.OK
    out = Path(args.output) if args.output else args.folder / f"member_{tr.member}"
    if not args.output:
        out = out.with_suffix(_SUFFIX[args.format])
    from adept_traj.files import write_text_atomic

    path = write_text_atomic(out, text)
    which = "best trade-off" if tr.best_tradeoff else "member"
    verdict = "certified" if tr.certified else "NOT CERTIFIED"
    print(f"wrote {path} ({which} {tr.member}, {verdict}, {len(tr.t)} samples at dt = {tr.dt:g} s)")
    return status.OK
