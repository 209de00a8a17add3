r"""The front explorer: one self-contained, offline HTML page per result folder
(``explorer.html``) to choose a member of the front.

The page is drawn by Plotly's JavaScript library (the copy bundled in the ``plotly`` Python
package, inlined: no network, no server; chosen because one file gives linked parallel
coordinates with brushing, scatter plots and a WebGL 3-D view). It shows:

- parallel coordinates of z1…z6, the clearance [m] and the worst limit ratio of every
  member (from its certificate, :class:`~adept_traj.analysis.MemberCertificate`), with
  brushing; certified members in colour, uncertified ones grey;
- a scatter plot of any two of those axes, linked to the brushing (members outside the
  brushed ranges faded), certified and uncertified told apart, the best trade-off marked;
- six weight sliders that recompute :math:`f_c` and the best trade-off in the page as
  :func:`adept_traj.analysis.best_tradeoff` does (bounds: the extremes of the front;
  ranks of :math:`f_c` and :math:`F_{avg}`; the first certified member in that order, as
  :func:`~adept_traj.plan` reports it);
- clicking a member plays it in a 3-D view (the robot as the chain of its joint origins
  and tool, the obstacles at their pose on the scene clock, each pendulum's pivot, the
  tool path), with its joint
  motion against the limits (computed in the page from the member's B-spline) and its
  certificate (guarantee, minimum distance, when and between what, worst ratios);
- downloads of the chosen member at a fixed step, the files of ``adept-traj export``
  (:mod:`adept_traj.export`; sampled in the page from the same B-spline).

Size: the page holds Plotly's library (≈ 4.8 MB), every member's decision vector in
float64 (exact; the downloads and joint plots are computed from it), and for the 3-D view
the joint origins and tool of every member at a coarse step (:data:`VIEW_DT`, float32),
the obstacles' meshes once and the moving ones' poses on one shared time grid. MODE's 500
members give about 8 MB (``docs/visualisation.md``).
"""

from __future__ import annotations

import base64
import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.analysis import PAPER_WEIGHTS
from adept_traj.certification import MemberCertificate
from adept_traj.export import DEFAULT_DT, csv_header
from adept_traj.files import write_text_atomic
from adept_traj.problem import OBJECTIVES
from adept_traj.results import PlanningResult, Replay, certified_members
from adept_traj.robot import Robot
from adept_traj.robot.limits import LIMIT_KINDS
from adept_traj.scene import Scene, shape_triangles
from adept_traj.validation import as_path, check_type
from adept_traj.viz.explorer_page import PAGE_TEMPLATE

__all__ = ["EXPLORER_FILE", "VIEW_DT", "explorer_data", "explorer_html", "write_explorer"]

#: The page's file name in a result folder.
EXPLORER_FILE = "explorer.html"
#: Time step [s] of the 3-D view's robot poses (the page interpolates between them).
VIEW_DT = 0.04
FIXED_COLOR, MOVING_COLOR = "#c0392b", "#8e44ad"


def _b64(values: np.ndarray, dtype: str) -> str:
    """Little-endian base64 of ``values`` as ``dtype`` (``"<f8"`` or ``"<f4"``)."""
    return base64.b64encode(np.ascontiguousarray(values, dtype=dtype).tobytes()).decode("ascii")


def _finite(value: float | None) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def _obstacles(scene: Scene, horizon: float) -> tuple[list[dict[str, Any]], float]:
    """The obstacles (mesh once; the pose, or the poses on the shared grid of step
    :data:`VIEW_DT` over [0, ``horizon``] for a moving one) and that grid's step [s]."""
    n = max(2, math.ceil(horizon / VIEW_DT - 1e-9) + 1)
    times = np.arange(n) * VIEW_DT
    poses = scene.obstacle_poses(times) if scene.obstacles else np.zeros((0, n, 4, 4))
    out = []
    for ob, pose in zip(scene.obstacles, poses, strict=True):
        v, f = shape_triangles(ob.shape)
        kept = pose if ob.is_moving else pose[:1]
        out.append(
            {
                "name": ob.name,
                "moving": bool(ob.is_moving),
                "color": MOVING_COLOR if ob.is_moving else FIXED_COLOR,
                "vertices": np.round(v, 6).tolist(),
                "faces": f.astype(int).tolist(),
                "poses": _b64(kept[:, :3, :], "<f4"),  # (n, 3, 4) row-major
                "n_poses": int(kept.shape[0]),
            }
        )
    return out, VIEW_DT


def _pivots(scene: Scene) -> list[dict[str, Any]]:
    """Each pendulum's pivot (:attr:`~adept_traj.scene.Scene.pendulums`): its name and the
    (3,) world point [m]."""
    return [{"name": n, "point": m.pivot.tolist()} for n, m in scene.pendulums.items()]


# ============================================================================ members
def _member_certificates(result: PlanningResult) -> list[MemberCertificate | None]:
    """Each member's certificate summary; the best trade-off's from its full certificate
    (every distance exact, as ``adept-traj front`` shows it)."""
    front = result.front
    certs = list(front.certificates) if front.certificates is not None else [None] * len(front)
    certs[result.best.index] = MemberCertificate.of(result.certificate)
    return certs


def _certificate_json(c: MemberCertificate | None, joint_names: tuple[str, ...]) -> Any:
    if c is None:
        return None
    return {
        "feasible": c.feasible,
        "guarantee": c.guarantee,
        "torque_guarantee": c.torque_guarantee,
        "worst": {
            kind: {"value": _finite(w), "joint": joint_names[j], "t": _finite(t)}
            for kind, w, j, t in zip(LIMIT_KINDS, c.worst, c.worst_joint, c.t_worst, strict=True)
        },
        "min_distance": _finite(c.min_distance),
        "min_distance_exact": c.min_distance_exact,
        "t_min_distance": _finite(c.t_min_distance),
        "closest_pair": list(c.closest_pair) if c.closest_pair else None,
        "distance_bound": _finite(c.distance_bound),
        "violations": list(c.violations),
    }


def _robot_points(robot: Robot, scene: Scene, q: np.ndarray) -> np.ndarray:
    """(n, p, 3) world positions [m] of the robot's base, joint origins and tool at the
    configurations ``q`` (n, nq)."""
    fk = robot.forward_kinematics(q)
    base = scene.robot_base
    joints = (base @ fk.joint_poses)[..., :3, 3]  # (n, njoints, 3), 0 = the base
    tool = (base @ fk.tool_pose)[:, None, :3, 3]
    return np.concatenate([joints, tool], axis=1)


def explorer_data(
    result: PlanningResult, *, robot: Robot | None = None, scene: Scene | None = None
) -> dict[str, Any]:
    """Everything the page shows, as a JSON-compatible dictionary (module docstring).

    Parameters
    ----------
    result: the planning result.
    robot, scene: the run's robot and scene when the caller has them; by default the
        result's robot files are loaded and its stored scene parsed
        (:meth:`~adept_traj.results.Replay.of`).
    """
    check_type(result, PlanningResult, "result")
    replay = Replay.of(result, robot=robot, scene=scene)
    robot, scene = replay.robot, replay.scene
    front = result.front
    n = len(front)
    T = front.x[:, 0]
    # --- the 3-D view: every member on its own coarse grid, in one FK call
    counts = np.maximum(2, np.ceil(T / VIEW_DT - 1e-9).astype(int) + 1)
    q_all = []
    for k in range(n):  # one spline sampling per member (its own T), then one FK
        s = np.minimum(np.arange(counts[k]) * VIEW_DT / T[k], 1.0)
        q_all.append(replay.trajectory.sample(front.x[k], s, orders=(0,)).q)
    points = _robot_points(robot, scene, np.concatenate(q_all))
    obstacles, scene_dt = _obstacles(scene, float(T.max()))
    certs = _member_certificates(result)
    names = tuple(result.robot.joint_names)
    clearance = [None if c is None else _finite(c.min_distance) for c in certs]
    ratio = [None if c is None else _finite(max(c.worst[1:])) for c in certs]
    lim = robot.limits
    return {
        "title": f"{result.algorithm} front, {n} members",
        "algorithm": result.algorithm,
        "objectives": [
            {"name": o.name, "label": o.label, "unit": o.unit, "maximised": o.maximised}
            for o in OBJECTIVES
        ],
        "F": front.objectives.tolist(),
        "certified": certified_members(result).tolist(),
        "best": int(result.best.index),
        "weights": list(PAPER_WEIGHTS),
        "clearance": clearance,
        "worst_ratio": ratio,
        "certificates": [_certificate_json(c, names) for c in certs],
        "joint_names": list(names),
        "joint_units": list(lim.units),
        "limits": {
            kind: [_finite(v) for v in np.asarray(getattr(lim, kind), float)]
            for kind in ("lower", "upper", "velocity", "acceleration", "jerk")
        },
        "spline": {
            "start": result.start.tolist(),
            "goal": result.goal.tolist(),
            "n_knots": int(result.problem_settings.n_knots),
            "n_var": int(front.x.shape[1]),
            "x": _b64(front.x, "<f8"),
        },
        "export_dt": DEFAULT_DT,
        "csv_header": csv_header(names, lim.units),
        "view": {
            "dt": VIEW_DT,
            "counts": counts.tolist(),
            "n_points": int(points.shape[1]),
            "points": _b64(points, "<f4"),
        },
        "obstacles": obstacles,
        "pivots": _pivots(scene),
        "scene_dt": scene_dt,
    }


def explorer_html(
    result: PlanningResult, *, robot: Robot | None = None, scene: Scene | None = None
) -> str:
    """The page's HTML text (:func:`explorer_data` and Plotly's library inlined)."""
    from plotly.offline import get_plotlyjs  # heavy: imported only here

    data = json.dumps(explorer_data(result, robot=robot, scene=scene), allow_nan=False)
    data = data.replace("</", "<\\/")  # never closes the script element
    return (
        PAGE_TEMPLATE.replace("@@PLOTLY@@", get_plotlyjs())
        .replace("@@TITLE@@", f"adept_traj explorer: {result.algorithm}")
        .replace("@@DATA@@", data)
    )


def write_explorer(
    result: PlanningResult,
    path: str | os.PathLike[str],
    *,
    robot: Robot | None = None,
    scene: Scene | None = None,
) -> Path:
    """Write ``explorer.html`` (:func:`explorer_html`) to ``path`` (folders created, a file
    replaced); return the path.

    Raises
    ------
    InvalidInputError: ``result`` not a PlanningResult, ``path`` not a path, an obstacle
        shape the page cannot draw.
    """
    check_type(result, PlanningResult, "result")
    out = as_path(path)
    return write_text_atomic(out, explorer_html(result, robot=robot, scene=scene))
