"""The best trade-offs side by side, scored on common bounds (the paper's Fig. 7)."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from adept_traj.analysis import normalise, objective_bounds
from adept_traj.results import PlanningResult
from adept_traj.viz.plots.common import (
    COLOURS,
    OBJECTIVE_LABELS,
    as_results,
    front_rows,
    legend_labels,
    new_figure,
    png_path,
    save_figure,
    status,
)

__all__ = ["best_tradeoffs"]


def best_tradeoffs(
    results: Mapping[str, PlanningResult] | PlanningResult, path: str | os.PathLike[str]
) -> Path:
    """The best trade-offs side by side (Fig. 7): grouped bars of the six objectives.

    Each objective is scored on common bounds, as ``decision.normalise`` does for F_avg:
    ``(Z_max − z)/(Z_max − Z_min)`` for a minimised objective and ``(z − Z_min)/(Z_max −
    Z_min)`` for z4 (maximised), so 1 is the best value and 0 the worst. Z_min and Z_max
    are the extremes over every result's front (feasible part, or the whole front when
    nothing is feasible) and best trade-off; an objective equal everywhere scores 1. The
    raw value is written on each bar, the bounds under each group, F_avg on these bounds
    in the legend.

    Parameters
    ----------
    results: ``{name: PlanningResult}`` (or one result).
    path: the PNG file to write.

    Returns
    -------
    pathlib.Path
        ``path``, the bar chart of the best trade-offs' scores.
    """
    res = as_results(results)
    out = png_path(path)
    labels = legend_labels(res)
    bests = np.array([r.best_objectives for r in res.values()])
    lo, hi = objective_bounds(*[front_rows(r) for r in res.values()], bests)
    scores = normalise(bests, lo, hi)
    m, n = bests.shape[1], len(res)

    fig = new_figure(12.0, 6.5)
    ax = fig.add_subplot()
    fig.subplots_adjust(left=0.09, right=0.98, bottom=0.16, top=0.85)
    width = 0.8 / n
    x0 = np.arange(m)
    for k, key in enumerate(res):
        xs = x0 - 0.4 + width * (k + 0.5)
        r = res[key]
        ax.bar(
            xs,
            scores[k],
            width * 0.92,
            color=COLOURS[k],
            alpha=0.85,
            edgecolor=COLOURS[k],
            linewidth=1.5,  # a zero score still shows as a line
            label=f"{labels[key]} (F_avg on these bounds {scores[k].mean():.3f}, {status(r)})",
        )
        for xi, s, v in zip(xs, scores[k], bests[k]):
            ax.text(
                xi,
                max(s, 0.0) + 0.02,
                f"{v:.4g}",
                ha="center",
                va="bottom",
                rotation=90 if n > 2 else 0,
                fontsize=8,
            )
    ticks = []
    for j in range(m):
        same = hi[j] == lo[j]
        bounds = f"all = {lo[j]:.4g}" if same else f"[{lo[j]:.4g}, {hi[j]:.4g}]"
        ticks.append(f"{OBJECTIVE_LABELS[j]}\n{bounds}")
    ax.set_xticks(x0, ticks, fontsize=8.5)
    ax.set_ylim(0.0, 1.22)
    ax.axhline(1.0, color="grey", lw=0.8, ls=":")
    ax.set_ylabel(
        "score on common bounds [-], 1 = best\n"
        "(Z_max − z)/(Z_max − Z_min); z4: (z − Z_min)/(Z_max − Z_min)",
        fontsize=9,
    )
    ax.set_xlabel(
        "objective [unit]\n[Z_min, Z_max] over all fronts and best trade-offs", fontsize=9
    )
    fig.legend(loc="upper center", bbox_to_anchor=(0.5, 0.93), ncol=min(n, 3), fontsize=9)
    fig.suptitle("Best trade-offs: six objectives scored on common bounds", fontsize=13, y=0.98)
    ax.text(0.995, 0.99, "raw values on the bars", transform=ax.transAxes, ha="right",
            va="top", fontsize=8, color="dimgrey")  # fmt: skip
    return save_figure(fig, out)
