"""Figures of planning results (the paper's Figs. 4–9) as PNG files.

Every function takes one :class:`~adept_traj.results.PlanningResult` or a mapping
``{name: PlanningResult}`` (e.g. ``{"nsga2": r1, "mode": r2}``), writes a PNG and returns
its :class:`~pathlib.Path`:

===========================  ==========================================================
:func:`pareto_matrix`        scatter matrix of z1…z6 of the fronts (Figs. 5–6)
:func:`best_tradeoffs`       the best trade-offs side by side, normalised bars (Fig. 7)
:func:`joint_motion`         q, q̇, q̈, q⃛ and u of every joint against time (Figs. 8–9)
:func:`tool_path_3d`         tool path, obstacles and pendulum in the world (Fig. 4)
:func:`hypervolume_history`  hypervolume (or feasible count) per generation
:func:`save_all`             all of the above into a folder
===========================  ==========================================================

matplotlib is imported lazily, inside the functions (``pip install 'adept-traj[plot]'``).
Figures are drawn on the Agg canvas directly: no pyplot state, no window, nothing is
shown, the caller's matplotlib backend is left alone. Units are SI. Bad arguments raise
:class:`~adept_traj.errors.InvalidInputError`. See ``docs/plots-and-export.md``.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from adept_traj.analysis.decision import normalise
from adept_traj.analysis.indicators import objective_bounds
from adept_traj.errors import InvalidInputError
from adept_traj.results.record import PlanningResult
from adept_traj.scene.scene import Scene
from adept_traj.scene.shapes import Box, Capsule, Cylinder, Sphere

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "OBJECTIVE_LABELS",
    "best_tradeoffs",
    "hypervolume_history",
    "joint_motion",
    "pareto_matrix",
    "save_all",
    "tool_path_3d",
]

#: Axis labels of z1…z6 with their units (z4 is maximised, the others minimised).
OBJECTIVE_LABELS = (
    "z1 time [s]",
    "z2 ∫Σu² [N²·m²·s]",
    "z3 clearance penalty [-]",
    "z4 min|det J| [m²] (max)",
    "z5 ∫Σq⃛² [rad²/s⁵]",
    "z6 ∫Σq̈² [rad²/s³]",
)

_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")
_MARKERS = ("o", "s", "^", "D", "v", "P")
_DPI = 110
_DISPLAY_NAMES = {
    "nsga2": "NSGA-II",
    "mode": "MODE",
    "nsga3": "NSGA-III",
    "unsga3": "U-NSGA-III",
    "smsemoa": "SMS-EMOA",
    "moead": "MOEA/D",
    "rvea": "RVEA",
}
_KINDS = (
    # (DenseTrajectory field, row title, unit suffix for rad / m joints, JointLimits field)
    ("q", "position", ("rad", "m"), None),
    ("qd", "velocity", ("rad/s", "m/s"), "velocity"),
    ("qdd", "acceleration", ("rad/s²", "m/s²"), "acceleration"),
    ("qddd", "jerk", ("rad/s³", "m/s³"), "jerk"),
    ("tau", "torque / force", ("N·m", "N"), "torque"),
)


# ============================================================================ validation
def _as_result(result: Any, name: str = "result") -> PlanningResult:
    if not isinstance(result, PlanningResult):
        raise InvalidInputError(f"{name} must be a PlanningResult; got {type(result).__name__}")
    return result


def _as_results(results: Any) -> dict[str, PlanningResult]:
    """``{name: result}`` from a mapping (or one result, named by its algorithm)."""
    if isinstance(results, PlanningResult):
        return {results.algorithm: results}
    if not isinstance(results, Mapping):
        raise InvalidInputError(
            "results must be a mapping {name: PlanningResult} (or one PlanningResult); got "
            f"{type(results).__name__}"
        )
    if not results:
        raise InvalidInputError("results must hold at least one PlanningResult")
    out: dict[str, PlanningResult] = {}
    for key, value in results.items():
        if not isinstance(key, str) or not key:
            raise InvalidInputError(f"results keys must be non-empty strings; got {key!r}")
        out[key] = _as_result(value, f"results[{key!r}]")
    if len(out) > len(_COLOURS):
        raise InvalidInputError(f"at most {len(_COLOURS)} results per figure; got {len(out)}")
    return out


def _display(algorithm: str) -> str:
    """The usual spelling of an algorithm's name (``"nsga2"`` → ``"NSGA-II"``)."""
    return _DISPLAY_NAMES.get(algorithm.lower(), algorithm)


def _labels(results: Mapping[str, PlanningResult]) -> dict[str, str]:
    """Legend label per key: the algorithm's name when unique, else key and name."""
    names = [_display(r.algorithm) for r in results.values()]
    if len(set(names)) == len(names):
        return dict(zip(results, names))
    return {k: f"{k} ({name})" for k, name in zip(results, names)}


def _png_path(path: Any) -> Path:
    try:
        out = Path(os.fspath(path))
    except TypeError:
        raise InvalidInputError(f"path must be a file path; got {type(path).__name__}") from None
    if out.suffix.lower() != ".png":
        raise InvalidInputError(f"path must name a .png file; got {str(out)!r}")
    out.parent.mkdir(parents=True, exist_ok=True)
    return out


def _file_suffix(key: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", key).strip("._") or "result"


# ============================================================================ matplotlib
def _figure(width: float, height: float) -> Figure:
    """A new figure on its own Agg canvas (no pyplot, no backend switch, never shown)."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover - matplotlib is in the test extra
        raise ImportError(
            "adept_traj.viz needs matplotlib: pip install 'adept-traj[plot]'"
        ) from exc
    fig = Figure(figsize=(width, height), dpi=_DPI)
    FigureCanvasAgg(fig)
    return fig


def _save(fig: Figure, path: Path) -> Path:
    fig.savefig(path, dpi=_DPI)
    return path


def _padded(lo: float, hi: float, frac: float = 0.06) -> tuple[float, float]:
    """Axis limits around [lo, hi], widened by ``frac`` of the span on each side; a
    single value v gets ±5 % of |v| (±0.05 for 0)."""
    span = hi - lo
    if span <= 1e-12 * max(abs(lo), abs(hi)) or span == 0.0:
        pad = 0.05 * abs(lo) if lo != 0.0 else 0.05
        return lo - pad, hi + pad
    return lo - frac * span, hi + frac * span


def _front_rows(result: PlanningResult) -> np.ndarray:
    """Objectives of the feasible front, or of the whole front if nothing is feasible."""
    feas = result.front.feasible
    return result.front.objectives[feas] if feas.any() else result.front.objectives


def _status(result: PlanningResult) -> str:
    return "verified feasible" if result.feasible else "NOT feasible"


def _violations(result: PlanningResult, at_most: int = 2) -> str:
    """A second title line listing the certificate's first violations (or nothing)."""
    v = result.certificate.violations
    if not v:
        return ""
    more = f"; {len(v) - at_most} more" if len(v) > at_most else ""
    return "\n" + "; ".join(v[:at_most]) + more


# ============================================================================ Figs. 5–6
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
    res = _as_results(results)
    out = _png_path(path)
    from matplotlib.lines import Line2D
    from matplotlib.ticker import MaxNLocator, ScalarFormatter

    labels = _labels(res)
    m = len(OBJECTIVE_LABELS)
    allobj = np.vstack([r.front.objectives for r in res.values()])
    limits = [_padded(float(allobj[:, j].min()), float(allobj[:, j].max()), 0.09) for j in range(m)]

    # histogram heights: share of each front per bin, on one scale for all results
    peak = max(
        np.histogram(r.front.objectives[:, j], bins=np.linspace(*limits[j], 13))[0].max()
        / len(r.front)
        for r in res.values()
        for j in range(m)
    )
    fig = _figure(15.0, 15.0)
    axes = fig.subplots(m, m)
    fig.subplots_adjust(left=0.08, right=0.98, bottom=0.07, top=0.9, wspace=0.08, hspace=0.08)
    for k, r in enumerate(res.values()):
        colour, marker = _COLOURS[k], _MARKERS[k]
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
                ax.scatter(x[feas], y[feas], s=16, marker=marker, color=colour, alpha=0.75, lw=0)
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
            for axis in (ax.xaxis, ax.yaxis):
                axis.set_major_locator(MaxNLocator(3))
                fmt = ScalarFormatter(useMathText=True)
                fmt.set_powerlimits((-2, 3))
                axis.set_major_formatter(fmt)
                axis.get_offset_text().set_fontsize(7)
            ax.tick_params(labelsize=7, length=2)
            if i < m - 1:
                ax.tick_params(labelbottom=False)
            else:
                ax.set_xlabel(OBJECTIVE_LABELS[j], fontsize=9)
            if j > 0:
                ax.tick_params(labelleft=False)
            else:
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
        Line2D([], [], ls="", marker=_MARKERS[k], color=_COLOURS[k], label=labels[key])
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
    return _save(fig, out)


# ============================================================================ Fig. 7
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
    The path written.
    """
    res = _as_results(results)
    out = _png_path(path)
    labels = _labels(res)
    bests = np.array([r.best_objectives for r in res.values()])
    lo, hi = objective_bounds(*[_front_rows(r) for r in res.values()], bests)
    scores = normalise(bests, lo, hi)
    m, n = bests.shape[1], len(res)

    fig = _figure(12.0, 6.5)
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
            color=_COLOURS[k],
            alpha=0.85,
            edgecolor=_COLOURS[k],
            linewidth=1.5,  # a zero score still shows as a line
            label=f"{labels[key]} (F_avg on these bounds {scores[k].mean():.3f}, {_status(r)})",
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
    return _save(fig, out)


# ============================================================================ Figs. 8–9
def _limit_lines(limits: Any, field: str | None, j: int) -> list[float]:
    if field is None:
        values = [float(limits.lower[j]), float(limits.upper[j])]
    else:
        v = float(getattr(limits, field)[j])
        values = [-v, v]
    return [v for v in values if math.isfinite(v)]


def joint_motion(result: PlanningResult, path: str | os.PathLike[str]) -> Path:
    """Position, velocity, acceleration, jerk and torque of every joint against time
    (Figs. 8–9), from the certified dense trajectory of the best trade-off.

    One row per quantity, one column per joint; the limits are dashed lines (position:
    lower and upper; the others ±limit; an infinite limit is not drawn). Each panel
    states the peak as a percentage of its limit (position: the smallest margin to a
    limit as a percentage of the range). Units: rad or m per joint, and their time
    derivatives; torque N·m, force N.

    Parameters
    ----------
    result: a :class:`PlanningResult`.
    path: the PNG file to write.

    Returns
    -------
    The path written.
    """
    r = _as_result(result)
    out = _png_path(path)
    dense, limits = r.best_trajectory, r.limits
    t, nq = dense.t, dense.nq
    fig = _figure(4.0 * nq + 1.0, 13.5)
    axes = np.atleast_2d(fig.subplots(len(_KINDS), nq, sharex=True, squeeze=False))
    fig.subplots_adjust(left=0.06, right=0.99, bottom=0.05, top=0.92, wspace=0.32, hspace=0.2)
    for row, (name, title, units, field) in enumerate(_KINDS):
        data = getattr(dense, name)
        for j in range(nq):
            ax = axes[row, j]
            unit = units[0] if limits.units[j] == "rad" else units[1]
            ax.plot(t, data[:, j], color="tab:blue", lw=1.3)
            lines = _limit_lines(limits, field, j)
            for v in lines:
                ax.axhline(v, color="tab:red", ls="--", lw=1.0)
            if field is None:
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
                lim = float(getattr(limits, field)[j])
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
            if row == 0:
                kind = "revolute" if limits.units[j] == "rad" else "prismatic"
                ax.set_title(f"{limits.names[j]} ({kind})", fontsize=11)
            if row == len(_KINDS) - 1:
                ax.set_xlabel("time t [s]", fontsize=9)
    ax0 = axes[0, 0]
    from matplotlib.lines import Line2D

    fig.legend(
        handles=[
            Line2D([], [], color="tab:blue", label="best trade-off (dense certificate samples)"),
            Line2D([], [], color="tab:red", ls="--", label="limit (QC, VC, WC, JC, UC)"),
        ],
        loc="upper right",
        ncol=2,
        fontsize=9,
        bbox_to_anchor=(0.99, 0.965),
    )
    ax0.set_xlim(float(t[0]), float(t[-1]))
    fig.suptitle(
        f"{_display(r.algorithm)}: joint motion of the best trade-off, "
        f"T = {r.best_objectives[0]:.3f} s "
        f"({_status(r)} at {r.certificate.rate_hz:g} Hz)" + _violations(r),
        fontsize=13,
        x=0.06,
        ha="left",
        y=0.975,
    )
    return _save(fig, out)


# ============================================================================ Fig. 4
def _circle(
    centre: np.ndarray, u: np.ndarray, v: np.ndarray, radius: float, n: int = 40
) -> np.ndarray:
    a = np.linspace(0.0, 2.0 * np.pi, n)
    return centre + radius * (np.cos(a)[:, None] * u + np.sin(a)[:, None] * v)


def _wireframe(kind: str, dims: Sequence[float], pose: np.ndarray) -> list[np.ndarray]:
    """Polylines (each (k, 3), world frame) outlining a solid of the given pose.

    kind: ``"box"`` (dims: half sides), ``"sphere"`` (radius), ``"cylinder"`` and
    ``"capsule"`` (radius, half length along local z).
    """
    rot, c = pose[:3, :3], pose[:3, 3]
    ex, ey, ez = rot[:, 0], rot[:, 1], rot[:, 2]
    if kind == "box":
        h = np.asarray(dims, dtype=float)
        corners = np.array(
            [[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float
        )
        world = c + (corners * h) @ rot.T
        edges = [(a, b) for a in range(8) for b in range(a + 1, 8) if bin(a ^ b).count("1") == 1]
        return [world[[a, b]] for a, b in edges]
    if kind == "sphere":
        (rad,) = dims
        return [_circle(c, p, q, rad) for p, q in ((ex, ey), (ey, ez), (ez, ex))]
    if kind in ("cylinder", "capsule"):
        rad, half = dims
        lines = [_circle(c + s * half * ez, ex, ey, rad) for s in (-1, 1)]
        for a in np.linspace(0, 2 * np.pi, 4, endpoint=False):
            d = rad * (np.cos(a) * ex + np.sin(a) * ey)
            lines.append(np.array([c - half * ez + d, c + half * ez + d]))
        if kind == "capsule":
            a = np.linspace(0, np.pi, 20)[:, None]
            for s in (-1, 1):
                for p in (ex, ey):
                    lines.append(c + s * half * ez + rad * (np.cos(a) * p + s * np.sin(a) * ez))
        return lines
    return []


def _shape_wireframe(shape: Any, pose: np.ndarray) -> list[np.ndarray]:
    """Wireframe of an adept_traj shape (Box, Sphere, Cylinder, Capsule)."""
    if isinstance(shape, Box):
        return _wireframe("box", 0.5 * shape.size, pose)
    if isinstance(shape, Sphere):
        return _wireframe("sphere", (shape.radius,), pose)
    if isinstance(shape, Cylinder):
        return _wireframe("cylinder", (shape.radius, 0.5 * shape.length), pose)
    if isinstance(shape, Capsule):
        return _wireframe("capsule", (shape.radius, 0.5 * shape.length), pose)
    return []


def _coal_wireframe(geometry: Any, pose: np.ndarray) -> list[np.ndarray]:
    """Wireframe of a coal collision geometry (robot solids)."""
    kind = type(geometry).__name__
    if kind == "Box":
        return _wireframe("box", np.asarray(geometry.halfSide, dtype=float), pose)
    if kind == "Sphere":
        return _wireframe("sphere", (float(geometry.radius),), pose)
    if kind in ("Cylinder", "Capsule"):
        dims = (float(geometry.radius), float(geometry.halfLength))
        return _wireframe(kind.lower(), dims, pose)
    return []


def tool_path_3d(result: PlanningResult, path: str | os.PathLike[str]) -> Path:
    """The tool path of the best trade-off in 3-D, world frame (Fig. 4).

    Left, in 3-D with equal scale on the three axes: the tool path
    ``robot_base @ tool_pose(q(t))`` coloured by time, its start and goal, the tool's
    position at the closest approach of the robot to an obstacle (from the certificate),
    the robot's collision solids at the start and the goal (grey wireframes), the fixed
    obstacles (boxes, spheres, cylinders and capsules as wireframes), every moving obstacle
    at t = 0 and t = T and the centre path of every moving sphere (the pendulum bob) over
    the motion. Right, the same zoomed on the tool path and projected on the world x–y
    plane (top view) and y–z plane (side view, looking along −x), equal scale.

    Parameters
    ----------
    result: a :class:`PlanningResult` (its robot files must exist: the robot is rebuilt
        with ``result.robot.load()``).
    path: the PNG file to write.

    Returns
    -------
    The path written.
    """
    r = _as_result(result)
    out = _png_path(path)
    import mpl_toolkits.mplot3d  # noqa: F401  (registers the 3-D projection)
    from matplotlib import colormaps
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    robot = r.robot.load()
    scene = Scene.from_dict(r.scene, source="result scene")
    base = scene.robot_base
    dense = r.best_trajectory
    t, T = dense.t, float(dense.t[-1])
    tool = (base @ robot.tool_pose(dense.q))[:, :3, 3]

    # everything but the tool path, as (polylines, style) layers in the world frame
    layers: list[tuple[list[np.ndarray], dict[str, Any]]] = []
    for q, alpha in ((dense.q[0], 0.55), (dense.q[-1], 0.25)):
        lines = []
        for g, pose in zip(robot.collision_model.geometryObjects, base @ robot.geometry_poses(q)):
            lines += _coal_wireframe(g.geometry, pose)
        layers.append((lines, {"colors": "dimgrey", "linewidths": 0.7, "alpha": alpha}))
    for ob in scene.fixed:
        layers.append(
            (_shape_wireframe(ob.shape, ob.pose(0.0)), {"colors": "saddlebrown", "linewidths": 1.3})
        )
    for ob in scene.moving:
        for ts, alpha in ((0.0, 0.35), (T, 0.9)):
            style = {"colors": "tab:red", "linewidths": 1.0, "alpha": alpha}
            layers.append((_shape_wireframe(ob.shape, ob.pose(ts)), style))
        if isinstance(ob.shape, Sphere):
            centre = ob.pose(t)[:, :3, 3]
            style = {"colors": "tab:red", "linewidths": 1.4, "linestyles": "--"}
            layers.append(([centre], style))

    fig = _figure(15.5, 9.5)
    grid = fig.add_gridspec(2, 2, width_ratios=(1.3, 1.0), left=0.0, right=0.92, bottom=0.06,
                            top=0.9, wspace=0.0, hspace=0.22)  # fmt: skip
    ax = fig.add_subplot(grid[:, 0], projection="3d")
    views = (
        (fig.add_subplot(grid[0, 1]), (0, 1), "top view (x–y), zoomed on the tool path"),
        (fig.add_subplot(grid[1, 1]), (1, 2), "side view (y–z, looking along −x), zoomed"),
    )
    norm = Normalize(0.0, T)
    cmap = colormaps["viridis"]
    t_mid = 0.5 * (t[:-1] + t[1:])
    k_close = None
    if r.certificate.t_min_distance is not None and math.isfinite(r.certificate.min_distance):
        k_close = int(np.argmin(np.abs(t - r.certificate.t_min_distance)))

    # ---- 3-D
    for lines, style in layers:
        if lines:
            ax.add_collection3d(Line3DCollection(lines, **style))
    segments = np.stack([tool[:-1], tool[1:]], axis=1)
    path3 = Line3DCollection(segments, cmap=cmap, norm=norm, linewidths=2.6)
    path3.set_array(t_mid)
    ax.add_collection3d(path3)
    marks = {"depthshade": False, "zorder": 6, "edgecolors": "black"}
    ax.scatter(*tool[0], s=60, color=cmap(0.0), **marks)
    ax.scatter(*tool[-1], s=60, color=cmap(1.0), marker="s", **marks)
    if k_close is not None:
        ax.scatter(*tool[k_close], s=90, marker="X", color="black", depthshade=False, zorder=7)
    ax.scatter(*base[:3, 3], s=50, marker="^", color="dimgrey", depthshade=False)
    allp = np.vstack([tool, base[None, :3, 3], *(np.vstack(ls) for ls, _ in layers if ls)])
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    pad = 0.03 * float((hi - lo).max())
    lo, hi = lo - pad, hi + pad
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(hi - lo), zoom=0.95)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.view_init(elev=24, azim=-60)

    # ---- 2-D projections, zoomed on the tool path
    centre = 0.5 * (tool.min(axis=0) + tool.max(axis=0))
    half = 0.5 * float((tool.max(axis=0) - tool.min(axis=0)).max()) + 0.12
    close_layer: list[np.ndarray] = []  # the robot at the closest approach (2-D views)
    if k_close is not None:
        poses = base @ robot.geometry_poses(dense.q[k_close])
        for g, pose in zip(robot.collision_model.geometryObjects, poses):
            close_layer += _coal_wireframe(g.geometry, pose)
    close_style = {"colors": "black", "linewidths": 0.9, "linestyles": ":"}
    for axv, dims, title in views:
        i, j = dims
        for lines, style in (*layers, (close_layer, close_style)):
            if lines:
                axv.add_collection(LineCollection([ln[:, dims] for ln in lines], **style))
        path2 = LineCollection(segments[:, :, dims], cmap=cmap, norm=norm, linewidths=2.6)
        path2.set_array(t_mid)
        axv.add_collection(path2)
        axv.scatter(*tool[0, dims], s=50, color=cmap(0.0), edgecolors="black", zorder=6)
        axv.scatter(*tool[-1, dims], s=50, color=cmap(1.0), edgecolors="black", marker="s",
                    zorder=6)  # fmt: skip
        if k_close is not None:
            axv.scatter(*tool[k_close, dims], s=80, marker="X", color="black", zorder=7)
        axv.set_xlim(centre[i] - half, centre[i] + half)
        axv.set_ylim(centre[j] - half, centre[j] + half)
        axv.set_aspect("equal", adjustable="box")
        axv.set_xlabel(f"{'xyz'[i]} [m]")
        axv.set_ylabel(f"{'xyz'[j]} [m]")
        axv.set_title(title, fontsize=10)
        axv.grid(alpha=0.3)
    cb = fig.colorbar(path3, ax=[v[0] for v in views], shrink=0.8, pad=0.03)
    cb.set_label("time along the tool path t [s]")

    closest = ""
    pair = r.certificate.closest_pair
    if k_close is not None and pair is not None:
        closest = (
            f"tool at the closest approach: {r.certificate.min_distance:.3f} m "
            f"at t = {r.certificate.t_min_distance:.3f} s ({' – '.join(pair)})"
        )
    handles = [
        Line2D([], [], color=cmap(0.6), lw=2.6, label="tool path (colour: time)"),
        Line2D([], [], ls="", marker="o", color=cmap(0.0), mec="black", label="start"),
        Line2D([], [], ls="", marker="s", color=cmap(1.0), mec="black", label="goal"),
    ]
    if scene.fixed:
        handles.append(Line2D([], [], color="saddlebrown", label="fixed obstacles"))
    if scene.moving:
        label = "moving obstacles at t = 0 (light), T"
        handles.append(Line2D([], [], color="tab:red", alpha=0.5, label=label))
    if any(isinstance(ob.shape, Sphere) for ob in scene.moving):
        label = "moving sphere (bob) centre over [0, T]"
        handles.append(Line2D([], [], color="tab:red", ls="--", label=label))
    handles += [
        Line2D([], [], color="dimgrey", label="robot solids at start (dark), goal (light)"),
        Line2D([], [], ls="", marker="^", color="dimgrey", label="robot base"),
    ]
    if closest:
        handles.append(Line2D([], [], ls="", marker="X", color="black", label=closest))
        handles.append(
            Line2D([], [], color="black", ls=":", label="robot solids then (right-hand views)")
        )
    ax.legend(handles=handles, loc="upper left", fontsize=8, bbox_to_anchor=(0.03, 1.02))
    fig.suptitle(
        f"{_display(r.algorithm)}: tool path of the best trade-off in the world frame, "
        f"T = {T:.3f} s ({_status(r)})" + _violations(r),
        fontsize=13,
    )
    return _save(fig, out)


# ============================================================================ history
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
    The path written.

    Raises
    ------
    InvalidInputError
        No result has a history (``result.history is None`` or empty).
    """
    res = _as_results(result_or_results)
    out = _png_path(path)
    labels = _labels(res)
    have = {k: r.history for k, r in res.items() if r.history}
    if not have:
        raise InvalidInputError("no result has a per-generation history to plot")
    use_hv = _records_hypervolume(have.values())

    fig = _figure(9.0, 5.5)
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
        ax.plot(g, v, color=_COLOURS[k], marker=_MARKERS[k], ms=3.5, lw=1.4, label=label)
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
    return _save(fig, out)


# ============================================================================ all
def save_all(
    results: Mapping[str, PlanningResult] | PlanningResult, folder: str | os.PathLike[str]
) -> list[Path]:
    """Write every figure into ``folder`` (created if needed).

    Files: ``pareto_matrix.png``, ``best_tradeoffs.png``, ``hypervolume_history.png``
    (left out when no result has a history) for all results together, and per result
    ``joint_motion_<name>.png`` and ``tool_path_<name>.png`` (``<name>``: the mapping key,
    characters other than letters, digits, ``_ . -`` replaced by ``_``).

    Returns
    -------
    The paths written, in that order.
    """
    res = _as_results(results)
    try:
        root = Path(os.fspath(folder))
    except TypeError:
        raise InvalidInputError(f"folder must be a path; got {type(folder).__name__}") from None
    suffixes = {key: _file_suffix(key) for key in res}
    if len(set(suffixes.values())) != len(suffixes):
        raise InvalidInputError(f"result names give clashing file names: {list(res)}")
    root.mkdir(parents=True, exist_ok=True)
    written = [
        pareto_matrix(res, root / "pareto_matrix.png"),
        best_tradeoffs(res, root / "best_tradeoffs.png"),
    ]
    if any(r.history for r in res.values()):
        written.append(hypervolume_history(res, root / "hypervolume_history.png"))
    for key, r in res.items():
        written.append(joint_motion(r, root / f"joint_motion_{suffixes[key]}.png"))
        written.append(tool_path_3d(r, root / f"tool_path_{suffixes[key]}.png"))
    return written
