"""What a seed study reports: ``study.json``, ``study.md`` and box plots.

``study.md`` has one row per metric (:data:`~adept_traj.cycle.study.METRICS`): median
[q25, q75] of NSGA-II and MODE, the Mann–Whitney U p-value, the better algorithm by median
and the verdict on the paper's single-run ordering; ``figures/study_boxplots.png`` one box
plot per metric.
"""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from adept_traj.cycle.study import ALGORITHM_PAIR, ALPHA, METRICS
from adept_traj.files import write_text_atomic

__all__ = [
    "BOXPLOT_FIGURE",
    "STUDY_FILE",
    "STUDY_REPORT",
    "save_boxplots",
    "study_markdown",
    "write_study_report",
]

STUDY_FILE = "study.json"
STUDY_REPORT = "study.md"
BOXPLOT_FIGURE = "figures/study_boxplots.png"


def _cell(q: dict[str, Any]) -> str:
    if q["median"] is None:
        return "–"
    return f"{q['median']:.4g} [{q['q25']:.4g}, {q['q75']:.4g}]"


def study_markdown(rows: list[dict[str, Any]], seeds: Sequence[int]) -> str:
    """The text of ``study.md`` from :func:`~adept_traj.cycle.study_statistics`'s rows."""
    a, b = ALGORITHM_PAIR
    first, last = min(seeds), max(seeds)
    out = [
        "# NSGA-II vs MODE over seeds",
        "",
        f"{len(seeds)} seeds ({first}…{last}) per algorithm. Median [q25, q75]; p: two-sided "
        f"Mann–Whitney U (rank-sum) test; significant when p < {ALPHA}. F_avg, f_c and HV "
        "on the study's common bounds.",
        "",
        f"| metric | {a} | {b} | p | better (median) | paper's single run | verdict |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        p = "–" if r["p"] is None else f"{r['p']:.3g}"
        out.append(
            f"| {r['label']} | {_cell(r[a])} | {_cell(r[b])} | {p} | {r['better'] or '–'} | "
            f"{r['paper_winner'] or '–'} | {r['verdict']} |"
        )
    judged = [r for r in rows if r["paper_winner"] is not None]
    counts = {v: sum(r["verdict"] == v for r in judged) for v in ("confirmed", "contradicted")}
    out += [
        "",
        f"Of the paper's {len(judged)} single-run orderings, {counts['confirmed']} are "
        f"confirmed, {counts['contradicted']} contradicted and "
        f"{len(judged) - sum(counts.values())} not significant over these seeds.",
    ]
    return "\n".join(out) + "\n"


def save_boxplots(metrics: dict[str, dict[str, list[float | None]]], path: Path) -> Path:
    """One box plot per metric (both algorithms side by side) in a PNG at ``path``."""
    from adept_traj.viz.plots.common import display_name, new_figure, save_figure

    cols = 4
    rows = -(-len(METRICS) // cols)
    fig = new_figure(3.2 * cols, 2.6 * rows)
    for k, m in enumerate(METRICS):
        ax = fig.add_subplot(rows, cols, k + 1)
        data = [[v for v in metrics[a][m.key] if v is not None] for a in ALGORITHM_PAIR]
        ax.boxplot(data, tick_labels=[display_name(a) for a in ALGORITHM_PAIR])
        arrow = {True: " ↓", False: " ↑", None: ""}[m.lower_is_better]
        ax.set_title(m.label + arrow, fontsize=8)
        ax.tick_params(labelsize=7)
    fig.subplots_adjust(left=0.06, right=0.98, bottom=0.05, top=0.95, wspace=0.35, hspace=0.45)
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(fig, path)


def write_study_report(
    rows: list[dict[str, Any]],
    metrics: dict[str, dict[str, list[float | None]]],
    seeds: Sequence[int],
    out: str | os.PathLike[str],
    *,
    figure: bool,
) -> str:
    """Write ``study.json`` (seeds, per-run values, statistics), ``study.md`` and
    (``figure``) the box plots into ``out``; return the markdown."""
    folder = Path(out)
    text = study_markdown(rows, seeds)
    doc = {"seeds": list(seeds), "runs": metrics, "statistics": rows}
    write_text_atomic(folder / STUDY_FILE, json.dumps(doc, indent=1))
    write_text_atomic(folder / STUDY_REPORT, text)
    if figure:
        save_boxplots(metrics, folder / BOXPLOT_FIGURE)
    return text
