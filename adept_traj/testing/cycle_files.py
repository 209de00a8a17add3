"""Cycle files (``docs/cycles.md``) for the tests and the benchmarks, written in one place.

:func:`cycle_text` writes the TOML of a cycle from Python values (top-level keys, ``[plan]``,
``[dwell]``, the locations and the moves, in that order, one ``key = value`` a line and a
blank line after each table); :func:`write_cycle` writes it into a folder beside the scene
files it names. :data:`HOME` and :data:`PLACE` are the paper's start and goal joints, the
two locations most cycles of the tests run between.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

__all__ = ["EMPTY_SCENE", "HOME", "PLACE", "cycle_text", "write_cycle"]

#: The paper's start (θ1 [rad], θ2 [rad], d3 [m], θ4 [rad]).
HOME = (0.1682, 1.3849, 0.08, -0.7555)
#: The paper's goal (θ1 [rad], θ2 [rad], d3 [m], θ4 [rad]).
PLACE = (-0.761, 0.245, 0.2, 1.0095)
#: A scene file without obstacles.
EMPTY_SCENE = 'name = "empty"\n'


def _value(v: Any) -> str:
    """``v`` as a TOML value (strings, booleans, numbers and lists of them)."""
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    return repr(v) if isinstance(v, float) else str(v)


def _table(header: str, entries: Mapping[str, Any]) -> str:
    return "".join([f"{header}\n", *(f"{k} = {_value(v)}\n" for k, v in entries.items()), "\n"])


def cycle_text(
    name: str,
    *,
    scene: str,
    locations: Mapping[str, Mapping[str, Any]],
    moves: Sequence[tuple[str, str] | Mapping[str, Any]],
    repeat: int | None = None,
    plan: Mapping[str, Any] | None = None,
    dwell: Mapping[str, Any] | None = None,
) -> str:
    """The text of a cycle file.

    Parameters
    ----------
    name, scene, repeat: the top-level keys (``repeat`` left out when ``None``).
    locations: per location name its keys (``{"joints": HOME}``, ``{"pose": …, "elbow":
        "righty"}``), in order.
    moves: per move ``(from, to)`` or the mapping of its keys (``{"from": "home", "to":
        "place", "choose": "fastest"}``).
    plan, dwell: the ``[plan]`` and ``[dwell]`` tables (left out when ``None``).
    """
    head = {"name": name, "scene": scene}
    if repeat is not None:
        head["repeat"] = repeat
    parts = ["".join(f"{k} = {_value(v)}\n" for k, v in head.items()) + "\n"]
    if plan is not None:
        parts.append(_table("[plan]", plan))
    if dwell is not None:
        parts.append(_table("[dwell]", dwell))
    for where, keys in locations.items():
        parts.append(_table("[[location]]", {"name": where, **keys}))
    for move in moves:
        keys = {"from": move[0], "to": move[1]} if isinstance(move, tuple) else dict(move)
        parts.append(_table("[[move]]", keys))
    return "".join(parts).rstrip("\n") + "\n"


def write_cycle(
    folder: str | os.PathLike[str],
    text: str,
    *,
    file: str = "c.toml",
    scenes: Mapping[str, str] | None = None,
) -> Path:
    """Write the cycle ``text`` into ``folder/file`` and each of ``scenes`` (file name →
    text; default: ``empty.toml``, :data:`EMPTY_SCENE`) beside it; return the cycle file."""
    where = Path(folder)
    for scene_name, scene_text in (
        {"empty.toml": EMPTY_SCENE} if scenes is None else scenes
    ).items():
        (where / scene_name).write_text(scene_text, encoding="utf-8")
    path = where / file
    path.write_text(text, encoding="utf-8")
    return path
