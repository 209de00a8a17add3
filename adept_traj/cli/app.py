"""The ``adept-traj`` command: its argument parser, :func:`main` and error handling.

Sub-commands, one module each:

- ``adept-traj plan --out DIR`` (:mod:`adept_traj.cli.plan`) — plan on a scene (default:
  the paper's), verify the best trade-off densely and save the result folder; Ctrl-C
  checkpoints, ``--resume DIR`` continues.
- ``adept-traj compare --out DIR`` (:mod:`adept_traj.cli.compare`) — NSGA-II and MODE on
  the same problem, with the paper's Tables 3–5 beside ours (``DIR/comparison.md``).
- ``adept-traj cycle FILE --out DIR`` (:mod:`adept_traj.cli.cycle`) — plan every move of
  a cycle file, each move a Dask task (local cluster or ``--scheduler``).
- ``adept-traj verify DIR`` (:mod:`adept_traj.cli.verify`) — re-run the dense
  verification of a saved result.
- ``adept-traj front DIR`` (:mod:`adept_traj.cli.front`) — list the members of a saved
  front (objectives, f_c, F_avg, certified), sorted by any column, to pick one.
- ``adept-traj export DIR`` (:mod:`adept_traj.cli.export`) — write a front member at a
  fixed time step for a controller (CSV, ROS ``JointTrajectory`` JSON or YAML).
- ``adept-traj show DIR`` (:mod:`adept_traj.cli.show`) — play a saved result in the
  browser (meshcat, 127.0.0.1); ``--member N`` plays another member of the front.
- ``adept-traj robot`` (:mod:`adept_traj.cli.robot`) — the robot-model demo (torques and
  manipulability along a move).
- ``adept-traj build-urdf PARAMS --output URDF`` (:mod:`adept_traj.cli.build_urdf`) —
  regenerate a URDF from a parameter file.

A negative number may follow its option as a word of its own (``--start -1.2,0.3,…``).

Bad input never prints a traceback: the command exits with status 2 and a one-line reason.
Ctrl-C that a command does not handle itself (e.g. while the problem is built) exits with
status 130 and one line, without a traceback.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import json
import re
import sys
import threading
from collections.abc import Callable, Sequence
from typing import NoReturn

from adept_traj.cli import status
from adept_traj.errors import AdeptTrajError
from adept_traj.frozen_imports import frozen_imports

__all__ = ["main", "run"]

_DESCRIPTION = "Multi-objective, collision-free trajectory planning of industrial robots."

#: Each command's module (``add_parser(sub)`` declares it, ``run(args)`` runs it) and its
#: line in ``adept-traj --help``. Only the module of the command given is imported: the
#: listing of ``adept-traj --help`` loads none of them (nor pinocchio, coal or pymoo).
#: Each module's own ``help=`` is the same line (tests/cli/test_cli_startup.py checks it).
_COMMANDS = {
    "plan": ("plan", "plan a trajectory and save a verified result"),
    "compare": ("compare", "NSGA-II vs MODE: the paper's Tables 3-5"),
    "cycle": ("cycle", "plan every move of a cycle file (TOML) on Dask"),
    "show": ("show", "play a saved result in the browser (meshcat) and serve its explorer"),
    "verify": ("verify", "re-run the dense verification of a saved result"),
    "front": ("front", "list the members of a saved front (to pick one)"),
    "export": ("export", "write a front member for a controller (CSV, ROS)"),
    "robot": ("robot", "robot-model demo: torques and manipulability"),
    "build-urdf": ("build_urdf", "write a URDF from a robot parameter file"),
}


#: A negative number or a comma-separated list of numbers starting with one (``-1.2,0.3``,
#: ``-1e-3``): argparse takes such a word for an option unless it is a plain number.
_NEGATIVE_NUMBERS = re.compile(
    r"-(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?:,\s*[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)*"
)


def negative_values_attached(argv: Sequence[str]) -> list[str]:
    """``argv`` with every long option followed by a negative number (list) written as one
    word, ``--start -1.2,0.3`` → ``--start=-1.2,0.3``, so that argparse reads the numbers as
    the option's value (it reads ``-1.2,0.3`` as an unknown option otherwise)."""
    out: list[str] = []
    for arg in argv:
        if (
            out
            and _NEGATIVE_NUMBERS.fullmatch(arg)
            and out[-1].startswith("--")
            and "=" not in out[-1]
            and out[-1] != "--"
        ):
            out[-1] = f"{out[-1]}={arg}"
        else:
            out.append(arg)
    return out


def _selected(argv: Sequence[str]) -> str | None:
    """The command named in ``argv`` (its first argument that is not an option), if any."""
    for arg in argv:
        if not arg.startswith("-"):
            return arg if arg in _COMMANDS else None
    return None


def _parser(
    selected: str | None,
) -> tuple[argparse.ArgumentParser, dict[str, Callable[[argparse.Namespace], int]]]:
    """The parser of every command; only ``selected``'s module is imported and declares its
    options (the others are listed by name and help line)."""
    parser = argparse.ArgumentParser(prog="adept-traj", description=_DESCRIPTION)
    sub = parser.add_subparsers(dest="command", required=True)
    runs = {}
    for name, (module_name, help_line) in _COMMANDS.items():
        if name == selected:
            module = importlib.import_module(f"adept_traj.cli.{module_name}")
            module.add_parser(sub)
            runs[name] = module.run
        else:
            sub.add_parser(name, help=help_line)
    return parser, runs


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``adept-traj``.

    Parameters
    ----------
    argv: the arguments after the program name (default: ``sys.argv[1:]``).

    Returns
    -------
    The exit status (:mod:`adept_traj.cli.status`): 0 success, 2 bad input (one line on
    standard error), 130 interrupted, and the command's own statuses.
    """
    argv = negative_values_attached(sys.argv[1:] if argv is None else list(argv))
    return _dispatch(argv, *_parser(_selected(argv)))


def _dispatch(
    argv: list[str],
    parser: argparse.ArgumentParser,
    runs: dict[str, Callable[[argparse.Namespace], int]],
) -> int:
    """Parse ``argv`` and run its command, its errors turned into exit statuses."""
    args = parser.parse_args(argv)
    try:
        return runs[args.command](args)
    except (AdeptTrajError, OSError, json.JSONDecodeError) as exc:
        print(f"adept-traj: error: {exc}", file=sys.stderr)
        return status.BAD_INPUT
    except KeyboardInterrupt:
        print(f"adept-traj: {args.command} interrupted", file=sys.stderr)
        return status.INTERRUPTED


def run() -> NoReturn:
    """The ``adept-traj`` program: what :func:`main` does, then the end of the process
    with the command's status (``SystemExit``).

    The interpreter's normal exit follows: threads still running are waited for, the exit
    handlers run (:mod:`atexit`: e.g. the worker processes are reaped), the standard
    streams are flushed. With no other thread running, the cyclic garbage collector is
    first stopped and every object frozen (:func:`gc.freeze`), so that the exit does not
    walk every object of numpy, pinocchio and coal once more: the system frees them at
    once.

    The selected command's module and what it imports are imported with the collector
    off and then frozen (:func:`~adept_traj.frozen_imports.frozen_imports`): they live as
    long as the process, and no collection of the run scans them. (:func:`main`, which a
    caller may call in its own process, leaves the collector alone.)
    """
    argv = negative_values_attached(sys.argv[1:])
    with frozen_imports():
        parser, runs = _parser(_selected(argv))
    code = _dispatch(argv, parser, runs)
    if not any(t is not threading.main_thread() and not t.daemon for t in threading.enumerate()):
        gc.disable()
        gc.freeze()
    raise SystemExit(code)
