"""Every figure of one or more results into a folder: :func:`save_all`, or in a forked
process while the caller goes on: :func:`start_save_all`.

The figures are drawn at once on the cores available (:func:`adept_traj.problem.available_cores`):
the calling process draws one share, forked processes the others (Linux ``fork``: they
inherit the results and matplotlib, nothing is pickled). A figure whose process fails (or
is killed) is drawn again by the caller, so that its error, if any, is raised there.

``adept-traj plan`` starts its figures with :func:`start_save_all` as soon as the run's
result exists and writes ``result.json`` and ``playback.html`` meanwhile: the same files.
An error in the forked process is raised by :meth:`BackgroundFigures.wait` in the caller
(the same exception, with the forked process' traceback as a note), never swallowed; a
process that dies without a word (killed) has its figures drawn again by the caller.
"""

from __future__ import annotations

import multiprocessing
import os
import pickle
import signal
from collections.abc import Callable, Mapping
from functools import partial
from pathlib import Path
from typing import Any

from adept_traj.errors import FigureError, InvalidInputError
from adept_traj.problem import available_cores
from adept_traj.processes import end_with_parent, error_report, stop_on_sigterm
from adept_traj.results import PlanningResult, Replay
from adept_traj.validation import as_integer, check_type
from adept_traj.viz.inputs import replay_for
from adept_traj.viz.plots.common import as_results, file_suffix, load_matplotlib
from adept_traj.viz.plots.fronts import pareto_matrix
from adept_traj.viz.plots.history import hypervolume_history
from adept_traj.viz.plots.motion import joint_motion
from adept_traj.viz.plots.tool_path import tool_path_3d
from adept_traj.viz.plots.tradeoffs import best_tradeoffs

__all__ = ["BackgroundFigures", "save_all", "start_save_all"]


def save_all(
    results: Mapping[str, PlanningResult] | PlanningResult,
    folder: str | os.PathLike[str],
    *,
    replays: Mapping[str, Replay] | None = None,
    processes: int | None = None,
) -> list[Path]:
    """Write every figure into ``folder`` (created if needed).

    Files: ``pareto_matrix.png``, ``best_tradeoffs.png``, ``hypervolume_history.png``
    (left out when no result has a history) for all results together, and per result
    ``joint_motion_<name>.png`` and ``tool_path_<name>.png`` (``<name>``: the mapping key,
    characters other than letters, digits, ``_ . -`` replaced by ``_``).

    Parameters
    ----------
    results: ``{name: PlanningResult}`` (at most six), or one result (named by its
        algorithm).
    folder: where the PNG files go.
    replays: ``{name: Replay}`` for the results whose
        :class:`~adept_traj.results.Replay` (robot and scene) the caller already has, each
        of its result's best solution; the others are built with ``Replay.of(result)``
        (for :func:`~adept_traj.viz.plots.tool_path_3d`).
    processes: processes drawing at once, ≥ 1 (default: the cores available; 1 draws
        every figure in the calling process). The files are the same either way.

    Returns
    -------
    The paths written, in that order.
    """
    jobs, paths, n_proc = _figure_jobs(results, folder, replays, processes)
    _draw(jobs, n_proc)
    return paths


#: A figure to draw: (cost weight, drawing with its path bound).
_Job = tuple[float, Callable[[], Path]]


def _figure_jobs(
    results: Any, folder: Any, replays: Any, processes: Any
) -> tuple[list[_Job], list[Path], int]:
    """The arguments of :func:`save_all`, checked (nothing is drawn; ``folder`` is
    created): the figures to draw, their paths in order and the number of processes."""
    res = as_results(results)
    try:
        root = Path(os.fspath(folder))
    except TypeError:
        raise InvalidInputError(f"folder must be a path; got {type(folder).__name__}") from None
    suffixes = {key: file_suffix(key) for key in res}
    if len(set(suffixes.values())) != len(suffixes):
        raise InvalidInputError(f"result names give clashing file names: {list(res)}")
    given = _replays(replays, res)
    n_proc = available_cores() if processes is None else processes
    n_proc = as_integer(n_proc, "processes", minimum=1)
    root.mkdir(parents=True, exist_ok=True)
    # (cost weight, file, drawing): the weights (CPU times per figure on the paper's
    # result [0.1 s], each drawn first in a fresh process) spread the figures evenly over
    # the processes: on two, the tool path and the best trade-offs, and the rest
    figures: list[tuple[float, Path, Callable[[Path], Path]]] = [
        (2.2, root / "pareto_matrix.png", partial(pareto_matrix, res)),
        (1.5, root / "best_tradeoffs.png", partial(best_tradeoffs, res)),
    ]
    if any(r.history for r in res.values()):
        figures.append((1.0, root / "hypervolume_history.png", partial(hypervolume_history, res)))
    for key, r in res.items():
        figures.append((3.5, root / f"joint_motion_{suffixes[key]}.png", partial(joint_motion, r)))
        draw_path = partial(tool_path_3d, r, replay=given.get(key))
        figures.append((5.0, root / f"tool_path_{suffixes[key]}.png", draw_path))
    jobs = [(weight, partial(draw, path)) for weight, path, draw in figures]
    return jobs, [path for _, path, _ in figures], n_proc


def _draw(jobs: list[_Job], processes: int) -> None:
    """Run the figure ``jobs`` (cost weight, drawing) on up to ``processes`` processes (this
    one included), the heaviest first, each to the least loaded process."""
    processes = min(processes, len(jobs))
    if processes == 1 or "fork" not in multiprocessing.get_all_start_methods():
        for _, draw in jobs:
            draw()
        return
    load_matplotlib()  # imported once, before the fork, for every process
    shares: list[list[int]] = [[] for _ in range(processes)]
    loads = [0.0] * processes
    for i in sorted(range(len(jobs)), key=lambda i: -jobs[i][0]):  # longest first
        k = loads.index(min(loads))
        shares[k].append(i)
        loads[k] += jobs[i][0]
    context = multiprocessing.get_context("fork")
    children = [
        context.Process(target=_draw_share, args=([jobs[i][1] for i in share],), daemon=True)
        for share in shares[1:]
    ]
    try:
        for child in children:
            child.start()
        for i in shares[0]:
            jobs[i][1]()
        for child, share in zip(children, shares[1:]):
            child.join()
            if child.exitcode != 0:  # drawn again here: its error, if any, is raised here
                for i in share:
                    jobs[i][1]()
    finally:
        for child in children:
            if child.is_alive():
                child.terminate()
                child.join()


def _draw_share(draws: list[Callable[[], Path]]) -> None:
    """Run in a forked process: draw these figures; any error ends it with status 1 (the
    caller draws its figures again and reports the error). It ends with its parent (a
    parent stopped outright cannot terminate it)."""
    end_with_parent()
    try:
        for draw in draws:
            draw()
    except BaseException:  # reported by the caller's second attempt
        os._exit(1)


def _replays(replays: Any, results: Mapping[str, PlanningResult]) -> dict[str, Replay]:
    """The caller's replays by result name, checked before anything is drawn."""
    if replays is None:
        return {}
    check_type(replays, Mapping, "replays")
    unknown = [key for key in replays if key not in results]
    if unknown:
        raise InvalidInputError(f"replays names no result: {unknown}; results: {list(results)}")
    return {key: replay_for(results[key], value) for key, value in replays.items()}


# ============================================================================ in the background
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
    :class:`~adept_traj.errors.FigureError` holding ``text`` if it does not unpickle."""
    try:
        error = pickle.loads(pickled) if pickled is not None else None
    except Exception:  # e.g. an exception class whose __init__ needs other arguments
        error = None
    if not isinstance(error, BaseException):
        return FigureError(f"drawing the figures failed in a forked process:\n{text}")
    error.add_note(f"raised while drawing the figures in a forked process:\n{text}")
    return error


def _child(jobs: list[_Job], processes: int, sender: Any) -> None:
    """In the forked process: draw, send ``("", None)`` or (the error's traceback, the
    pickled error or ``None``), and end at once (``os._exit``: none of the parent's exit
    handlers runs here)."""
    signal.signal(signal.SIGTERM, stop_on_sigterm)  # cancel
    code, text, pickled = 0, "", None
    try:
        _draw(jobs, processes)
    except BaseException as exc:  # every error is sent to the caller, which raises it
        code = 1
        text, pickled = error_report(exc)
    try:
        sender.send((text, pickled))
        sender.close()
    finally:
        os._exit(code)
