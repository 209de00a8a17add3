"""Every figure of one or more results into a folder: :func:`save_all`, or in a forked
process while the caller goes on: :func:`start_save_all`.

The figures are drawn at once on the cores available (:func:`adept_traj.problem.available_cores`):
the calling process draws one share, worker processes the others
(:class:`~adept_traj.process_pool.Worker`: they inherit the results and matplotlib,
nothing is pickled). An error of a worker is raised in the caller (the same exception,
with the worker's traceback as a note); a worker that dies without a word (killed) has its
figures drawn again by the caller.

``adept-traj plan`` starts its figures with :func:`start_save_all` as soon as the run's
result exists and writes ``result.json`` and ``playback.html`` meanwhile: the same files.
An error in the worker is raised by :meth:`BackgroundFigures.wait` in the caller, never
swallowed; a worker that dies without a word has its figures drawn again by the caller.
"""

from __future__ import annotations

import gc
import os
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from functools import partial
from pathlib import Path
from typing import Any

from adept_traj.errors import InvalidInputError, WorkerDiedError
from adept_traj.problem import available_cores
from adept_traj.process_helper import Helper
from adept_traj.process_pool import Channel, Worker, can_fork
from adept_traj.results import PlanningResult, Replay
from adept_traj.validation import as_integer, check_type
from adept_traj.viz.inputs import replay_for
from adept_traj.viz.plots.common import as_results, file_suffix, load_matplotlib
from adept_traj.viz.plots.fronts import pareto_matrix
from adept_traj.viz.plots.history import hypervolume_history
from adept_traj.viz.plots.motion import joint_motion
from adept_traj.viz.plots.tool_path import tool_path_3d
from adept_traj.viz.plots.tradeoffs import best_tradeoffs

__all__ = [
    "BackgroundFigures",
    "Job",
    "draw_jobs",
    "figure_jobs",
    "has_front_figures",
    "save_all",
    "start_save_all",
]

#: The note before a worker's traceback on its error.
_NOTE = "raised while drawing the figures in a forked process"


def save_all(
    results: Mapping[str, PlanningResult] | PlanningResult,
    folder: str | os.PathLike[str],
    *,
    replays: Mapping[str, Replay] | None = None,
    processes: int | None = None,
) -> list[Path]:
    """Write every figure into ``folder`` (created if needed).

    Files: ``pareto_matrix.png`` and ``best_tradeoffs.png`` (left out when the results
    hold one front member in all, e.g. one time-optimal move: there is no trade-off to
    show), ``hypervolume_history.png`` (left out when no result has a history) for all
    results together, and per result ``joint_motion_<name>.png`` and
    ``tool_path_<name>.png`` (``<name>``: the mapping key, characters other than letters,
    digits, ``_ . -`` replaced by ``_``).

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
    jobs, paths, n_proc = figure_jobs(results, folder, replays, processes)
    draw_jobs(jobs, n_proc)
    return paths


#: A figure to draw: (cost weight, drawing with its path bound).
Job = tuple[float, Callable[[], Path]]


def figure_jobs(
    results: Any, folder: Any, replays: Any, processes: Any
) -> tuple[list[Job], list[Path], int]:
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
    figures: list[tuple[float, Path, Callable[[Path], Path]]] = []
    if has_front_figures(res):
        figures.append((2.2, root / "pareto_matrix.png", partial(pareto_matrix, res)))
        figures.append((1.5, root / "best_tradeoffs.png", partial(best_tradeoffs, res)))
    if any(r.history for r in res.values()):
        figures.append((1.0, root / "hypervolume_history.png", partial(hypervolume_history, res)))
    for key, r in res.items():
        figures.append((3.5, root / f"joint_motion_{suffixes[key]}.png", partial(joint_motion, r)))
        draw_path = partial(tool_path_3d, r, replay=given.get(key))
        figures.append((5.0, root / f"tool_path_{suffixes[key]}.png", draw_path))
    jobs = [(weight, partial(draw, path)) for weight, path, draw in figures]
    return jobs, [path for _, path, _ in figures], n_proc


def has_front_figures(results: Mapping[str, PlanningResult]) -> bool:
    """Whether :func:`save_all` draws ``pareto_matrix.png`` and ``best_tradeoffs.png`` for
    ``results`` (``{name: PlanningResult}``): when they hold more than one front member in
    all (one member has no trade-off to show)."""
    return sum(len(r.front) for r in results.values()) > 1


def draw_jobs(jobs: list[Job], processes: int) -> None:
    """Run the figure ``jobs`` (cost weight, drawing) on up to ``processes`` processes (this
    one and worker processes), the heaviest first, each to the least loaded process.

    Raises
    ------
    Exception
        A drawing's error (a worker's with its traceback as a note); a worker that died
        without a word has its share drawn again here.
    """
    processes = min(processes, len(jobs))
    if processes == 1 or not can_fork():
        with _frozen_heap():
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
    workers: list[Worker] = []
    try:
        for share in shares[1:]:
            workers.append(Worker(_draw_share, [jobs[i][1] for i in share], note=_NOTE))
        with _frozen_heap():
            for i in shares[0]:
                jobs[i][1]()
        for worker, share in zip(workers, shares[1:]):
            try:
                worker.recv()
            except WorkerDiedError:  # killed: drawn again here
                for i in share:
                    jobs[i][1]()
    finally:
        for worker in workers:
            worker.close()


def _draw_share(channel: Channel, draws: list[Callable[[], Path]]) -> None:
    """A worker: draw these figures, then say so."""
    with _frozen_heap():
        for draw in draws:
            draw()
    channel.send(None)


@contextmanager
def _frozen_heap() -> Iterator[None]:
    """The objects alive on entry moved out of the garbage collector's reach
    (:func:`gc.freeze`) until the block ends: the collections that the figures' many new
    matplotlib objects trigger then scan these objects only, not the whole heap (the
    robot, the results, numpy and matplotlib themselves). Garbage of the block is
    collected as usual. A caller that froze objects itself keeps its freeze: nothing is
    frozen or unfrozen then (:func:`gc.unfreeze` would release the caller's objects too)."""
    if gc.get_freeze_count():
        yield
        return
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


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
    jobs, paths, n_proc = figure_jobs(results, folder, replays, processes)
    return BackgroundFigures(jobs, paths, n_proc)


class BackgroundFigures(Helper):
    """The figures being drawn in a worker process (made by :func:`start_save_all`).

    Attributes
    ----------
    paths: the files being written, in the order :func:`~adept_traj.viz.plots.save_all`
        returns them.
    """

    def __init__(self, jobs: list[Job], paths: list[Path], processes: int) -> None:
        self.paths = list(paths)
        self._jobs, self._processes = jobs, processes
        self._worker: Worker | None = None
        if can_fork():
            self._worker = Worker(_draw_all, jobs, processes, note=_NOTE)

    def wait(self) -> list[Path]:
        """Wait until every figure is written; return their paths.

        Raises
        ------
        Exception
            The error that stopped the worker (or the caller's own attempt, if the worker
            was killed), with the worker's traceback as a note.
        """
        if self._worker is None:
            draw_jobs(self._jobs, self._processes)
            return list(self.paths)
        worker, self._worker = self._worker, None
        try:
            worker.recv()
        except WorkerDiedError:  # the worker ended without a word (killed): drawn here
            draw_jobs(self._jobs, 1)
        finally:
            worker.close()
        return list(self.paths)

    def cancel(self) -> None:
        """Stop the drawing (a no-op once :meth:`wait` has returned): the worker is killed
        and reaped; files it has finished stay (each is written atomically)."""
        super().cancel()
        self._worker = None


def _draw_all(channel: Channel, jobs: list[Job], processes: int) -> None:
    """The worker of :class:`BackgroundFigures`: draw, then say so."""
    draw_jobs(jobs, processes)
    channel.send(None)
