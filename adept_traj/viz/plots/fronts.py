"""The final fronts as a scatter matrix of the objectives z1…z6 (the paper's Figs. 5–6).

The 36 panels are cells of one hidden ``Axes`` (``adept_traj.viz.plots._panels``): each
result is three scatters (feasible, infeasible, best trade-off) over all the panels, its
histograms one filled and one outlined collection.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.results import PlanningResult
from adept_traj.viz.plots._panels import hidden_axes, panel_texts, shifter, tick_labels
from adept_traj.viz.plots.common import (
    COLOURS,
    MARKERS,
    OBJECTIVE_LABELS,
    as_results,
    legend_labels,
    new_figure,
    padded,
    png_path,
    save_figure,
)

__all__ = ["pareto_matrix"]

#: Side of a panel in cells (pitch 1): the gap between panels is 8 % of a panel.
_SIDE = 1.0 / 1.08
_BINS = 12
#: Figure size [inch] and the panels' box in figure fractions (left, bottom, right, top).
_SIZE = 15.0
_BOX = (0.08, 0.07, 0.98, 0.9)


def pareto_matrix(
    results: Mapping[str, PlanningResult] | PlanningResult, path: str | os.PathLike[str]
) -> Path:
    """Scatter matrix of the objectives z1…z6 of one or more fronts (Figs. 5–6).

    Off the diagonal, panel (i, j) plots z_j (x) against z_i (y); each result has its own
    colour and marker. Feasible solutions are filled, infeasible ones (a front of
    least-infeasible solutions) hollow; the best trade-off is a large star. The diagonal
    holds the histogram of each objective per result, drawn in the row's scale. The
    panels of a column share its x range, those of a row its y range: the bottom row
    carries the x ticks, the left column the y ticks.

    Parameters
    ----------
    results: ``{name: PlanningResult}`` (or one result).
    path: the PNG file to write (folders created).

    Returns
    -------
    pathlib.Path
        ``path``, the matrix of the fronts' pairwise scatter plots.
    """
    res = as_results(results)
    out = png_path(path)
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.lines import Line2D

    labels = legend_labels(res)
    m = len(OBJECTIVE_LABELS)
    allobj = np.vstack([r.front.objectives for r in res.values()])
    limits = np.array(
        [padded(float(allobj[:, j].min()), float(allobj[:, j].max()), 0.09) for j in range(m)]
    )
    edges = np.linspace(limits[:, 0], limits[:, 1], _BINS + 1, axis=1)  # (m, bins + 1)
    # histogram heights: share of each front per bin, on one scale for all results
    counts = {
        key: np.array([np.histogram(r.front.objectives[:, j], bins=edges[j])[0] for j in range(m)])
        / len(r.front)
        for key, r in res.items()
    }
    peak = max(float(c.max()) for c in counts.values())

    fig = new_figure(_SIZE, _SIZE)
    ax = hidden_axes(fig, _BOX, m - 1 + _SIDE, m - 1 + _SIDE)
    _frames_and_ticks(ax, limits)
    rows, cols = np.nonzero(~np.eye(m, dtype=bool))  # the off-diagonal panels (i, j)
    diag = np.arange(m)
    for k, (key, r) in enumerate(res.items()):
        colour, marker = COLOURS[k], MARKERS[k]
        obj, feas, best = r.front.objectives, r.front.feasible, r.best.index
        u = _to_panel(obj, limits)  # (n, m) panel coordinates in [0, _SIDE]
        x = (cols[:, None] + u[:, cols].T).ravel()  # (panels · n,)
        y = (m - 1 - rows[:, None] + u[:, rows].T).ravel()
        mask = np.tile(feas, len(rows))
        if feas.any():  # (an empty scatter costs as much as a full one)
            ax.scatter(x[mask], y[mask], s=16, marker=marker, color=colour, alpha=0.75, lw=0)
        if not feas.all():
            ax.scatter(x[~mask], y[~mask], s=16, marker=marker, facecolors="none",
                       edgecolors=colour, lw=0.9)  # fmt: skip
        ax.scatter(
            cols + u[best, cols],
            m - 1 - rows + u[best, rows],
            s=230 * 0.72**k,  # shrinking: coinciding best trade-offs stay visible
            marker="*",
            facecolors=colour if feas[best] else "white",
            edgecolors="black" if feas[best] else colour,
            lw=1.0 if feas[best] else 2.0,
            zorder=5,
        )
        # histograms as closed steps from the baseline, in the diagonal panels' scale
        h = 0.9 * _SIDE * counts[key] / peak  # (m, bins)
        xs = diag[:, None] + _SIDE * np.repeat(np.linspace(0.0, 1.0, _BINS + 1), 2)[None, :]
        ys = np.concatenate([np.zeros((m, 1)), np.repeat(h, 2, axis=1), np.zeros((m, 1))], 1)
        steps = np.stack([xs, (m - 1 - diag)[:, None] + ys], axis=-1)  # (m, 2 bins + 2, 2)
        ax.add_collection(PolyCollection(steps, facecolors=colour, alpha=0.3, lw=0))
        ax.add_collection(LineCollection(steps, colors=colour, lw=1.2))
    handles = [
        Line2D([], [], ls="", marker=MARKERS[k], color=COLOURS[k], label=labels[key])
        for k, key in enumerate(res)
    ]
    handles += [
        Line2D([], [], ls="", marker="o", color="grey", label="feasible (filled)"),
        Line2D([], [], ls="", marker="o", mfc="none", mec="grey", label="infeasible (hollow)"),
        Line2D([], [], ls="", marker="*", ms=13, mfc="grey", mec="black", label="best trade-off"),
    ]
    fig.legend(handles=handles, loc="upper center", ncol=len(handles), bbox_to_anchor=(0.5, 0.95))
    sizes = ", ".join(
        f"{labels[k]}: {len(r.front)} solution{'s' if len(r.front) != 1 else ''}"
        for k, r in res.items()
    )
    fig.suptitle(
        f"Final fronts, objectives z1…z6 ({sizes})\ndiagonal: histogram of each objective "
        "(share of each front per bin, one scale for all)",
        fontsize=13,
        y=0.985,
    )
    return save_figure(fig, out)


def _to_panel(values: np.ndarray, limits: np.ndarray) -> np.ndarray:
    """(n, m) objective values to panel coordinates in [0, _SIDE] (limits (m, 2))."""
    return _SIDE * (values - limits[:, 0]) / (limits[:, 1] - limits[:, 0])


def _frames_and_ticks(ax: Any, limits: np.ndarray) -> None:
    """The frames of the m × m panels (the diagonal shaded, named z1…z6) and the ticks,
    tick labels and axis labels of the bottom row (x) and the left column (y): three
    ticks per objective (``MaxNLocator(3)``), labels as matplotlib's ``ScalarFormatter``
    writes them (scientific outside 10⁻² … 10³, the factor at the axis' end)."""
    from matplotlib.collections import LineCollection, PatchCollection
    from matplotlib.patches import Rectangle

    m = len(limits)
    shift = shifter(ax)
    put = panel_texts(ax)
    boxes = [Rectangle((j, m - 1 - i), _SIDE, _SIDE) for i in range(m) for j in range(m)]
    shade = ["#f4f4f4" if i == j else "white" for i in range(m) for j in range(m)]
    ax.add_collection(PatchCollection(boxes, facecolors=shade, edgecolors="none", zorder=0))
    frames = PatchCollection(boxes, facecolors="none", edgecolors="black", lw=0.8, zorder=2.5)
    ax.add_collection(frames)
    below, left_of = shift(0.0, -3.5), shift(-3.5, 0.0)
    ticks = []
    for j in range(m):
        lo, hi = limits[j]
        locs, texts, offset = tick_labels(lo, hi, 3, power_of_ten=True, power_limits=(-2, 3))
        pos = _SIDE * (locs - lo) / (hi - lo)
        # x ticks under panel (m - 1, j), y ticks left of panel (j, 0)
        for p, text in zip(pos, texts):
            ticks.append([(j + p, 0.0), (j + p, -0.012)])
            ticks.append([(0.0, m - 1 - j + p), (-0.012, m - 1 - j + p)])
            put(j + p, 0.0, text, transform=below, fontsize=7, ha="center", va="top")
            put(0.0, m - 1 - j + p, text, transform=left_of, fontsize=7, ha="right",
                va="center")  # fmt: skip
        if offset:
            put(j + _SIDE, 0.0, offset, transform=shift(0.0, -13.0), fontsize=7,
                ha="right", va="top")  # fmt: skip
            put(0.0, m - 1 - j + _SIDE, offset, transform=shift(0.0, 2.0),
                fontsize=7, ha="left", va="bottom")  # fmt: skip
        put(j + 0.5 * _SIDE, 0.0, OBJECTIVE_LABELS[j], transform=shift(0.0, -14.0),
            fontsize=9, ha="center", va="top")  # fmt: skip
        put(0.0, m - 1 - j + 0.5 * _SIDE, OBJECTIVE_LABELS[j],
                transform=shift(-30.0, 0.0), fontsize=9, ha="right", va="center",
                rotation=90)  # fmt: skip
        put(j + 0.04 * _SIDE, m - 1 - j + 0.93 * _SIDE, f"z{j + 1}", fontsize=10,
            fontweight="bold", va="top")  # fmt: skip
    ax.add_collection(LineCollection(ticks, colors="black", lw=0.8))
