"""The tool path of the best trade-off in the scene, world frame (the paper's Fig. 4)."""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.results import PlanningResult, Replay
from adept_traj.robot import Robot
from adept_traj.scene import Scene, Sphere
from adept_traj.viz.inputs import as_result, replay_for
from adept_traj.viz.plots.common import (
    display_name,
    new_figure,
    png_path,
    save_figure,
    status,
    violations_line,
)
from adept_traj.viz.plots.wireframes import shape_wireframe, solid_wireframe

__all__ = ["tool_path_3d"]


def _layers(
    robot: Robot, scene: Scene, q: np.ndarray, t: np.ndarray
) -> list[tuple[list[np.ndarray], dict[str, Any]]]:
    """Everything but the tool path, as (polylines, line style) layers in the world frame:
    the robot's solids at the first and last of the samples ``q`` (n, nq) [rad | m], the
    fixed obstacles, the moving ones at the first and last of the scene times ``t`` (n,)
    [s] and the centre path of every moving sphere over them."""
    base = scene.robot_base
    solids = robot.collision_model.geometryObjects
    layers: list[tuple[list[np.ndarray], dict[str, Any]]] = []
    for poses, alpha in zip(base @ robot.geometry_poses(q[[0, -1]]), (0.55, 0.25)):
        lines = []
        for g, pose in zip(solids, poses):
            lines += solid_wireframe(g.geometry, pose)
        layers.append((lines, {"colors": "dimgrey", "linewidths": 0.7, "alpha": alpha}))
    for ob in scene.fixed:
        layers.append(
            (shape_wireframe(ob.shape, ob.pose(0.0)), {"colors": "saddlebrown", "linewidths": 1.3})
        )
    for ob in scene.moving:
        for ts, alpha in ((float(t[0]), 0.35), (float(t[-1]), 0.9)):
            style = {"colors": "tab:red", "linewidths": 1.0, "alpha": alpha}
            layers.append((shape_wireframe(ob.shape, ob.pose(ts)), style))
        if isinstance(ob.shape, Sphere):
            centre = ob.pose(t)[:, :3, 3]
            style = {"colors": "tab:red", "linewidths": 1.4, "linestyles": "--"}
            layers.append(([centre], style))
    return layers


def _one_style_per_line(
    layers: list[tuple[list[np.ndarray], dict[str, Any]]],
) -> tuple[list[np.ndarray], dict[str, Any]]:
    """The polylines of every layer in order and the style of one collection drawing them
    as the layers' collections would, one after the other (colours with their alpha, line
    widths and styles per line)."""
    from matplotlib.colors import to_rgba

    lines: list[np.ndarray] = []
    style: dict[str, list[Any]] = {"colors": [], "linewidths": [], "linestyles": []}
    for polylines, st in layers:
        n = len(polylines)
        lines += polylines
        style["colors"] += [to_rgba(st["colors"], st.get("alpha"))] * n
        style["linewidths"] += [st["linewidths"]] * n
        style["linestyles"] += [st.get("linestyles", "solid")] * n
    return lines, style


def tool_path_3d(
    result: PlanningResult, path: str | os.PathLike[str], *, replay: Replay | None = None
) -> Path:
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
    result: a :class:`~adept_traj.results.PlanningResult`.
    path: the PNG file to write.
    replay: the result's :class:`~adept_traj.results.Replay` (robot and scene) if the
        caller has one (it must replay ``result.best_x``); default ``Replay.of(result)``,
        which loads the robot files named in the result (they must exist) and parses its
        stored scene.

    Returns
    -------
    pathlib.Path
        ``path``, the tool path in the scene and its two projections.
    """
    r = as_result(result)
    out = png_path(path)
    import mpl_toolkits.mplot3d  # noqa: F401  (registers the 3-D projection)
    from matplotlib import colormaps
    from matplotlib.collections import LineCollection
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    replay = replay_for(r, replay)
    robot, scene = replay.robot, replay.scene
    base = scene.robot_base
    dense = r.best_trajectory
    t, T = dense.t, float(dense.t[-1])
    tool = (base @ robot.tool_pose(dense.q))[:, :3, 3]
    layers = _layers(robot, scene, dense.q, replay.scene_time(t))  # the scene's clock

    fig = new_figure(15.5, 9.5)
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
            # one colour map for all (a collection without copies matplotlib's default)
            ax.add_collection3d(Line3DCollection(lines, cmap=cmap, **style), autolim=False)
    segments = np.stack([tool[:-1], tool[1:]], axis=1)
    path3 = Line3DCollection(segments, cmap=cmap, norm=norm, linewidths=2.6)
    path3.set_array(t_mid)
    ax.add_collection3d(path3, autolim=False)  # the limits are set below
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
            close_layer += solid_wireframe(g.geometry, pose)
    close_style = {"colors": "black", "linewidths": 0.9, "linestyles": ":"}
    flat, flat_style = _one_style_per_line([*layers, (close_layer, close_style)])
    for axv, dims, title in views:
        i, j = dims
        if flat:  # every layer in one collection, in the same order
            flat2 = [ln[:, dims] for ln in flat]
            axv.add_collection(LineCollection(flat2, cmap=cmap, **flat_style))
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
        axv.set_title(title, fontsize=10, y=1.0)  # where matplotlib puts it, not searched
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
        f"{display_name(r.algorithm)}: tool path of the best trade-off in the world frame, "
        f"T = {T:.3f} s ({status(r)})" + violations_line(r),
        fontsize=13,
    )
    return save_figure(fig, out)
