"""The final fronts as a scatter matrix of the objectives z1…z6 (the paper's Figs. 5–6)."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from adept_traj.results import PlanningResult
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


def pareto_matrix(
    results: Mapping[str, PlanningResult] | PlanningResult, path: str | os.PathLike[str]
) -> Path:
    """Scatter matrix of the objectives z1…z6 of one or more fronts (Figs. 5–6).

    Off the diagonal, panel (i, j) plots z_j (x) against z_i (y); each result has its own
    colour and marker. Feasible solutions are filled, infeasible ones (a front of
    least-infeasible solutions) hollow; the best trade-off is a large star. The diagonal
    holds the histogram of each objective per result, drawn in the row's scale.

    Parameters
    ----------
    results: ``{name: PlanningResult}`` (or one result).
    path: the PNG file to write (folders created).

    Returns
    -------
    The path written.
    """
    res = as_results(results)
    out = png_path(path)
    from matplotlib.lines import Line2D
    from matplotlib.ticker import MaxNLocator, NullLocator, ScalarFormatter

    labels = legend_labels(res)
    m = len(OBJECTIVE_LABELS)
    allobj = np.vstack([r.front.objectives for r in res.values()])
    limits = [padded(float(allobj[:, j].min()), float(allobj[:, j].max()), 0.09) for j in range(m)]

    # histogram heights: share of each front per bin, on one scale for all results
    peak = max(
        np.histogram(r.front.objectives[:, j], bins=np.linspace(*limits[j], 13))[0].max()
        / len(r.front)
        for r in res.values()
        for j in range(m)
    )
    fig = new_figure(15.0, 15.0)
    axes = fig.subplots(m, m)
    fig.subplots_adjust(left=0.08, right=0.98, bottom=0.07, top=0.9, wspace=0.08, hspace=0.08)
    for k, r in enumerate(res.values()):
        colour, marker = COLOURS[k], MARKERS[k]
        obj, feas, best = r.front.objectives, r.front.feasible, r.best.index
        for i in range(m):
            for j in range(m):
                ax = axes[i, j]
                if i == j:
                    lo, hi = limits[j]
                    edges = np.linspace(lo, hi, 13)
                    counts, _ = np.histogram(obj[:, j], bins=edges)
                    scale = 0.9 * (hi - lo) / (peak * len(obj))  # share of the front
                    ax.stairs(
                        lo + counts * scale,
                        edges,
                        baseline=lo,
                        fill=True,
                        alpha=0.3,
                        color=colour,
                    )
                    ax.stairs(lo + counts * scale, edges, baseline=lo, color=colour, lw=1.2)
                    continue
                x, y = obj[:, j], obj[:, i]
                if feas.any():  # (an empty scatter costs as much as a full one)
                    ax.scatter(
                        x[feas], y[feas], s=16, marker=marker, color=colour, alpha=0.75, lw=0
                    )
                if not feas.all():
                    ax.scatter(
                        x[~feas],
                        y[~feas],
                        s=16,
                        marker=marker,
                        facecolors="none",
                        edgecolors=colour,
                        lw=0.9,
                    )
                ax.scatter(
                    [x[best]],
                    [y[best]],
                    s=230 * 0.72**k,  # shrinking: coinciding best trade-offs stay visible
                    marker="*",
                    facecolors=colour if feas[best] else "white",
                    edgecolors="black" if feas[best] else colour,
                    lw=1.0 if feas[best] else 2.0,
                    zorder=5,
                )
    for i in range(m):
        for j in range(m):
            ax = axes[i, j]
            ax.set_xlim(limits[j])
            ax.set_ylim(limits[i])
            # Ticks on the outer panels only (they carry the labels; the panels of a column
            # share its x range, those of a row its y range): a tick is four artists, and
            # the inner panels' ticks made up about half of the figure's drawing time.
            for axis, outer in ((ax.xaxis, i == m - 1), (ax.yaxis, j == 0)):
                if not outer:
                    axis.set_major_locator(NullLocator())
                    continue
                axis.set_major_locator(MaxNLocator(3))
                fmt = ScalarFormatter(useMathText=True)
                fmt.set_powerlimits((-2, 3))
                axis.set_major_formatter(fmt)
                axis.get_offset_text().set_fontsize(7)
            ax.tick_params(labelsize=7, length=2)
            if i == m - 1:
                ax.set_xlabel(OBJECTIVE_LABELS[j], fontsize=9)
            if j == 0:
                ax.set_ylabel(OBJECTIVE_LABELS[i], fontsize=9)
            if i == j:
                ax.set_facecolor("#f4f4f4")
                ax.text(
                    0.04,
                    0.93,
                    f"z{i + 1}",
                    transform=ax.transAxes,
                    fontsize=10,
                    fontweight="bold",
                    va="top",
                )
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
