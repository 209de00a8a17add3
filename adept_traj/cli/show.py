"""``adept-traj show DIR``: play a saved result in the browser (meshcat on 127.0.0.1, in a
page with the member's label, the legend, play/pause, a scrubber and a time read-out:
:func:`~adept_traj.viz.meshcat_scene.live_html`), and serve beside it, on 127.0.0.1 too
(:class:`~adept_traj.viz.page_server.PageServer`), the
folder's front explorer (``explorer.html``, written first when missing) and the playback
page of the member shown (the page ``plan`` writes as ``playback.html``: label, legend,
play/pause, scrubber and time read-out), at ``http://127.0.0.1:PORT/explorer.html`` and
``…/playback.html``.

``--member N`` plays member N of the front (the index of ``adept-traj front DIR``) instead
of the best trade-off; an uncertified member
(:func:`~adept_traj.results.certified_members`) is refused unless ``--allow-infeasible``,
and a member out of range is refused, both before the server starts (exit status 2).
Without ``--member`` the best trade-off is played, certified or not, as before.
``--robot URDF [--params TOML] [--srdf FILE] [--tool-frame NAME] [--package-dir DIR]``
give the robot instead of the recorded files (moved, or meshes elsewhere); it must be the
recorded robot (:mod:`adept_traj.cli.result_robot`), else exit status 2, before the
server starts.

Loops until stopped. Ctrl-C (SIGINT) stops the meshcat server and exits with status 0;
SIGTERM (``kill``, a supervisor, a CI timeout) does the same and exits with status 143
(128 + 15, the shell's code for a process ended by SIGTERM), so that the caller still
sees that the command was terminated. The server is a process of its own: without this
it would outlive a terminated command.
"""

from __future__ import annotations

import argparse
import signal
import threading
import time
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, NoReturn

from adept_traj.cli import status
from adept_traj.cli.result_options import add_member_option, add_result_folder
from adept_traj.cli.result_robot import add_result_robot_arguments, result_robot
from adept_traj.errors import InvalidInputError
from adept_traj.results import PlanningResult, Replay, certified_members, member_index

if TYPE_CHECKING:  # pragma: no cover - for type checkers only
    from adept_traj.viz.page_server import PageServer

#: The names of the pages served beside meshcat (those of a result folder's files).
EXPLORER_PAGE = "explorer.html"
PLAYBACK_PAGE = "playback.html"

__all__ = ["add_parser", "run"]


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``show`` and its options."""
    p = sub.add_parser(
        "show", help="play a saved result in the browser (meshcat) and serve its explorer"
    )
    add_result_folder(p)
    p.add_argument("--speed", type=float, default=1.0, help="playback speed factor")
    p.add_argument("--closest", action="store_true", help="draw the closest-point segment")
    p.add_argument("--open", action="store_true", help="open the page in a web browser")
    add_member_option(p, "play")
    p.add_argument(
        "--allow-infeasible",
        action="store_true",
        help="with --member: play the member even if it is not certified",
    )
    add_result_robot_arguments(p)
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``show`` until Ctrl-C (exit status 0) or SIGTERM (exit status 143)."""
    terminated: list[int] = []

    def on_sigterm(signum: int, frame: FrameType | None) -> None:
        signal.signal(signal.SIGTERM, signal.SIG_IGN)  # one is enough: let close() finish
        terminated.append(signum)
        raise KeyboardInterrupt

    in_main_thread = threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGTERM, on_sigterm) if in_main_thread else None
    try:
        _play(args)
    except KeyboardInterrupt:
        return status.TERMINATED if terminated else status.OK
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _explorer(folder: Path, result: PlanningResult, replay: Replay | None) -> Path:
    """The folder's ``explorer.html``, written first when missing (a folder of an earlier
    version, or ``plan --no-html``)."""
    from adept_traj.viz.explorer import EXPLORER_FILE, write_explorer

    page = folder / EXPLORER_FILE
    if not page.is_file():
        robot, scene = (None, None) if replay is None else (replay.robot, replay.scene)
        write_explorer(result, page, robot=robot, scene=scene)
    return page


def _play(args: argparse.Namespace) -> NoReturn:
    """Start the server and play until interrupted; the server is closed on the way out."""
    from adept_traj.viz import server

    result = PlanningResult.load(args.folder)
    index = member_index(result, args.member)
    certified = bool(certified_members(result)[index])
    if args.member is not None and not certified and not args.allow_infeasible:
        raise InvalidInputError(
            f"member {index} of the front is not certified (adept-traj front "
            f"{args.folder}); pass --allow-infeasible to play it anyway"
        )
    robot = result_robot(args, result)
    replay = None if robot is None else Replay.of(result, result.front.x[index], robot=robot)
    vis = server.show(  # closes its own server if interrupted while starting
        result,
        replay=replay,
        speed=args.speed,
        show_closest=args.closest,
        open_browser=args.open,
        member=index,
    )
    pages = None
    try:  # the URLs are printed inside: a Ctrl-C right after them must still stop cleanly
        pages = _serve_pages(args, result, replay, index)
        which = "best trade-off" if index == result.best.index else "member"
        label = f"{which} {index}, {'certified' if certified else 'NOT CERTIFIED'}"
        print(f"front explorer (any member): {pages.url(EXPLORER_PAGE)}")
        print(f"playback page (time read-out, scrubber): {pages.url(PLAYBACK_PAGE)}")
        print(
            f"playing {args.folder} ({label}) at {vis.url()} (live meshcat viewer: label, "
            "legend, play/pause, scrubber; Ctrl-C to stop)",
            flush=True,
        )
        while True:
            time.sleep(1.0)
    finally:
        if pages is not None:
            pages.close()
        vis.close()


def _serve_pages(
    args: argparse.Namespace, result: PlanningResult, replay: Replay | None, index: int
) -> PageServer:
    """Serve the folder's explorer and the member's playback page on 127.0.0.1."""
    from adept_traj.viz.meshcat_scene import result_page
    from adept_traj.viz.page_server import PageServer

    explorer = _explorer(args.folder, result, replay).read_bytes()
    playback = result_page(
        result, speed=args.speed, show_closest=args.closest, replay=replay, member=index
    )
    return PageServer({EXPLORER_PAGE: explorer, PLAYBACK_PAGE: playback})
