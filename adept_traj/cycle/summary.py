"""What a cycle run reports: ``cycle.json``, ``cycle.md`` and a Gantt-like figure.

Per move: whether its reported solution (the first certified member in the trade-off
order, :func:`~adept_traj.optimise.plan`) is certified, its travel time T [s] and f_c,
the fastest certified T of its front [s] and the number of certified members. The cycle
time is ``repeat`` × the sum of the moves' T (the robot rests at every location, so
moves follow each other end to end), for the best trade-offs and for the fastest
certified members (``None`` when a move has no certified member).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.cycle.cycle_file import Cycle
from adept_traj.cycle.runner import MOVES_FOLDER
from adept_traj.files import write_text_atomic
from adept_traj.results import PlanningResult

__all__ = [
    "CYCLE_FILE",
    "CYCLE_REPORT",
    "GANTT_FIGURE",
    "cycle_markdown",
    "cycle_summary",
    "fastest_certified",
    "save_gantt",
    "write_cycle_report",
]

CYCLE_FILE = "cycle.json"
CYCLE_REPORT = "cycle.md"
GANTT_FIGURE = "cycle_gantt.png"


def fastest_certified(result: PlanningResult) -> float | None:
    """Smallest travel time T [s] among the certified members of ``result``'s front
    (``None``: none is certified)."""
    f = result.front
    times = f.objectives[np.asarray(f.feasible, dtype=bool), 0]
    return float(times.min()) if times.size else None


def cycle_summary(cycle: Cycle, results: list[PlanningResult]) -> dict[str, Any]:
    """The content of ``cycle.json`` for ``results`` (one per move, in order)."""
    moves = []
    for m, r in zip(cycle.moves, results, strict=True):
        moves.append(
            {
                "name": m.name,
                "from": m.start,
                "to": m.goal,
                "folder": f"{MOVES_FOLDER}/{m.name}",
                "algorithm": r.algorithm,
                "seed": m.seed,
                "certified": bool(r.feasible),
                "T": float(r.best_objectives[0]),
                "f_c": float(r.best.f_c),
                "fastest_certified_T": fastest_certified(r),
                "n_certified": int(r.front.n_certified),
            }
        )
    best = sum(m["T"] for m in moves)
    fastest = [m["fastest_certified_T"] for m in moves]
    return {
        "format": "adept_traj cycle",
        "version": 1,
        "name": cycle.name,
        "source": cycle.source,
        "repeat": cycle.repeat,
        "locations": {
            name: {
                "joints": loc.joints.tolist(),
                "pose": list(loc.pose) if loc.pose is not None else None,
                "elbow": loc.elbow,
            }
            for name, loc in cycle.locations.items()
        },
        "moves": moves,
        "all_certified": all(m["certified"] for m in moves),
        "cycle_time": cycle.repeat * best,
        "cycle_time_fastest": (
            cycle.repeat * sum(fastest) if all(t is not None for t in fastest) else None
        ),
    }


def _t(value: float | None) -> str:
    return "–" if value is None else f"{value:.3f}"


def cycle_markdown(summary: dict[str, Any]) -> str:
    """The text of ``cycle.md`` from :func:`cycle_summary`'s ``summary``."""
    lines = [
        f"# Cycle {summary['name']}",
        "",
        f"Source: `{summary['source']}`; the sequence runs {summary['repeat']}× per cycle.",
        "",
        "| # | move | from → to | certified | T [s] | f_c | fastest certified T [s] "
        "| certified members |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for k, m in enumerate(summary["moves"]):
        lines.append(
            f"| {k} | {m['name']} | {m['from']} → {m['to']} | "
            f"{'yes' if m['certified'] else 'NO'} | {_t(m['T'])} | {m['f_c']:.4g} | "
            f"{_t(m['fastest_certified_T'])} | {m['n_certified']} |"
        )
    lines += [
        "",
        f"Cycle time (best trade-offs): **{_t(summary['cycle_time'])} s**; "
        f"with the fastest certified members: {_t(summary['cycle_time_fastest'])} s.",
    ]
    if not summary["all_certified"]:
        lines += ["", "**Some moves have no certified solution: do not run this cycle.**"]
    return "\n".join(lines) + "\n"


def save_gantt(summary: dict[str, Any], path: Path) -> Path:
    """A Gantt-like figure of one pass of the sequence: each move a bar from its start to
    its end time [s] (best trade-off), red when not certified. Needs matplotlib."""
    from adept_traj.viz.plots.common import new_figure, save_figure

    moves = summary["moves"]
    fig = new_figure(8.0, 0.4 * len(moves) + 1.2)
    ax = fig.add_subplot()
    t0 = 0.0
    for k, m in enumerate(moves):
        color = "tab:blue" if m["certified"] else "tab:red"
        ax.barh(k, m["T"], left=t0, color=color, edgecolor="black")
        ax.text(t0 + m["T"] / 2, k, m["name"], ha="center", va="center", fontsize=7)
        t0 += m["T"]
    ax.set_yticks(range(len(moves)), [f"{m['from']} → {m['to']}" for m in moves])
    ax.invert_yaxis()
    ax.set_xlabel("time in the cycle [s]")
    ax.set_title(f"{summary['name']}: {t0:.3f} s per pass × {summary['repeat']}")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(fig, path)


def write_cycle_report(
    cycle: Cycle, results: list[PlanningResult], out: str | os.PathLike[str], *, figure: bool
) -> dict[str, Any]:
    """Write ``cycle.json``, ``cycle.md`` and (``figure``) ``cycle_gantt.png`` into
    ``out``; return the summary."""
    folder = Path(out)
    summary = cycle_summary(cycle, results)
    write_text_atomic(folder / CYCLE_FILE, json.dumps(summary, indent=1))
    write_text_atomic(folder / CYCLE_REPORT, cycle_markdown(summary))
    if figure:
        save_gantt(summary, folder / GANTT_FIGURE)
    return summary
