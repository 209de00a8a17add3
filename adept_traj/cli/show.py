"""``adept-traj show DIR``: play a saved result in the browser (meshcat on 127.0.0.1).

Loops until Ctrl-C, which stops the meshcat server and exits with status 0.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from adept_traj.results import PlanningResult

__all__ = ["add_parser", "run"]


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``show`` and its options."""
    p = sub.add_parser("show", help="play a saved result in the browser (meshcat)")
    p.add_argument("folder", type=Path, help="result folder (with result.json)")
    p.add_argument("--speed", type=float, default=1.0, help="playback speed factor")
    p.add_argument("--closest", action="store_true", help="draw the closest-point segment")
    p.add_argument("--open", action="store_true", help="open the page in a web browser")
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``show`` until Ctrl-C; return the exit status (0)."""
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
