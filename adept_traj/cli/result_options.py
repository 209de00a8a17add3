"""The options of the commands on a saved result (``export``, ``front``, ``show``): its
folder and the front member a command takes."""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["add_member_option", "add_result_folder"]


def add_result_folder(parser: argparse.ArgumentParser) -> None:
    """Declare the positional ``folder``: the result folder (with ``result.json``)."""
    parser.add_argument("folder", type=Path, help="result folder (with result.json)")


def add_member_option(parser: argparse.ArgumentParser, verb: str) -> None:
    """Declare ``--member N``: the front member the command takes (default: the best
    trade-off), its help beginning with ``verb`` (what the command does with it, e.g.
    ``"play"``)."""
    parser.add_argument(
        "--member",
        type=int,
        help=f"{verb} member N of the front (see adept-traj front DIR; default: the best "
        "trade-off)",
    )
