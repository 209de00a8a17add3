"""Every figure of one or more results into a folder: :func:`save_all`."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from adept_traj.errors import InvalidInputError
from adept_traj.results import PlanningResult, Replay
from adept_traj.validation import check_type
from adept_traj.viz.inputs import replay_for
from adept_traj.viz.plots.common import as_results, file_suffix
from adept_traj.viz.plots.fronts import pareto_matrix
from adept_traj.viz.plots.history import hypervolume_history
from adept_traj.viz.plots.motion import joint_motion
from adept_traj.viz.plots.tool_path import tool_path_3d
from adept_traj.viz.plots.tradeoffs import best_tradeoffs

__all__ = ["save_all"]


def save_all(
    results: Mapping[str, PlanningResult] | PlanningResult,
    folder: str | os.PathLike[str],
    *,
    replays: Mapping[str, Replay] | None = None,
) -> list[Path]:
    """Write every figure into ``folder`` (created if needed).

    Files: ``pareto_matrix.png``, ``best_tradeoffs.png``, ``hypervolume_history.png``
    (left out when no result has a history) for all results together, and per result
    ``joint_motion_<name>.png`` and ``tool_path_<name>.png`` (``<name>``: the mapping key,
    characters other than letters, digits, ``_ . -`` replaced by ``_``).

    Parameters
    ----------
    results: ``{name: PlanningResult}`` (at most six), or one result (named by its
        algorithm).
    folder: where the PNG files go.
    replays: ``{name: Replay}`` for the results whose
        :class:`~adept_traj.results.Replay` (robot and scene) the caller already has, each
        of its result's best solution; the others are built with ``Replay.of(result)``
        (for :func:`~adept_traj.viz.plots.tool_path_3d`).

    Returns
    -------
    The paths written, in that order.
    """
    res = as_results(results)
    try:
        root = Path(os.fspath(folder))
    except TypeError:
        raise InvalidInputError(f"folder must be a path; got {type(folder).__name__}") from None
    suffixes = {key: file_suffix(key) for key in res}
    if len(set(suffixes.values())) != len(suffixes):
        raise InvalidInputError(f"result names give clashing file names: {list(res)}")
    given = _replays(replays, res)
    root.mkdir(parents=True, exist_ok=True)
    written = [
        pareto_matrix(res, root / "pareto_matrix.png"),
        best_tradeoffs(res, root / "best_tradeoffs.png"),
    ]
    if any(r.history for r in res.values()):
        written.append(hypervolume_history(res, root / "hypervolume_history.png"))
    for key, r in res.items():
        written.append(joint_motion(r, root / f"joint_motion_{suffixes[key]}.png"))
        path = root / f"tool_path_{suffixes[key]}.png"
        written.append(tool_path_3d(r, path, replay=given.get(key)))
    return written


def _replays(replays: Any, results: Mapping[str, PlanningResult]) -> dict[str, Replay]:
    """The caller's replays by result name, checked before anything is drawn."""
    if replays is None:
        return {}
    check_type(replays, Mapping, "replays")
    unknown = [key for key in replays if key not in results]
    if unknown:
        raise InvalidInputError(f"replays names no result: {unknown}; results: {list(results)}")
    return {key: replay_for(results[key], value) for key, value in replays.items()}
