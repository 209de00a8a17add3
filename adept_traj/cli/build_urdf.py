"""``adept-traj build-urdf PARAMS``: write a URDF from a robot parameter file."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from adept_traj.cli import status
from adept_traj.robot import build_urdf

__all__ = ["add_parser", "run"]


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``build-urdf`` and its options."""
    p = sub.add_parser("build-urdf", help="write a URDF from a robot parameter file")
    p.add_argument("params", type=Path, help="parameter file (TOML)")
    p.add_argument("--output", "-o", type=Path, help="URDF path (default: stdout)")
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``build-urdf``; return the exit status (0)."""
    text = build_urdf(args.params)
    if args.output is None:
        sys.stdout.write(text)
    else:
        args.output.write_text(text)
        print(f"wrote {args.output}")
    return status.OK
