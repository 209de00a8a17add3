"""What the planning commands print and draw after a run: the summary and the figures."""

from __future__ import annotations

import contextlib
import importlib.util
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.analysis import WeightedSum
from adept_traj.problem import OBJECTIVES
from adept_traj.results import PlanningResult, Replay
from adept_traj.results.unchecked import unchecked_of
from adept_traj.viz.finisher import start_finisher

__all__ = [
    "MATRIX_FILE",
    "figures_line",
    "finish_figures",
    "finisher_for",
    "objectives_text",
    "save_collision_matrix",
    "save_figures",
    "start_figures",
    "summary",
    "t_best_text",
    "weighted_sum_text",
    "write_page",
]


#: The self-collision matrix ``plan`` saves beside a result when it made one for the robot.
MATRIX_FILE = "collision_matrix.srdf"


def save_collision_matrix(problem: Any, folder: Path) -> Path | None:
    """Write the collision matrix made for ``problem``'s robot (no SRDF and no disabled
    pairs given: :func:`~adept_traj.collision.robot_collision_matrix`) as
    ``folder/collision_matrix.srdf`` (reusable with ``--srdf``) and say so; ``None`` (nothing
    written) when the robot's pairs came from an SRDF or a parameter file, or
    self-collision is off."""
    robot = problem.robot
    if problem.self_check is None or robot.srdf_path is not None or robot.disabled_pairs:
        return None
    from adept_traj.collision import robot_collision_matrix
    from adept_traj.files import write_text_atomic

    if set(problem.settings.disabled_pairs) != set(robot_collision_matrix(robot).always):
        return None  # pairs given by the caller, not the matrix's
    path = write_text_atomic(folder / MATRIX_FILE, robot_collision_matrix(robot).to_srdf())
    print(f"self-collision matrix made for robot '{robot.name}' saved to {path} (--srdf)")
    return path


def t_best_text(result: PlanningResult) -> str:
    """``"T = 1.06 × T_best (1.0766 s by polish)"`` (the best trade-off's z1 over
    ``metrics.t_best`` [s]) or ``"T_best not computed"``."""
    m = result.metrics
    if m.t_best is None:
        return "T_best not computed"
    return f"T = {result.gap_best:.3f} × T_best ({m.t_best:.4f} s by {m.t_best_source})"


def objectives_text(z: np.ndarray) -> str:
    """``"z2 = 3451 N²·m²·s, z3 = 0.0256, …"``: z2…z6 (6,) with their units
    (:data:`~adept_traj.problem.OBJECTIVES`; none where dimensionless)."""
    parts = []
    for value, objective in zip(z[1:], OBJECTIVES[1:]):
        unit = "" if objective.unit == "-" else f" {objective.unit}"
        parts.append(f"{objective.name} = {value:.4g}{unit}")
    return ", ".join(parts)


def weighted_sum_text(result: PlanningResult) -> list[str]:
    """``["weighted sum f_w = … (…)"]`` for a result of the weighted-sum mode (its
    ``algorithm_settings["weighted_sum"]``): the best member's :math:`f_w` and that of the
    fastest certified member (the minimum-T move), with the weights; ``[]`` otherwise."""
    weighted = WeightedSum.from_settings(result.algorithm_settings)
    if weighted is None:
        return []
    f = weighted.values(result.front.objectives)
    ok = np.flatnonzero(result.front.feasible)
    weights = ",".join(f"{w:.4g}" for w in weighted.weights)
    fastest = (
        f"; fastest certified member {f[ok[np.argmin(result.front.objectives[ok, 0])]]:.6f}"
        if len(ok)
        else ""
    )
    return [
        f"weighted sum f_w = {f[result.best.index]:.6f} (weights {weights}, scales of the "
        f"{weighted.reference}{fastest})"
    ]


def summary(result: PlanningResult, folder: Path) -> str:
    """A few lines on a finished run: evaluations, time and evaluation workers, the best
    trade-off's objectives z1 [s] … z6 and its gaps to the kinematic lower bound and to
    T_best (``metrics.t_best``, the best T the local solver reached; "not computed"), how many
    front members are certified, its dense certificate and the guarantee it gives
    (violations listed), what it did not check (``result.unchecked``), the result's
    warning and where it was saved."""
    z = result.best_objectives
    cert, front = result.certificate, result.front
    workers = result.problem_settings.workers
    certified = (
        f", {front.n_certified} certified (continuous guarantee)"
        if front.n_certified is not None
        else ""
    )
    lines = [
        f"{result.algorithm}: {result.timing.n_evaluations} evaluations in "
        f"{result.timing.total_s:.1f} s ({result.timing.evaluation_s:.1f} s evaluating, "
        f"{workers} worker{'s' if workers != 1 else ''}); "
        f"front of {len(front)}{certified}",
        f"best trade-off: T = {z[0]:.3f} s (T = {result.gap:.2f} × T_lb, the kinematic lower "
        f"bound {result.lower_bound.T_min:.3f} s; {t_best_text(result)}), {objectives_text(z)}",
        f"verified at {cert.rate_hz:g} Hz: {'FEASIBLE' if cert.feasible else 'NOT FEASIBLE'}"
        f" (min distance {cert.min_distance:.4f} m, margin {cert.margin} m; "
        f"distance: {cert.guarantee or f'sampled at {cert.rate_hz:g} Hz'}; "
        f"torque: {cert.torque_guarantee or f'sampled at {cert.rate_hz:g} Hz'})",
    ]
    t0 = result.problem_settings.start_time
    if t0:
        lines.append(
            f"  scene clock: the move starts at scene time t0 = {t0:g} s (obstacles at t0 + t)"
        )
    lines += weighted_sum_text(result)
    lines += [f"  violation: {v}" for v in cert.violations]
    if result.self_pairs is not None:
        lines += [f"self-collision: {line}" for line in result.self_pairs.lines()]
    lines += [f"unchecked: {item}" for item in unchecked_of(result)]
    if result.warning:
        lines.append(f"warning: {result.warning}")
    lines.append(f"saved to {folder}/result.json")
    return "\n".join(lines)


def save_figures(
    results: dict[str, PlanningResult],
    folder: Path,
    replays: dict[str, Replay] | None = None,
) -> None:
    """The paper's figures of ``results`` (by algorithm name) as PNGs in ``folder``
    (matplotlib, the ``plot`` extra; a note on standard error when it is missing);
    ``replays`` (same keys) reuse the run's robot and scene."""
    try:
        from adept_traj.viz import plots

        paths = plots.save_all(results, folder, replays=replays)
    except ImportError as exc:
        _note_missing_matplotlib(exc)
        return
    print(figures_line(paths, folder, results))


def figures_line(paths: list[Path], folder: Path, results: Mapping[str, PlanningResult]) -> str:
    """``"4 figures in FOLDER"``, with the reason when the front figures were left out
    (:func:`~adept_traj.viz.plots.all_figures.has_front_figures`)."""
    from adept_traj.viz.plots.all_figures import has_front_figures

    line = f"{len(paths)} figures in {folder}"
    if has_front_figures(results):
        return line
    return f"{line} (no pareto_matrix.png or best_tradeoffs.png: the front is one move)"


def _note_missing_matplotlib(exc: ImportError) -> None:
    """A note on standard error for a missing matplotlib (the ``plot`` extra); any other
    :class:`ImportError` (a broken install of adept_traj itself) is raised again."""
    if (exc.name or "").split(".")[0] != "matplotlib":
        raise exc
    print(f"note: figures skipped ({exc}); install the 'plot' extra", file=sys.stderr)


def start_figures(
    results: dict[str, PlanningResult],
    folder: Path,
    replays: dict[str, Replay] | None = None,
) -> Any:
    """Start drawing the figures of :func:`save_figures` in a forked process
    (:func:`adept_traj.viz.plots.start_save_all`) and return the drawing under way, to be
    ended by :func:`finish_figures`; ``None`` (a note on standard error) when matplotlib is
    missing. matplotlib is imported by the forked process, not here."""
    if importlib.util.find_spec("matplotlib") is None:
        print("note: figures skipped (no module named 'matplotlib'); install the 'plot' "
              "extra", file=sys.stderr)  # fmt: skip
        return None
    from adept_traj.viz import plots

    return plots.start_save_all(results, folder, replays=replays)


def finish_figures(drawing: Any, folder: Path, results: Mapping[str, PlanningResult]) -> None:
    """Wait for the figures of ``results`` started by :func:`start_figures` (``None``:
    nothing to do) and say how many were written (:func:`figures_line`); their error is
    raised here (an :class:`ImportError` of matplotlib is a note, as in
    :func:`save_figures`)."""
    if drawing is None:
        return
    try:
        paths = drawing.wait()
    except ImportError as exc:
        _note_missing_matplotlib(exc)
        return
    print(figures_line(paths, folder, results))


def finisher_for(robot: Any, scene: Any, *, figures: bool, html: bool, urgent: bool = False) -> Any:
    """The helper process that will write a run's figures and/or ``playback.html``
    (:func:`adept_traj.viz.finisher.start_finisher`: it imports matplotlib and meshcat at
    the lowest priority while the run goes on, or at the caller's when ``urgent``), in a
    context that stops it; an empty context (``None``) when neither output is asked for,
    without matplotlib for the figures (the finish says so) or when no process can be
    forked (the caller writes them)."""
    if not (figures or html) or (figures and importlib.util.find_spec("matplotlib") is None):
        return contextlib.nullcontext(None)
    try:
        return start_finisher(robot, scene, figures=figures, html=html, urgent=urgent)
    except OSError:  # e.g. no memory to fork: the caller writes the files itself
        return contextlib.nullcontext(None)


@contextlib.contextmanager
def finishers_for(robot: Any, scene: Any, *, figures: bool, html: bool, time_optimal: bool) -> Any:
    """The finish's helpers of ``plan`` (:func:`finisher_for`), stopped when the block is
    left: ``(drawer, pager)``. For an evolutionary run, whose imports take the idle time
    of a long search, one helper for the figures and the page (``pager`` ``None``); for
    the time-optimal mode, whose search is shorter than the imports, one for the figures,
    importing at the caller's priority, and one for the page, importing at the lowest (its
    imports and page take a fraction of the figures' time: they leave the cores to the
    run and the figures' imports, and are raised when the page is due)."""
    with contextlib.ExitStack() as stack:
        if not time_optimal:
            yield stack.enter_context(finisher_for(robot, scene, figures=figures, html=html)), None
            return
        parts = (robot, scene)
        drawer = stack.enter_context(finisher_for(*parts, figures=figures, html=False, urgent=True))
        # the page alone (no figures) is the last output: its imports are urgent then
        pager = stack.enter_context(
            finisher_for(*parts, figures=False, html=html, urgent=not figures)
        )
        yield drawer, pager


def write_page(result: PlanningResult, path: Path, replay: Replay) -> None:
    """``playback.html`` at ``path`` and the front explorer beside it, written by the
    calling process (``replay``: the run's :class:`~adept_traj.results.Replay`)."""
    from adept_traj.viz import explorer, meshcat_scene

    meshcat_scene.static_html(result, path, replay=replay)
    explorer.write_explorer(result, path.parent / explorer.EXPLORER_FILE,
                            robot=replay.robot, scene=replay.scene)  # fmt: skip
