"""Planning at scale on Dask: work cycles (named locations, a sequence of moves, each move
a task) and seed studies (NSGA-II vs MODE over many seeds, each run a task).

A cycle file (TOML, ``docs/cycles.md``) is read by :func:`read_cycle_file`;
:func:`run_cycle` plans its moves on a Dask cluster and saves each result as it finishes;
:func:`write_cycle_report` writes ``cycle.json``, ``cycle.md`` and a Gantt-like figure;
:func:`run_seed_study`, :func:`study_statistics` and :func:`write_study_report` make
``adept-traj compare --seeds``.
Dask (``distributed``) is imported only when a cycle runs."""

from __future__ import annotations

from adept_traj.cycle.certified_schedule import (
    ScheduleChoice,
    certified_schedules,
    schedule_span,
)
from adept_traj.cycle.chained import ChainPlan, chained_clock
from adept_traj.cycle.choice import chosen_member
from adept_traj.cycle.clock import (
    MAX_CLOCKED_MOVES,
    check_chained,
    dwell_grid,
    plan_on_clock,
    scene_period,
)
from adept_traj.cycle.cycle_file import (
    CHOICES,
    MAX_DWELL_CANDIDATES,
    MAX_MOVES,
    Cycle,
    Location,
    MoveSpec,
    read_cycle_file,
)
from adept_traj.cycle.cycle_playback import (
    PLAYBACK_FILE,
    PLAYBACK_PASSES,
    clock_playback,
    cycle_html,
    cycle_playback,
)
from adept_traj.cycle.move_task import (
    MoveTask,
    RelaxedOptima,
    SavedMove,
    cycle_tasks,
    plan_and_encode,
    plan_move,
    relaxed_group,
    relaxed_optima,
)
from adept_traj.cycle.phase_grid import (
    DEFAULT_PHASES,
    MAX_PHASES,
    MAX_REFINED_PHASES,
    RECERTIFIED_PASSES,
    plan_phase_grid,
)
from adept_traj.cycle.recertify import (
    CHECKS_PER_TASK,
    CertifyBatch,
    CheckBatch,
    MoveCertifier,
    MoveCheck,
    MoveVerdict,
    PlannedMove,
    RestCertifier,
    certify_batch,
    check_batch,
    check_moves,
)
from adept_traj.cycle.rest import RestCheck, RestProfile, certify_rest
from adept_traj.cycle.runner import (
    CLOSE_TIMEOUT,
    LOCAL_DASK_CONFIG,
    MOVE_FILE,
    MOVES_FOLDER,
    RETRIES,
    dask_client,
    refuse_earlier_run,
    run_cycle,
    run_planning_tasks,
    run_tasks,
)
from adept_traj.cycle.schedules import (
    MAX_BACK_TO_BACK_MOVES,
    MAX_UNDONE,
    PhaseOption,
    back_to_back,
    chain_passes,
    phase_frontier,
    phase_schedules,
)
from adept_traj.cycle.study import (
    ALGORITHM_PAIR,
    METRICS,
    RUNS_FOLDER,
    Metric,
    parse_seeds,
    run_metrics,
    run_seed_study,
    study_statistics,
)
from adept_traj.cycle.study_report import (
    BOXPLOT_FIGURE,
    STUDY_FILE,
    STUDY_REPORT,
    save_boxplots,
    study_markdown,
    write_study_report,
)
from adept_traj.cycle.summary import (
    CYCLE_FILE,
    CYCLE_REPORT,
    GANTT_FIGURE,
    clock_summary,
    cycle_markdown,
    cycle_summary,
    fastest_certified,
    save_gantt,
    write_cycle_report,
)
from adept_traj.cycle.timeline import ClockedMove, CycleClock

__all__ = [
    "ALGORITHM_PAIR",
    "BOXPLOT_FIGURE",
    "CHECKS_PER_TASK",
    "CHOICES",
    "CLOSE_TIMEOUT",
    "CYCLE_FILE",
    "CYCLE_REPORT",
    "DEFAULT_PHASES",
    "GANTT_FIGURE",
    "LOCAL_DASK_CONFIG",
    "MAX_BACK_TO_BACK_MOVES",
    "MAX_CLOCKED_MOVES",
    "MAX_DWELL_CANDIDATES",
    "MAX_MOVES",
    "MAX_PHASES",
    "MAX_REFINED_PHASES",
    "MAX_UNDONE",
    "METRICS",
    "MOVES_FOLDER",
    "MOVE_FILE",
    "PLAYBACK_FILE",
    "PLAYBACK_PASSES",
    "RECERTIFIED_PASSES",
    "RETRIES",
    "RUNS_FOLDER",
    "STUDY_FILE",
    "STUDY_REPORT",
    "CertifyBatch",
    "ChainPlan",
    "CheckBatch",
    "ClockedMove",
    "Cycle",
    "CycleClock",
    "Location",
    "Metric",
    "MoveCertifier",
    "MoveCheck",
    "MoveSpec",
    "MoveTask",
    "MoveVerdict",
    "PhaseOption",
    "PlannedMove",
    "RelaxedOptima",
    "RestCertifier",
    "RestCheck",
    "RestProfile",
    "SavedMove",
    "ScheduleChoice",
    "back_to_back",
    "certified_schedules",
    "certify_batch",
    "certify_rest",
    "chain_passes",
    "chained_clock",
    "check_batch",
    "check_chained",
    "check_moves",
    "chosen_member",
    "clock_playback",
    "clock_summary",
    "cycle_html",
    "cycle_markdown",
    "cycle_playback",
    "cycle_summary",
    "cycle_tasks",
    "dask_client",
    "dwell_grid",
    "fastest_certified",
    "parse_seeds",
    "phase_frontier",
    "phase_schedules",
    "plan_and_encode",
    "plan_move",
    "plan_on_clock",
    "plan_phase_grid",
    "read_cycle_file",
    "refuse_earlier_run",
    "relaxed_group",
    "relaxed_optima",
    "run_cycle",
    "run_metrics",
    "run_planning_tasks",
    "run_seed_study",
    "run_tasks",
    "save_boxplots",
    "save_gantt",
    "scene_period",
    "schedule_span",
    "study_markdown",
    "study_statistics",
    "write_cycle_report",
    "write_study_report",
]
