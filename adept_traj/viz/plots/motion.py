"""The motion of a front member (default: the best trade-off): position, velocity,
acceleration, jerk and torque of every joint against time, with their limits (the paper's
Figs. 8–9)."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.results import PlanningResult, certified_members, member_dense, member_index
from adept_traj.robot import LIMITS
from adept_traj.viz.inputs import as_result
from adept_traj.viz.plots._panels import hidden_axes, panel_texts, shifter, tick_labels
from adept_traj.viz.plots.common import (
    display_name,
    new_figure,
    padded,
    png_path,
    save_figure,
    status,
    violations_line,
)

__all__ = ["joint_motion"]

#: Row title of each limit kind (torque rows also hold the prismatic joint's force).
_TITLES = {"torque": "torque / force"}
#: Panels are unit cells of one hidden Axes (``_panels``), apart by these gaps [cell],
#: inside this box of the figure (left, bottom, right, top).
_GAP_X, _GAP_Y = 0.32, 0.2
_PITCH_X, _PITCH_Y = 1.0 + _GAP_X, 1.0 + _GAP_Y
_BOX = (0.06, 0.05, 0.99, 0.92)


def _limit_lines(limits: Any, kind: str, j: int) -> list[float]:
    if kind == "position":
        values = [float(limits.lower[j]), float(limits.upper[j])]
    else:
        v = float(limits.bound(kind)[j])
        values = [-v, v]
    return [v for v in values if math.isfinite(v)]


def _note(limits: Any, kind: str, j: int, values: np.ndarray) -> str:
    """A panel's note: the peak of ``values`` (n,) as a percentage of its limit, or for
    positions the smallest margin to a limit as a percentage of the range; ``"no limit"``
    where a bound is infinite (its panel has no limit line), ``""`` for an infinite
    position range."""
    if kind == "position":
        span = float(limits.upper[j] - limits.lower[j])
        margin = min(float(limits.upper[j] - values.max()), float(values.min() - limits.lower[j]))
        return (
            f"margin {100 * margin / span:.0f} % of range"
            if math.isfinite(span) and span > 0
            else ""
        )
    lim = float(limits.bound(kind)[j])
    peak = float(np.abs(values).max())
    return f"peak {100 * peak / lim:.0f} % of limit" if math.isfinite(lim) else "no limit"


def joint_motion(
    result: PlanningResult, path: str | os.PathLike[str], *, member: int | None = None
) -> Path:
    """Position, velocity, acceleration, jerk and torque of every joint against time
    (Figs. 8–9) of a front member: by default the best trade-off, from its certified dense
    trajectory; another member's spline is resampled on the certificate's grid
    (:func:`~adept_traj.results.member_dense`). The title names the member and whether it
    is certified (:func:`~adept_traj.results.certified_members`).

    One row per quantity, one column per joint; the limits are dashed lines (position:
    lower and upper; the others ±limit; an infinite limit is not drawn). Each panel
    states the peak as a percentage of its limit (position: the smallest margin to a
    limit as a percentage of the range). Units: rad or m per joint, and their time
    derivatives; torque N·m, force N.

    Parameters
    ----------
    result: a :class:`~adept_traj.results.PlanningResult`.
    path: the PNG file to write.
    member: the row of ``result.front`` to draw, in [0, ``len(result.front)`` − 1];
        ``None`` (default): the best trade-off, ``result.best.index``.

    Returns
    -------
    pathlib.Path
        ``path``, the member's joint profiles against their limits.

    Raises
    ------
    InvalidInputError
        ``member`` is not an integer in [0, n − 1] (the message names the range).
    """
    r = as_result(result)
    out = png_path(path)
    index = member_index(r, member)
    best = index == r.best.index
    dense, limits = member_dense(r, index), r.limits
    t, nq = dense.t, dense.nq
    from matplotlib.collections import LineCollection, PatchCollection
    from matplotlib.lines import Line2D
    from matplotlib.patches import Rectangle

    fig = new_figure(4.0 * nq + 1.0, 13.5)
    n_rows = len(LIMITS)
    ax = hidden_axes(fig, _BOX, nq * _PITCH_X - _GAP_X, n_rows * _PITCH_Y - _GAP_Y)
    shift = shifter(ax)
    put = panel_texts(ax)
    t0, t1 = float(t[0]), float(t[-1])
    x_locs, x_texts, _ = tick_labels(t0, t1, 5)  # the columns share the time axis
    x_pos = (x_locs - t0) / (t1 - t0)
    u = (t - t0) / (t1 - t0)  # (n,) time in cell units
    curves, limit_lines, grid, boxes = [], [], [], []
    x_ticks: list[tuple[float, float]] = []
    y_ticks: list[tuple[float, float]] = []
    for row, kind in enumerate(LIMITS):
        data = getattr(dense, kind.quantity)
        title, units = _TITLES.get(kind.name, kind.name), kind.units
        y0 = (n_rows - 1 - row) * _PITCH_Y
        for j in range(nq):
            x0 = j * _PITCH_X
            boxes.append(Rectangle((x0, y0), 1.0, 1.0))
            unit = units[0] if limits.units[j] == "rad" else units[1]
            lines = _limit_lines(limits, kind.name, j)
            lo, hi = padded(min([data[:, j].min(), *lines]), max([data[:, j].max(), *lines]), 0.05)
            curves.append(np.column_stack([x0 + u, y0 + (data[:, j] - lo) / (hi - lo)]))
            limit_lines += [
                [(x0, y0 + (v - lo) / (hi - lo)), (x0 + 1.0, y0 + (v - lo) / (hi - lo))]
                for v in lines
            ]
            y_locs, y_texts, offset = tick_labels(lo, hi, 4)
            y_pos = y0 + (y_locs - lo) / (hi - lo)
            grid += [[(x0, y), (x0 + 1.0, y)] for y in y_pos]
            grid += [[(x0 + x, y0), (x0 + x, y0 + 1.0)] for x in x_pos]
            x_ticks += [(x0 + x, y0) for x in x_pos]
            y_ticks += [(x0, y) for y in y_pos]
            for y, text in zip(y_pos, y_texts):
                put(x0, y, text, transform=shift(-7.0, 0.0), fontsize=8, ha="right",
                    va="center")  # fmt: skip
            if offset:
                put(x0, y0 + 1.0, offset, transform=shift(0.0, 2.0), fontsize=8, va="bottom")
            # the label left of the widest tick label (about 0.62 em a character) [points]
            width = 7.0 + 0.62 * 8 * max((len(s) for s in y_texts), default=0) + 4.0
            put(x0, y0 + 0.5, f"{title} [{unit}]", transform=shift(-width, 0.0),
                fontsize=9, ha="right", va="center", rotation=90)  # fmt: skip
            note = _note(limits, kind.name, j, data[:, j])
            if note:
                put(
                    x0 + 0.98,
                    y0 + 0.04,
                    note,
                    ha="right",
                    va="bottom",
                    fontsize=8,
                    bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 1},
                    zorder=3,
                )
            if row == 0:
                joint_type = "revolute" if limits.units[j] == "rad" else "prismatic"
                put(
                    x0 + 0.5,
                    y0 + 1.0,
                    f"{limits.names[j]} ({joint_type})",
                    transform=shift(0.0, 6.0),
                    fontsize=11,
                    ha="center",
                    va="bottom",
                )
            if row == n_rows - 1:
                for x, text in zip(x_pos, x_texts):
                    put(x0 + x, y0, text, transform=shift(0.0, -7.0), fontsize=8,
                        ha="center", va="top")  # fmt: skip
                put(x0 + 0.5, y0, "time t [s]", transform=shift(0.0, -19.0),
                    fontsize=9, ha="center", va="top")  # fmt: skip
    ax.add_collection(LineCollection(grid, colors="#b0b0b0", alpha=0.3, lw=0.8, zorder=1.5))
    ax.add_collection(LineCollection(curves, colors="tab:blue", lw=1.3, zorder=2))
    ax.add_collection(LineCollection(limit_lines, colors="tab:red", linestyles="--", lw=1.0,
                                     zorder=2))  # fmt: skip
    ax.add_collection(PatchCollection(boxes, facecolors="none", edgecolors="black", lw=0.8,
                                      zorder=2.5))  # fmt: skip
    for ticks, marker in ((x_ticks, 3), (y_ticks, 0)):  # TICKDOWN, TICKLEFT: 3.5 pt long
        xs, ys = np.array(ticks).T
        ax.plot(xs, ys, ls="", marker=marker, ms=3.5, mew=0.8, color="black", clip_on=False)

    who = "best trade-off" if best else f"member {index}"

    fig.legend(
        handles=[
            Line2D([], [], color="tab:blue", label=f"{who} (dense certificate samples)"),
            Line2D([], [], color="tab:red", ls="--", label="limit (QC, VC, WC, JC, UC)"),
        ],
        loc="upper right",
        ncol=2,
        fontsize=9,
        bbox_to_anchor=(0.99, 0.965),
    )
    if best:
        what, T = "the best trade-off", float(r.best_objectives[0])
        verdict = f"{status(r)} at {r.certificate.rate_hz:g} Hz"
        details = violations_line(r)
    else:
        what, T = f"member {index} of the front", float(t[-1])
        verdict = "certified" if certified_members(r)[index] else "NOT certified"
        details = ""
    fig.suptitle(
        f"{display_name(r.algorithm)}: joint motion of {what}, T = {T:.3f} s ({verdict})" + details,
        fontsize=13,
        x=0.06,
        ha="left",
        y=0.975,
    )
    return save_figure(fig, out)
