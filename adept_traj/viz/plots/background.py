"""Every figure drawn in a forked process while the caller goes on: :func:`start_save_all`.

``adept-traj plan`` starts its figures as soon as the run's result exists and writes
``result.json`` and ``playback.html`` meanwhile; the figures are the same files as
:func:`~adept_traj.viz.plots.save_all` writes. An error in the forked process is raised by
:meth:`BackgroundFigures.wait` in the caller: the same exception (with the forked
process' traceback as a note), never swallowed. A process that dies without a word (killed)
has its figures drawn again by the caller, so that their error, if any, is raised there.
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
import signal
import sys
import traceback
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from adept_traj.results import PlanningResult, Replay
from adept_traj.viz.plots.all_figures import _draw, _figure_jobs, _Job

__all__ = ["BackgroundFigures", "start_save_all"]


def start_save_all(
    results: Mapping[str, PlanningResult] | PlanningResult,
    folder: str | os.PathLike[str],
    *,
    replays: Mapping[str, Replay] | None = None,
    processes: int | None = None,
) -> BackgroundFigures:
    """Start writing every figure into ``folder`` in a forked process and return at once.

    The arguments are those of :func:`~adept_traj.viz.plots.save_all`, checked here before
    anything starts (bad ones raise :class:`~adept_traj.errors.InvalidInputError` here);
    the forked process draws on ``processes`` processes (default: the cores available)
    as ``save_all`` does. Without ``fork`` (not Linux) the figures are drawn by
    :meth:`BackgroundFigures.wait`, in the caller.

    Returns
    -------
    The drawing under way: call :meth:`~BackgroundFigures.wait` for the paths (and any
    error), or use it as a context manager, which stops it if the block is left early.
    """
    jobs, paths, n_proc = _figure_jobs(results, folder, replays, processes)
    return BackgroundFigures(jobs, paths, n_proc)


class BackgroundFigures:
    """The figures being drawn in a forked process (made by :func:`start_save_all`).

    Attributes
    ----------
    paths: the files being written, in the order :func:`~adept_traj.viz.plots.save_all`
        returns them.
    """

    def __init__(self, jobs: list[_Job], paths: list[Path], processes: int) -> None:
        self.paths = list(paths)
        self._jobs, self._processes = jobs, processes
        self._process: Any = None
        self._receiver: Any = None
        if "fork" in multiprocessing.get_all_start_methods():
            context = multiprocessing.get_context("fork")
            self._receiver, sender = context.Pipe(duplex=False)
            self._process = context.Process(target=_child, args=(jobs, processes, sender))
            self._process.start()  # (flushes sys.stdout and sys.stderr before the fork)
            sender.close()

    def wait(self) -> list[Path]:
        """Wait until every figure is written; return their paths.

        Raises
        ------
        Exception
            The error that stopped the forked process (or the caller's own attempt, if
            that process was killed), with the forked process' traceback as a note.
        """
        if self._process is None:
            _draw(self._jobs, self._processes)
            return list(self.paths)
        try:
            text, pickled = self._receiver.recv()
        except EOFError:  # the process ended without a word (killed)
            text, pickled = None, None
        except BaseException:  # e.g. Ctrl-C while waiting
            self.cancel()
            raise
        self._process.join()
        self._receiver.close()
        self._process = None
        if text is None:
            _draw(self._jobs, 1)  # drawn again here: its error, if any, is raised here
        elif text:
            raise _error(text, pickled)
        return list(self.paths)

    def cancel(self) -> None:
        """Stop the drawing (a no-op once :meth:`wait` has returned): the forked process is
        terminated and waited for; files it has finished stay (each is written atomically)."""
        if self._process is None:
            return
        self._process.terminate()
        self._process.join()
        self._receiver.close()
        self._process = None

    def __enter__(self) -> BackgroundFigures:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.cancel()


def _error(text: str, pickled: bytes | None) -> BaseException:
    """The forked process' error (unpickled) with its traceback ``text`` as a note; a
    :class:`RuntimeError` holding ``text`` if it does not unpickle."""
    try:
        error = pickle.loads(pickled) if pickled is not None else None
    except Exception:  # e.g. an exception class whose __init__ needs other arguments
        error = None
    if not isinstance(error, BaseException):
        return RuntimeError(f"drawing the figures failed in a forked process:\n{text}")
    error.add_note(f"raised while drawing the figures in a forked process:\n{text}")
    return error


def _child(jobs: list[_Job], processes: int, sender: Any) -> None:
    """In the forked process: draw, send ``("", None)`` or (the error's traceback, the
    pickled error or ``None``), and end at once (``os._exit``: none of the parent's exit
    handlers runs here)."""
    # SIGTERM (cancel) unwinds through the drawing, which stops its own processes
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(128 + signal.SIGTERM))
    code, text, pickled = 0, "", None
    try:
        _draw(jobs, processes)
    except BaseException as exc:  # every error is sent to the caller, which raises it
        code, text = 1, traceback.format_exc()
        try:
            pickled = pickle.dumps(exc)
        except Exception:  # sent as text only
            pickled = None
    try:
        sender.send((text, pickled))
        sender.close()
    finally:
        os._exit(code)
