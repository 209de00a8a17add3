"""Work cycles: named locations, a sequence of moves, each move planned as a Dask task.

A cycle file (TOML, ``docs/cycles.md``) is read by :func:`read_cycle_file`;
:func:`run_cycle` plans its moves on a Dask cluster and saves each result as it finishes;
:func:`write_cycle_report` writes ``cycle.json``, ``cycle.md`` and a Gantt-like figure.
Dask (``distributed``) is imported only when a cycle runs."""

from __future__ import annotations

from adept_traj.cycle.cycle_file import (
    MAX_MOVES,
    Cycle,
    Location,
    MoveSpec,
    RobotSource,
    read_cycle_file,
)
from adept_traj.cycle.runner import (
    MOVE_FILE,
    MOVES_FOLDER,
    RETRIES,
    MoveTask,
    cycle_tasks,
    plan_move,
    run_cycle,
    run_planning_tasks,
    run_tasks,
)
from adept_traj.cycle.summary import (
    CYCLE_FILE,
    CYCLE_REPORT,
    GANTT_FIGURE,
    cycle_markdown,
    cycle_summary,
    save_gantt,
    write_cycle_report,
)

__all__ = [
    "CYCLE_FILE",
    "CYCLE_REPORT",
    "GANTT_FIGURE",
    "MAX_MOVES",
    "MOVES_FOLDER",
    "MOVE_FILE",
    "RETRIES",
    "Cycle",
    "Location",
    "MoveSpec",
    "MoveTask",
    "RobotSource",
    "cycle_markdown",
    "cycle_summary",
    "cycle_tasks",
    "plan_move",
    "read_cycle_file",
    "run_cycle",
    "run_planning_tasks",
    "run_tasks",
    "save_gantt",
    "write_cycle_report",
]
