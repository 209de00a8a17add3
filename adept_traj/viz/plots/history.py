"""Hypervolume of the feasible front per generation (or, when none was recorded, the
number of feasible individuals)."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.results import PlanningResult
from adept_traj.viz.plots.common import (
    COLOURS,
    MARKERS,
    as_results,
    legend_labels,
    new_figure,
    png_path,
    save_figure,
)

__all__ = ["hypervolume_history"]


def _evaluations_per_generation(history: Sequence[Any]) -> int:
    """Median number of evaluations between consecutive records (the population size)."""
    evals = np.array([rec.n_evaluations for rec in history], dtype=float)
    gens = np.array([rec.generation for rec in history], dtype=float)
    if len(evals) < 2:
        return int(evals[0] / max(gens[0], 1.0))
    return round(float(np.median(np.diff(evals) / np.maximum(np.diff(gens), 1.0))))


def _records_hypervolume(histories: Any) -> bool:
    """True when some history records a hypervolume (else feasible counts are drawn)."""
    return any(rec.hypervolume is not None for h in histories for rec in h)


def hypervolume_history(
    result_or_results: PlanningResult | Mapping[str, PlanningResult],
    path: str | os.PathLike[str],
) -> Path:
    """Hypervolume of the feasible front per generation, one line per result.

    Generations whose hypervolume is ``None`` are skipped. When no result records any
    hypervolume, the number of feasible individuals per generation is plotted instead
    and the title says so.

    Parameters
    ----------
    result_or_results: one result or ``{name: PlanningResult}``.
    path: the PNG file to write.

    Returns
    -------
    pathlib.Path
        ``path``, the hypervolume (or feasible count) per generation.

    Raises
    ------
    InvalidInputError
        No result has a history (``result.history is None`` or empty).
    """
    res = as_results(result_or_results)
    out = png_path(path)
    labels = legend_labels(res)
    have = {k: r.history for k, r in res.items() if r.history}
    if not have:
        raise InvalidInputError("no result has a per-generation history to plot")
    use_hv = _records_hypervolume(have.values())

    fig = new_figure(9.0, 5.5)
    ax = fig.add_subplot()
    fig.subplots_adjust(left=0.1, right=0.97, bottom=0.12, top=0.88)
    for k, key in enumerate(res):
        if key not in have:
            continue
        history = have[key]
        if use_hv:
            rows = [(rec.generation, rec.hypervolume) for rec in history]
            rows = [(g, v) for g, v in rows if v is not None]
            label = labels[key] if rows else f"{labels[key]} (no hypervolume recorded)"
        else:
            rows = [(rec.generation, rec.n_feasible) for rec in history]
            label = f"{labels[key]} ({_evaluations_per_generation(history)} evaluations/gen.)"
        g = np.array([row[0] for row in rows], dtype=float)
        v = np.array([row[1] for row in rows], dtype=float)
        ax.plot(g, v, color=COLOURS[k], marker=MARKERS[k], ms=3.5, lw=1.4, label=label)
    ax.set_xlabel("generation [-]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=9)
    if use_hv:
        ceilings = {
            float(np.prod(r.metrics.hv_reference_point))
            for r in res.values()
            if r.metrics.hv_reference_point is not None
        }
        if len(ceilings) == 1:
            (top,) = ceilings
            ax.axhline(top, color="grey", ls=":", lw=1.0, label=f"maximum {top:.4g} (∏ ref. point)")
            ax.legend(fontsize=9)
        ax.set_ylabel("hypervolume of the feasible front [-] (normalised objectives)")
        title = "Hypervolume per generation"
        if len(have) > 1:
            title += "\neach run normalised on the bounds of its own final front: compare shapes"
        ax.set_title(title)
    else:
        ax.set_ylabel("feasible individuals in the population [-]")
        ax.set_title("No hypervolume recorded in the history: feasible individuals per generation")
        ax.set_ylim(bottom=0)
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    return save_figure(fig, out)
