"""What a cycle run reports: ``cycle.json``, ``cycle.md`` and a Gantt-like figure.

Per move: whether its reported solution (the first certified member in the trade-off
order, :func:`~adept_traj.optimise.plan`) is certified, its travel time T [s] and f_c,
the fastest certified T of its front [s] and the number of certified members. The cycle
time is ``repeat`` × the sum of the moves' T (the robot rests at every location, so
moves follow each other end to end), for the best trade-offs and for the fastest
certified members (``None`` when a move has no certified member).

A cycle planned on the scene clock (moving obstacles, :mod:`adept_traj.cycle.clock`) adds
``clock``: each planned pass's moves with their scene start time [s], dwell [s], T [s]
and certificates (one pass and the period for a periodic scene), and its ``cycle_time``
includes the dwells; ``cycle_time_fastest`` is then ``None`` (a faster member would shift
every later start time: it was not certified so).
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.analysis import combined_objective
from adept_traj.cycle.choice import chosen_member
from adept_traj.cycle.clock import CycleClock
from adept_traj.cycle.cycle_file import Cycle, MoveSpec
from adept_traj.cycle.rest import RestCheck
from adept_traj.cycle.runner import MOVES_FOLDER
from adept_traj.files import write_text_atomic
from adept_traj.results import PlanningResult

__all__ = [
    "CYCLE_FILE",
    "CYCLE_REPORT",
    "GANTT_FIGURE",
    "clock_summary",
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


def cycle_summary(
    cycle: Cycle, results: list[PlanningResult], clock: CycleClock | None = None
) -> dict[str, Any]:
    """The content of ``cycle.json`` for ``results`` (one per move, in order: the first
    pass's with a ``clock``)."""
    moves = []
    for m, r in zip(cycle.moves, results, strict=True):
        folder = f"{MOVES_FOLDER}/{m.name}" if clock is None else clock.passes[0][m.index].folder
        moves.append(
            {
                "name": m.name,
                "from": m.start,
                "to": m.goal,
                "folder": folder,
                "algorithm": r.algorithm,
                "seed": m.seed,
                **_reported(r, m),
                "fastest_certified_T": fastest_certified(r),
                "n_certified": int(r.front.n_certified),
            }
        )
    best = sum(m["T"] for m in moves)
    fastest = [m["fastest_certified_T"] for m in moves]
    out = {
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
    if clock is not None:
        out["all_certified"] = clock.certified
        out["cycle_time"] = clock.cycle_time
        out["cycle_time_fastest"] = None
        out["clock"] = clock_summary(clock)
    return out


def _reported(r: PlanningResult, m: MoveSpec) -> dict[str, Any]:
    """certified, T [s] and f_c of the member the move runs (``choose``; the key
    ``choose`` and the member's row ``member`` when it is not the best trade-off)."""
    if m.choose == "trade-off":
        return {
            "certified": bool(r.feasible),
            "T": float(r.best_objectives[0]),
            "f_c": float(r.best.f_c),
        }
    k = chosen_member(r, m)
    f_c = combined_objective(r.front.objectives, m.weights)[k]
    return {
        "choose": m.choose,
        "member": k,
        "certified": bool(r.front.feasible[k]),
        "T": float(r.front.objectives[k, 0]),
        "f_c": float(f_c),
    }


def _rest(rest: RestCheck | None) -> dict[str, Any] | None:
    if rest is None:
        return None
    low = rest.min_distance
    return {
        "start_time": rest.start,
        "duration": rest.duration,
        "min_distance": low if math.isfinite(low) else None,
        "certified": rest.certified,
    }


def clock_summary(clock: CycleClock) -> dict[str, Any]:
    """The ``clock`` entry of ``cycle.json``: the period, the dwell grid, the pass time and
    every planned pass's moves (scene start time, dwell, T [s], certificates, candidates:
    per dwell of the grid, or per start phase a plan of the move was planned at)."""
    key = "phase" if clock.mode.startswith("phase") else "dwell"
    return {
        "scene_clock": "periodic" if clock.period is not None else "every pass planned",
        "mode": clock.mode,
        "period": clock.period,
        "passes_planned": len(clock.passes),
        ("phase_grid" if clock.mode.startswith("phase") else "dwell_grid"): list(clock.dwells),
        "pass_time": clock.pass_time,
        "final_dwell": clock.final_dwell,
        "final_rest": _rest(clock.final_rest),
        "passes": [
            [
                {
                    "name": m.name,
                    "folder": m.folder,
                    "member": m.member,
                    "start_time": m.start_time,
                    "dwell": m.dwell,
                    "T": m.T,
                    "end_time": m.end_time,
                    "certified": m.certified,
                    "move_certified": m.move_certified,
                    "rest": _rest(m.rest),
                    "candidates": [{key: d, "T": t, "certified": ok} for d, t, ok in m.candidates],
                }
                for m in moves
            ]
            for moves in clock.passes
        ],
        "start_times": clock.start_times(),
        **({"choice": clock.choice} if clock.choice else {}),
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
    fastest = (
        f"with the fastest certified members: {_t(summary['cycle_time_fastest'])} s."
        if "clock" not in summary
        else "the fastest members would shift every later start: not certified so."
    )
    lines += ["", f"Cycle time (best trade-offs): **{_t(summary['cycle_time'])} s**; {fastest}"]
    if "clock" in summary:
        lines += _clock_markdown(summary)
    if not summary["all_certified"]:
        lines += ["", "**Some moves have no certified solution: do not run this cycle.**"]
    return "\n".join(lines) + "\n"


def _clock_markdown(summary: dict[str, Any]) -> list[str]:
    """The scene-clock part of ``cycle.md``: every planned pass's start times and dwells."""
    c = summary["clock"]
    if c["period"] is not None:
        how = (
            f"The moving obstacles are periodic (P = {c['period']:.4f} s): one pass is planned; "
            f"a final dwell of {c['final_dwell']:.3f} s makes the pass time "
            f"{c['pass_time']:.3f} s a multiple of P, so every one of the "
            f"{summary['repeat']} passes sees the same obstacle phases."
        )
    elif "back to back" in c.get("mode", ""):
        how = (
            f"All {c['passes_planned']} passes run back to back, with no final dwell "
            "(shorter than rounding each pass up to a multiple of the obstacles' period): "
            "each pass sees other obstacle phases, and each move is re-certified at its "
            "real start time."
        )
    else:
        how = (
            f"The moving obstacles are not periodic: all {c['passes_planned']} passes are planned."
        )
    lines = [
        "",
        "## Scene clock",
        "",
        how + " Every move is planned and certified at its start time on the scene clock; "
        "a dwell is the robot at rest at the move's start (certified too).",
        *(["", f"Schedule kept: {c['choice']}."] if c.get("choice") else []),
        "",
        "| pass | move | dwell [s] | start [s] | T [s] | end [s] | certified |",
        "|---|---|---|---|---|---|---|",
    ]
    for p, moves in enumerate(c["passes"]):
        for m in moves:
            lines.append(
                f"| {p} | {m['name']} | {m['dwell']:.3f} | {m['start_time']:.3f} | "
                f"{m['T']:.3f} | {m['end_time']:.3f} | {'yes' if m['certified'] else 'NO'} |"
            )
    lines += ["", f"Cycle time, dwells included: **{summary['cycle_time']:.3f} s**."]
    return lines


def save_gantt(summary: dict[str, Any], path: Path) -> Path:
    """A Gantt-like figure of one pass of the sequence: each move a bar from its start to
    its end time [s] (best trade-off), red when not certified. Needs matplotlib."""
    from adept_traj.viz.plots.common import new_figure, save_figure

    moves = summary["moves"]
    fig = new_figure(8.0, 0.4 * len(moves) + 1.2)
    ax = fig.add_subplot()
    t0 = 0.0
    clock = summary.get("clock")
    if clock is not None:  # every planned pass on the scene clock, dwells hatched grey
        for moves_of_pass in clock["passes"]:
            for k, m in enumerate(moves_of_pass):
                color = "tab:blue" if m["certified"] else "tab:red"
                ax.barh(
                    k,
                    m["dwell"],
                    left=m["start_time"] - m["dwell"],
                    color="lightgrey",
                    hatch="//",
                    edgecolor="grey",
                )
                ax.barh(k, m["T"], left=m["start_time"], color=color, edgecolor="black")
                ax.text(
                    m["start_time"] + m["T"] / 2, k, m["name"], ha="center", va="center", fontsize=7
                )
        if clock["final_dwell"] > 0:
            end = clock["pass_time"] - clock["final_dwell"]
            ax.barh(
                len(moves) - 1,
                clock["final_dwell"],
                left=end,
                color="lightgrey",
                hatch="//",
                edgecolor="grey",
            )
        t0 = clock["pass_time"]
    else:
        for k, m in enumerate(moves):
            color = "tab:blue" if m["certified"] else "tab:red"
            ax.barh(k, m["T"], left=t0, color=color, edgecolor="black")
            ax.text(t0 + m["T"] / 2, k, m["name"], ha="center", va="center", fontsize=7)
            t0 += m["T"]
    ax.set_yticks(range(len(moves)), [f"{m['from']} → {m['to']}" for m in moves])
    ax.invert_yaxis()
    ax.set_xlabel("time in the cycle [s]")
    title = f"{summary['name']}: {t0:.3f} s per pass × {summary['repeat']}"
    if clock is not None and clock["period"] is None:
        title = f"{summary['name']}: {summary['repeat']} passes, {t0:.3f} s (dwells grey)"
    elif clock is not None:
        title += " (dwells grey)"
    ax.set_title(title)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(fig, path)


def write_cycle_report(
    cycle: Cycle,
    results: list[PlanningResult],
    out: str | os.PathLike[str],
    *,
    figure: bool,
    clock: CycleClock | None = None,
) -> dict[str, Any]:
    """Write ``cycle.json``, ``cycle.md`` and (``figure``) ``cycle_gantt.png`` into
    ``out``; return the summary (``clock``: the cycle was planned on the scene clock)."""
    folder = Path(out)
    summary = cycle_summary(cycle, results, clock)
    write_text_atomic(folder / CYCLE_FILE, json.dumps(summary, indent=1))
    write_text_atomic(folder / CYCLE_REPORT, cycle_markdown(summary))
    if figure:
        save_gantt(summary, folder / GANTT_FIGURE)
    return summary
