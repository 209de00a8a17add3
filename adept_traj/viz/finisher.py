"""The end of a run written by a helper process prepared while the run goes on:
:func:`start_finisher`, :class:`Finisher`.

A run's figures and ``playback.html`` need matplotlib and meshcat, whose imports
used to come after the optimiser. :func:`start_finisher` forks a helper process (a
:class:`~adept_traj.process_pool.Worker`) from the caller once the robot and scene
exist; a thread of the helper imports the drawing modules at the lowest priority (nice
19: it runs while a core idles and never takes one from the optimiser), and the helper
then waits. :meth:`Finisher.start` hands it the finished results over a pipe (pickled: about
0.4 MB for the paper run); the helper builds each
:class:`~adept_traj.results.Replay` from the robot and scene it inherited (nothing is
reloaded) and writes the figures (:func:`adept_traj.viz.plots.save_all`, its second
share in its own fork) and the page (:func:`adept_traj.viz.meshcat_scene.static_html`),
at the caller's priority, while the caller saves the result. The files are those the
caller would write itself, byte for byte.

The helper never outlives the caller (:mod:`adept_traj.process_pool`): it ignores Ctrl-C
(the caller stops it), :meth:`Finisher.cancel` (or leaving the ``with`` block) kills and
reaps it, and it ends with the caller however the caller ends. An error of the helper is
raised by :meth:`Finisher.wait` in the caller (the same exception, with the helper's
traceback as a note); a helper that dies without a word has its work done again by the
caller. A helper that has not finished its imports when the run ends (a machine too
busy to lend it a core) has them raised to the caller's priority and is waited for, a
bounded time; where the system does not allow that, or the bound passes, it is not used:
:meth:`Finisher.start` stops it and returns ``False``, and the caller writes the files
itself.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from functools import partial
from pathlib import Path
from typing import Any

from adept_traj.errors import InvalidInputError, WorkerDiedError
from adept_traj.frozen_imports import frozen_imports
from adept_traj.process_helper import Helper
from adept_traj.process_pool import LOWEST_PRIORITY, Channel, Worker, can_fork
from adept_traj.results import PlanningResult, Replay
from adept_traj.robot import Robot
from adept_traj.scene import Scene
from adept_traj.validation import check_type
from adept_traj.viz.inputs import as_result

__all__ = ["Finisher", "start_finisher"]

#: Niceness of the helper's importing thread (the lowest priority).
IMPORT_NICENESS = LOWEST_PRIORITY
#: How long :meth:`Finisher.start` waits for the helper's imports to end [s] at their
#: lowest priority (0: not at all).
READY_TIMEOUT = 0.0
#: How long :meth:`Finisher.start` waits for imports still under way once they are raised
#: to the caller's priority (:meth:`~adept_traj.process_pool.Worker.hurry`) [s]: a bound;
#: the rest of the imports takes a fraction of it on a free core, and redoing them in
#: the caller would take as long.
HURRIED_TIMEOUT = 3.0
#: Cost weight of ``playback.html`` on the scale of the figures' weights (their relative
#: CPU costs, :func:`~adept_traj.viz.plots.all_figures.figure_jobs`).
_HTML_WEIGHT = 0.3


def start_finisher(
    robot: Robot, scene: Scene, *, figures: bool, html: bool, urgent: bool = False
) -> Finisher:
    """Fork the helper that will write a run's figures and/or ``playback.html``.

    Call it once the run's robot and scene exist (as early as that: the imports overlap
    the rest of the run's setup); the helper imports what the outputs need at nice
    :data:`IMPORT_NICENESS` (``urgent``: at the caller's) and waits for
    :meth:`Finisher.start`. Without ``fork`` (not Linux) no helper starts:
    :meth:`Finisher.start` returns ``False``.

    Parameters
    ----------
    robot, scene: the run's robot and scene (the helper builds its replays from them).
    figures: the helper will draw the figures (imports matplotlib).
    html: the helper will write ``playback.html`` (imports meshcat).
    urgent: the run will end soon (e.g. the time-optimal mode, whose search is shorter
        than these imports): they share the cores with it from the start, instead of
        taking only idle time and being raised at the end (:data:`HURRIED_TIMEOUT`).

    Raises
    ------
    InvalidInputError
        ``robot`` or ``scene`` of the wrong type, or neither output asked for.
    """
    check_type(robot, Robot, "robot")
    check_type(scene, Scene, "scene")
    if not (figures or html):
        raise InvalidInputError("start_finisher needs figures=True or html=True; got neither")
    return Finisher(robot, scene, figures=bool(figures), html=bool(html), urgent=bool(urgent))


class Finisher(Helper):
    """The helper process forked by :func:`start_finisher`; a context manager that stops
    it when the block is left.

    Attributes
    ----------
    pid : int or None
        The helper's process id (``None`` without one, or once it is reaped).
    """

    def __init__(
        self, robot: Robot, scene: Scene, *, figures: bool, html: bool, urgent: bool = False
    ) -> None:
        self._robot, self._scene = robot, scene
        self._figures, self._html = figures, html
        self._order: tuple | None = None
        self._worker: Worker | None = None
        if can_fork():
            self._worker = Worker(
                _helper,
                robot,
                scene,
                prepare=partial(_preload, figures, html),
                prepare_niceness=None if urgent else IMPORT_NICENESS,
                note="raised while writing the figures and page in a worker process",
            )

    def _ready_now(self) -> bool:
        """Whether the helper is ready: at once, or within :data:`READY_TIMEOUT`, or, with
        its imports raised to this process's priority, within :data:`HURRIED_TIMEOUT`."""
        if self.ready(READY_TIMEOUT):
            return True
        worker = self._worker
        return worker is not None and worker.hurry() and self.ready(HURRIED_TIMEOUT)

    def start(
        self,
        results: Mapping[str, PlanningResult],
        *,
        figures: str | os.PathLike[str] | None = None,
        html: str | os.PathLike[str] | None = None,
    ) -> bool:
        """Hand the finished ``results`` to the helper, if it is ready, and return at once.

        Parameters
        ----------
        results: ``{name: PlanningResult}`` (the figures' legend names, as for
            :func:`~adept_traj.viz.plots.save_all`).
        figures: the folder of the figures (``None``: no figures).
        html: the ``playback.html`` file of the only result (``None``: no page).

        Returns
        -------
        ``True`` if the helper writes them (collect with :meth:`wait`); ``False`` if it was
        not ready (its imports not done within :data:`READY_TIMEOUT`, nor, raised to the
        caller's priority where the system allows, within :data:`HURRIED_TIMEOUT`) or
        cannot do them: it is then stopped, and the caller writes the files itself.
        """
        order = _order(results, figures, html)
        if (order[1] is not None and not self._figures) or (order[2] and not self._html):
            raise InvalidInputError("the helper was started without the output asked for")
        if self._worker is None or not self._ready_now():
            if self._worker is not None:
                self._worker.kill()  # reaped by cancel: a helper at nice 19 may end slowly
            return False
        try:
            self._worker.send(*order)
        except WorkerDiedError:  # died meanwhile: the caller writes the files
            self.cancel()
            return False
        self._order = order
        return True

    def wait(self) -> list[Path]:
        """Wait for the files handed over by :meth:`start`; return the figures' paths (in
        the order of :func:`~adept_traj.viz.plots.save_all`; ``[]`` without figures).

        Raises
        ------
        Exception
            The error that stopped the helper (or the caller's own attempt, if the helper
            died without a word), with the helper's traceback as a note.
        """
        if self._order is None or self._worker is None:
            raise InvalidInputError("Finisher.wait needs a successful Finisher.start first")
        order, self._order = self._order, None
        try:
            paths = self._worker.recv()
        except WorkerDiedError:  # the helper ended without a word (killed): done again here
            return _write(*order, self._robot, self._scene)
        finally:
            self._worker.close()
        return paths


def _order(results: Any, figures: Any, html: Any) -> tuple:
    """(results, figures folder or ``None``, page path or ``None``), checked."""
    check_type(results, Mapping, "results")
    res = {key: as_result(value, f"results[{key!r}]") for key, value in results.items()}
    if not res:
        raise InvalidInputError("results must hold at least one PlanningResult")
    if html is not None and len(res) != 1:
        raise InvalidInputError(f"html is the page of one result; got {len(res)} results")
    if figures is None and html is None:
        raise InvalidInputError("give figures (a folder) or html (a file), or both")
    paths = []
    for value, name in ((figures, "figures"), (html, "html")):
        try:
            paths.append(None if value is None else Path(os.fspath(value)))
        except TypeError:
            raise InvalidInputError(f"{name} must be a path; got {type(value).__name__}") from None
    return res, *paths


def _write(
    results: dict[str, PlanningResult],
    figures: Path | None,
    html: Path | None,
    robot: Robot,
    scene: Scene,
) -> list[Path]:
    """Write the figures into ``figures`` and the page of the only result into ``html``
    on the cores available (the page as one more job of the figures' processes); return
    the figures' paths."""
    from adept_traj.viz.plots.all_figures import draw_jobs, figure_jobs

    replays = {key: Replay.of(r, robot=robot, scene=scene) for key, r in results.items()}
    jobs, paths, processes = [], [], 1
    if figures is not None:
        jobs, paths, processes = figure_jobs(results, figures, replays, None)
    if html is not None:
        (key, result), = results.items()  # fmt: skip
        jobs.append((_HTML_WEIGHT, partial(_page, result, html, replays[key])))
    draw_jobs(jobs, processes)
    return paths


def _page(result: PlanningResult, path: Path, replay: Replay) -> Path:
    """``playback.html`` at ``path`` and the front explorer beside it
    (:data:`~adept_traj.viz.explorer.EXPLORER_FILE`)."""
    from adept_traj.viz.explorer import EXPLORER_FILE, write_explorer
    from adept_traj.viz.meshcat_scene import static_html

    write_explorer(result, path.parent / EXPLORER_FILE, robot=replay.robot, scene=replay.scene)
    return static_html(result, path, replay=replay)


def _preload(figures: bool, html: bool) -> None:
    """Import what the outputs need (matplotlib and the figure modules; meshcat), in the
    helper process, with the collector off and then frozen
    (:func:`~adept_traj.frozen_imports.frozen_imports`: the figures' collections then
    scan none of it)."""
    with frozen_imports():
        if figures:
            import mpl_toolkits.mplot3d  # noqa: F401  (the tool path's 3-D axes)

            from adept_traj.viz.plots.common import load_matplotlib

            load_matplotlib()
        if html:
            import plotly.offline  # noqa: F401  (the explorer's library)

            import adept_traj.viz.explorer
            import adept_traj.viz.meshcat_scene  # noqa: F401


def _helper(channel: Channel, robot: Robot, scene: Scene) -> None:
    """The helper process, once its imports are done: wait for the order (results,
    figures folder, page path), write, send the figures' paths."""
    results, figures_dir, html_path = channel.recv()
    channel.send(_write(results, figures_dir, html_path, robot, scene))
