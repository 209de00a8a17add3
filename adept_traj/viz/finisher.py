"""The end of a run written by a helper process prepared while the run goes on:
:func:`start_finisher`, :class:`Finisher`.

A run's figures and ``playback.html`` need matplotlib and meshcat, whose slow imports
used to come after the optimiser. :func:`start_finisher` forks a helper
process from the caller once the robot and scene exist (before the optimiser's workers);
a thread of the helper imports the drawing modules at the lowest priority (nice 19: it
runs while a core idles and never takes one from the optimiser), and the helper then
waits. :meth:`Finisher.start` hands it the finished results over a pipe (pickled: about
0.4 MB for the paper run); the helper builds each
:class:`~adept_traj.results.Replay` from the robot and scene it inherited (nothing is
reloaded) and writes the figures (:func:`adept_traj.viz.plots.save_all`, its second
share in its own fork) and the page (:func:`adept_traj.viz.meshcat_scene.static_html`),
at the caller's priority, while the caller saves the result. The files are those the
caller would write itself, byte for byte.

The helper never outlives the caller: it ignores Ctrl-C (the caller stops it),
:meth:`Finisher.cancel` (or leaving the ``with`` block) terminates and reaps it, and on
Linux it receives SIGTERM when the caller dies (``PR_SET_PDEATHSIG``), even by SIGKILL.
An error of the helper is raised by :meth:`Finisher.wait` in the caller (the same
exception, with the helper's traceback as a note); a helper that dies without a word has
its work done again by the caller. A helper that has not finished its imports when the
run ends (a machine too busy to lend it a core) is not used: :meth:`Finisher.start`
stops it and returns ``False``, and the caller writes the files itself.
"""

from __future__ import annotations

import os
import signal
from collections.abc import Mapping
from functools import partial
from pathlib import Path
from typing import Any

from adept_traj.errors import InvalidInputError
from adept_traj.processes import (
    LOWEST_PRIORITY,
    READY,
    ForkedHelper,
    end_with_parent,
    error_report,
    prepare_quietly,
    stop_on_sigterm,
)
from adept_traj.results import PlanningResult, Replay
from adept_traj.robot import Robot
from adept_traj.scene import Scene
from adept_traj.validation import check_type
from adept_traj.viz.inputs import as_result

__all__ = ["Finisher", "start_finisher"]

#: Niceness of the helper's importing thread (the lowest priority).
IMPORT_NICENESS = LOWEST_PRIORITY
#: How long :meth:`Finisher.start` waits for the helper's imports to end [s] (0: the
#: helper is used only if it is ready when the run ends).
READY_TIMEOUT = 0.0
#: Cost weight of ``playback.html`` on the scale of the figures' weights [0.1 s CPU].
_HTML_WEIGHT = 0.3


def start_finisher(robot: Robot, scene: Scene, *, figures: bool, html: bool) -> Finisher:
    """Fork the helper that will write a run's figures and/or ``playback.html``.

    Call it once the run's robot and scene exist and before the optimiser's worker
    processes start (forked after them, the helper would hold copies of their pipes, and
    nothing but the evaluator's stop word would end them); the helper imports what the
    outputs need at nice :data:`IMPORT_NICENESS` and waits for :meth:`Finisher.start`.

    Parameters
    ----------
    robot, scene: the run's robot and scene (the helper builds its replays from them).
    figures: the helper will draw the figures (imports matplotlib).
    html: the helper will write ``playback.html`` (imports meshcat).

    Raises
    ------
    InvalidInputError
        ``robot`` or ``scene`` of the wrong type, or neither output asked for.
    """
    check_type(robot, Robot, "robot")
    check_type(scene, Scene, "scene")
    if not (figures or html):
        raise InvalidInputError("start_finisher needs figures=True or html=True; got neither")
    return Finisher(robot, scene, figures=bool(figures), html=bool(html))


class Finisher(ForkedHelper):
    """The helper process forked by :func:`start_finisher`; a context manager that stops
    it when the block is left (:class:`~adept_traj.processes.ForkedHelper`: ``ready``,
    ``cancel``, ``pid``).
    """

    def __init__(self, robot: Robot, scene: Scene, *, figures: bool, html: bool) -> None:
        self._robot, self._scene = robot, scene
        self._figures, self._html = figures, html
        self._order: tuple | None = None
        super().__init__(_helper, (robot, scene, figures, html))

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
        not ready (its imports not done within :data:`READY_TIMEOUT`) or cannot do them:
        it is then stopped, and the caller writes the files itself.
        """
        order = _order(results, figures, html)
        if (order[1] is not None and not self._figures) or (order[2] and not self._html):
            raise InvalidInputError("the helper was started without the output asked for")
        if not self.ready(READY_TIMEOUT):
            self._give_up()
            return False
        try:
            self._conn.send(order)
        except OSError:  # died meanwhile: the caller writes the files
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
        if self._order is None:
            raise InvalidInputError("Finisher.wait needs a successful Finisher.start first")
        message = self._answer()
        order, self._order = self._order, None
        if message is None:  # the helper ended without a word (killed): done again here
            return _write(*order, self._robot, self._scene)
        text, pickled, paths = message
        if text:
            from adept_traj.viz.plots.all_figures import _error

            raise _error(text, pickled)
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
    from adept_traj.viz.plots.all_figures import _draw, _figure_jobs

    replays = {key: Replay.of(r, robot=robot, scene=scene) for key, r in results.items()}
    jobs, paths, processes = [], [], 1
    if figures is not None:
        jobs, paths, processes = _figure_jobs(results, figures, replays, None)
    if html is not None:
        (key, result), = results.items()  # fmt: skip
        jobs.append((_HTML_WEIGHT, partial(_page, result, html, replays[key])))
    _draw(jobs, processes)
    return paths


def _page(result: PlanningResult, path: Path, replay: Replay) -> Path:
    """``playback.html`` at ``path`` and the front explorer beside it
    (:data:`~adept_traj.viz.explorer.EXPLORER_FILE`)."""
    from adept_traj.viz.explorer import EXPLORER_FILE, write_explorer
    from adept_traj.viz.meshcat_scene import static_html

    write_explorer(result, path.parent / EXPLORER_FILE, robot=replay.robot, scene=replay.scene)
    return static_html(result, path, replay=replay)


def _preload(figures: bool, html: bool) -> None:
    """Import what the outputs need (matplotlib and the figure modules; meshcat)."""
    if figures:
        import mpl_toolkits.mplot3d  # noqa: F401  (the tool path's 3-D axes)

        from adept_traj.viz.plots.common import load_matplotlib

        load_matplotlib()
    if html:
        import plotly.offline  # noqa: F401  (the explorer's library)

        import adept_traj.viz.explorer
        import adept_traj.viz.meshcat_scene  # noqa: F401


def _die_with(parent: int) -> None:
    """Ask Linux for SIGTERM when the parent dies (``PR_SET_PDEATHSIG``); end now if it
    is gone already."""
    end_with_parent()
    if os.getppid() != parent:
        os._exit(0)


def _helper(
    conn: Any, callers_end: Any, parent: int, robot: Robot, scene: Scene, figures: bool, html: bool
) -> None:
    """The helper process: import (a thread at nice 19), say ``"ready"``, wait for the
    order, write, send ``(traceback or "", pickled error or None, figure paths)`` and end
    at once (``os._exit``: none of the parent's exit handlers runs here). ``callers_end``
    (the caller's end of the pipe, inherited by the fork) is closed first: the caller's
    death then ends the wait for the order."""
    code = 0
    try:
        callers_end.close()
        signal.signal(signal.SIGTERM, stop_on_sigterm)
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C: the caller stops the helper
        _die_with(parent)
        if prepare_quietly(partial(_preload, figures, html)):  # failed: not ready
            code = 1
            return
        conn.send(READY)
        try:
            results, figures_dir, html_path = conn.recv()
        except EOFError:  # the caller stopped without work for the helper
            return
        text, pickled, paths = "", None, []
        try:
            paths = _write(results, figures_dir, html_path, robot, scene)
        except Exception as exc:  # every error is sent to the caller, which raises it
            code = 1
            text, pickled = error_report(exc)
        conn.send((text, pickled, paths))
        conn.close()
    except BaseException:  # SIGTERM (cancel, the caller's death) or a broken pipe
        code = code or 1
    finally:
        os._exit(code)
