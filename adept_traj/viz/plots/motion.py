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
from adept_traj.viz.plots.common import (
    display_name,
    new_figure,
    png_path,
    save_figure,
    status,
    violations_line,
)

__all__ = ["joint_motion"]

#: Row title of each limit kind (torque rows also hold the prismatic joint's force).
_TITLES = {"torque": "torque / force"}


def _limit_lines(limits: Any, kind: str, j: int) -> list[float]:
    if kind == "position":
        values = [float(limits.lower[j]), float(limits.upper[j])]
    else:
        v = float(limits.bound(kind)[j])
        values = [-v, v]
    return [v for v in values if math.isfinite(v)]


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
    The path written.

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
    from matplotlib.ticker import MaxNLocator

    fig = new_figure(4.0 * nq + 1.0, 13.5)
    axes = np.atleast_2d(fig.subplots(len(LIMITS), nq, sharex=True, squeeze=False))
    fig.subplots_adjust(left=0.06, right=0.99, bottom=0.05, top=0.92, wspace=0.32, hspace=0.2)
    for row, kind in enumerate(LIMITS):
        data = getattr(dense, kind.quantity)
        title, units = _TITLES.get(kind.name, kind.name), kind.units
        for j in range(nq):
            ax = axes[row, j]
            unit = units[0] if limits.units[j] == "rad" else units[1]
            ax.plot(t, data[:, j], color="tab:blue", lw=1.3)
            lines = _limit_lines(limits, kind.name, j)
            for v in lines:
                ax.axhline(v, color="tab:red", ls="--", lw=1.0)
            if kind.name == "position":
                span = float(limits.upper[j] - limits.lower[j])
                margin = min(
                    float(limits.upper[j] - data[:, j].max()),
                    float(data[:, j].min() - limits.lower[j]),
                )
                note = (
                    f"margin {100 * margin / span:.0f} % of range"
                    if math.isfinite(span) and span > 0
                    else ""
                )
            else:
                lim = float(limits.bound(kind.name)[j])
                peak = float(np.abs(data[:, j]).max())
                note = f"peak {100 * peak / lim:.0f} % of limit" if math.isfinite(lim) else ""
            if note:
                ax.text(
                    0.98,
                    0.04,
                    note,
                    transform=ax.transAxes,
                    ha="right",
                    va="bottom",
                    fontsize=8,
                    bbox={"fc": "white", "ec": "none", "alpha": 0.8, "pad": 1},
                )
            ax.set_ylabel(f"{title} [{unit}]", fontsize=9)
            ax.tick_params(labelsize=8)
            ax.grid(alpha=0.3)
            ax.yaxis.set_major_locator(MaxNLocator(4))  # fewer ticks: each is 4 artists
            if row == 0:
                joint_type = "revolute" if limits.units[j] == "rad" else "prismatic"
                ax.set_title(f"{limits.names[j]} ({joint_type})", fontsize=11)
            if row == len(LIMITS) - 1:
                ax.set_xlabel("time t [s]", fontsize=9)
    ax0 = axes[0, 0]
    ax0.xaxis.set_major_locator(MaxNLocator(5))  # shared by the columns' time axes
    from matplotlib.lines import Line2D

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
    ax0.set_xlim(float(t[0]), float(t[-1]))
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
