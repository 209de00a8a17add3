"""Planning the moves of a cycle as Dask tasks.

:func:`run_cycle` submits one task per move to a Dask cluster — by default a
``distributed.LocalCluster`` with one single-threaded worker process per core, started and
stopped here; ``scheduler="tcp://host:8786"`` uses an existing cluster (``dask scheduler``
and ``dask worker`` on several machines; the robot's files must exist at the same paths on
every worker). Each task builds the problem and calls :func:`~adept_traj.optimise.plan`
with the move's own seed, so a move's result does not depend on the worker, the number of
workers or the order. The client saves each result as soon as it arrives
(``DIR/moves/NAME/``: :meth:`~adept_traj.results.PlanningResult.save`, written into a
temporary folder that is then renamed, plus ``move.json`` describing the task); with
``resume=True`` a move whose folder holds the same task is loaded, not planned again.
A task whose worker dies is rescheduled by the scheduler; a task that raises is retried
(``retries``) before the run fails. Dask is imported only here, when a cycle runs.
"""

from __future__ import annotations

import json
import os
import shutil
import uuid
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from adept_traj.cycle.cycle_file import Cycle
from adept_traj.cycle.move_task import (
    MoveTask,
    SavedMove,
    cycle_tasks,
    plan_and_encode,
    relaxed_group,
    relaxed_optima,
)
from adept_traj.errors import CycleError, ResultFormatError
from adept_traj.files import write_text_atomic
from adept_traj.problem import heap_environment
from adept_traj.results import PlanningResult
from adept_traj.validation import as_integer

__all__ = [
    "CLOSE_TIMEOUT",
    "LOCAL_DASK_CONFIG",
    "MOVES_FOLDER",
    "MOVE_FILE",
    "RETRIES",
    "dask_client",
    "refuse_earlier_run",
    "run_cycle",
    "run_planning_tasks",
    "run_tasks",
]

#: Sub-folder of the output folder holding one result folder per move.
MOVES_FOLDER = "moves"
#: The task a move folder was planned for (what ``resume`` compares).
MOVE_FILE = "move.json"
#: Times a task that raised is submitted again.
RETRIES = 2
#: Seconds [s] a local worker process is given to exit by itself when the cluster stops
#: (Dask's nanny kills it after 0.8 × this; Dask's own default, 5, kills busy machines'
#: workers and warns "Worker process still alive after 4.0 seconds, killing").
CLOSE_TIMEOUT = 60.0
#: Dask settings of the local cluster (its scheduler and the workers' nannies run in this
#: process; the workers inherit them): no worker profiler, no GIL monitor, and the system
#: monitor, the watchdog and the memory monitor (of each nanny and worker: ten times a
#: second by default; the limit is still enforced, within a second) less often than Dask's
#: defaults: CPU time for as long as the run lasts, serial in the command, for the
#: dashboard only. The workers are the command's own processes: they keep their heap
#: between evaluation blocks as the command does (:func:`~adept_traj.problem.keep_heap`,
#: set through the environment the nannies give them, in place of Dask's
#: ``MALLOC_TRIM_THRESHOLD_`` of 64 KiB, which made the pick6 cycle's workers spend
#: about a fifth of their CPU time in the kernel, page-faulting freed memory back in).
LOCAL_DASK_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.system-monitor.gil.enabled": False,
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.admin.tick.interval": "500ms",
    "distributed.worker.memory.monitor-interval": "1s",
    **{f"distributed.nanny.pre-spawn-environ.{k}": v for k, v in heap_environment().items()},
}


def _finished(folder: Path, task: MoveTask) -> PlanningResult | None:
    """The saved result of ``task`` in ``folder`` when it is complete and planned for the
    same task; ``None`` otherwise (then it is planned again)."""
    try:
        saved = json.loads((folder / MOVE_FILE).read_text(encoding="utf-8"))
        if saved != task.description():
            return None
        return PlanningResult.load(folder)
    except (OSError, ValueError, ResultFormatError):
        return None


def _save(folder: Path, task: MoveTask, saved: SavedMove) -> Path:
    """Write the files of ``saved`` into ``folder/NAME`` at once and atomically (a
    temporary folder renamed), with ``move.json``."""
    final = folder / task.move.name
    tmp = final.with_name(f".{task.move.name}.partial")
    shutil.rmtree(tmp, ignore_errors=True)
    tmp.mkdir(parents=True)
    for name, content in saved.files.items():
        (tmp / name).write_bytes(content)
    write_text_atomic(tmp / MOVE_FILE, json.dumps(task.description(), indent=1))
    shutil.rmtree(final, ignore_errors=True)
    os.replace(tmp, final)
    return final


def run_tasks(
    tasks: Sequence[Any],
    function: Callable[..., Any],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    on_result: Callable[[int, Any], None] | None = None,
    client: Any = None,
    extra: Sequence[tuple[Any, ...]] | None = None,
) -> list[Any]:
    """``[function(t) for t in tasks]``, each call a Dask task (``retries`` =
    :data:`RETRIES`), on a new local cluster of ``workers`` single-threaded worker
    processes (default: one per core) or on the scheduler at address ``scheduler``, or on
    the caller's ``distributed.Client`` ``client`` (:func:`dask_client`; left open).
    ``extra[i]``: more positional arguments of task i's call (a Dask future among them is
    a dependency: the task runs once it has finished, with its result). ``on_result(i,
    value)`` is called in this process as each task finishes."""
    if client is not None:
        return _run_on(client, tasks, function, on_result, extra)
    with dask_client(workers, scheduler, len(tasks)) as own:
        return _run_on(own, tasks, function, on_result, extra)


@contextmanager
def dask_client(workers: int | None, scheduler: str | None, n_tasks: int) -> Iterator[Any]:
    """A ``distributed.Client``: of a new local cluster of ``min(workers, n_tasks)``
    single-threaded worker processes (default: one per core), or of the scheduler at
    address ``scheduler``; closed (and the cluster stopped, each worker process given
    :data:`CLOSE_TIMEOUT` to exit) on leaving. A local cluster runs with
    :data:`LOCAL_DASK_CONFIG`."""
    import dask
    from distributed import Client, LocalCluster

    with dask.config.set(LOCAL_DASK_CONFIG if scheduler is None else {}):
        if scheduler is None:
            n = as_integer(workers or os.cpu_count() or 1, "workers", minimum=1, maximum=1024)
            cluster = LocalCluster(
                n_workers=min(n, max(n_tasks, 1)),
                threads_per_worker=1,
                processes=True,
                dashboard_address=":0",  # any free port: 8787 may be taken
            )
            client = Client(cluster)
        else:
            cluster, client = None, Client(scheduler)
        try:
            yield client
        finally:
            client.close()
            if cluster is not None:
                _stop_workers(cluster, CLOSE_TIMEOUT)
                cluster.close()


def _stop_workers(cluster: Any, timeout: float) -> None:
    """Close every worker of the local ``cluster`` (its nanny and worker process),
    waiting up to 0.8 × ``timeout`` [s] for each process to exit by itself before it is
    killed; ``cluster.close()`` then finds them closed. (``LocalCluster.close`` closes each
    nanny with Dask's default of 5 s: a worker process that needs longer to exit — its
    interpreter's teardown on a loaded machine — is killed, with a warning.)"""
    import asyncio

    nannies = list(cluster.workers.values())

    async def close_all() -> None:
        await asyncio.gather(*(n.close(timeout=timeout) for n in nannies))

    cluster.sync(close_all)


def _run_on(
    client: Any,
    tasks: Sequence[Any],
    function: Callable[..., Any],
    on_result: Callable[[int, Any], None] | None,
    extra: Sequence[tuple[Any, ...]] | None = None,
) -> list[Any]:
    """:func:`run_tasks` on ``client``."""
    from distributed import as_completed

    run_id = uuid.uuid4().hex  # keys unique on a shared scheduler
    more = extra if extra is not None else [()] * len(tasks)
    futures = [
        client.submit(function, t, *a, key=f"adept-traj-{run_id}-{i}", pure=False, retries=RETRIES)
        for i, (t, a) in enumerate(zip(tasks, more, strict=True))
    ]
    index = {f.key: i for i, f in enumerate(futures)}
    out: list[Any] = [None] * len(tasks)
    for future in as_completed(futures):
        i = index[future.key]
        out[i] = future.result()
        future.release()
        if on_result is not None:
            on_result(i, out[i])
    return out


def refuse_earlier_run(folder: Path, resume: bool) -> None:
    """Refuse to plan a cycle into a folder that holds an earlier run, unless resuming.

    Parameters
    ----------
    folder: the moves' folder of the run (``out/moves``).
    resume: the run keeps the moves already saved there (nothing is refused).

    Raises
    ------
    CycleError
        ``folder`` exists and is not empty, and ``resume`` is false.
    """
    if not resume and folder.exists() and any(folder.iterdir()):
        raise CycleError(f"{folder} holds an earlier run: give --resume or another folder")


def run_planning_tasks(
    tasks: Sequence[MoveTask],
    folder: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
    client: Any = None,
    relaxed: dict[str, Any] | None = None,
) -> list[PlanningResult]:
    """Plan ``tasks`` on Dask (:func:`run_tasks`; on ``client`` when given), each result
    saved as it arrives into ``folder/NAME/`` (NAME: the task's move name); return the
    results in order.

    ``resume``: a task whose folder holds the same task (``move.json``) is loaded, not
    planned; without it a ``folder`` that already holds results is refused
    (:class:`~adept_traj.errors.CycleError`). ``progress`` is called with each name as its
    result is saved (or found saved). Where obstacles move, each
    :func:`~adept_traj.cycle.move_task.relaxed_group` of the tasks to plan has its relaxed
    optima made once, by a task of its own run before its planning tasks
    (:func:`~adept_traj.cycle.move_task.relaxed_optima`); ``relaxed``: those already made
    (by group), kept and added to over the calls."""
    where = Path(folder)
    refuse_earlier_run(where, resume)
    results: list[PlanningResult | None] = [None] * len(tasks)
    pending = []
    for i, task in enumerate(tasks):
        done = _finished(where / task.move.name, task) if resume else None
        if done is None:
            pending.append(i)
        else:
            results[i] = done
            if progress is not None:
                progress(task.move.name)

    def saved(j: int, move: SavedMove) -> None:
        i = pending[j]
        _save(where, tasks[i], move)
        results[i] = move.result
        if progress is not None:
            progress(tasks[i].move.name)

    if pending:
        where.mkdir(parents=True, exist_ok=True)
        todo = [tasks[i] for i in pending]
        with _given_or_own(client, workers, scheduler, len(todo)) as own:
            shared = {} if relaxed is None else relaxed
            extra = _relaxed_arguments(own, todo, shared)
            run_tasks(todo, plan_and_encode, on_result=saved, client=own, extra=extra)
    return results  # type: ignore[return-value]


@contextmanager
def _given_or_own(client: Any, workers: int | None, scheduler: str | None, n: int) -> Any:
    """``client``, or a new one of :func:`dask_client` for ``n`` tasks (closed on leaving)."""
    if client is not None:
        yield client
        return
    with dask_client(workers, scheduler, n) as own:
        yield own


def _relaxed_arguments(
    client: Any, tasks: Sequence[MoveTask], shared: dict[str, Any]
) -> list[tuple[Any, ...]]:
    """Per task, the extra argument of :func:`~adept_traj.cycle.move_task.plan_and_encode`:
    its group's relaxed optima (made here as Dask tasks, one per group that ``shared`` does
    not hold yet, all at once), or none without moving obstacles. The planning tasks get
    values, not futures: without dependencies Dask queues them and hands them out in order
    as workers free up."""
    groups = [relaxed_group(task) for task in tasks]
    todo = {g: t for g, t in zip(groups, tasks) if g is not None and g not in shared}
    if todo:
        made = run_tasks(list(todo.values()), relaxed_optima, client=client)
        shared.update(zip(todo, made))
    return [() if g is None else (shared[g],) for g in groups]


def run_cycle(
    cycle: Cycle,
    out: str | os.PathLike[str],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    progress: Callable[[str], None] | None = None,
) -> list[PlanningResult]:
    """Plan every move of ``cycle`` on Dask; save each result as it finishes
    (``out/moves/NAME/``, :func:`run_planning_tasks`); return the results in the order of
    the moves.

    Every move is planned from scene time 0, all at once: right for a fixed-obstacle
    scene. With moving obstacles a move is certified only for its own start time: plan
    such a cycle with :func:`~adept_traj.cycle.plan_on_clock` (``adept-traj cycle`` does).

    Parameters
    ----------
    cycle: from :func:`~adept_traj.cycle.read_cycle_file`.
    out: output folder.
    workers: local worker processes (default: one per core; ignored with ``scheduler``).
    scheduler: address of an existing Dask scheduler (``tcp://127.0.0.1:8786``).
    resume: keep the moves already saved for the same task (else ``out`` must not hold
        an earlier cycle run).
    progress: called with a move's name as it finishes (or is found finished).

    Raises
    ------
    CycleError
        ``out`` holds an earlier run and ``resume`` is false.
    """
    return run_planning_tasks(
        cycle_tasks(cycle),
        Path(out) / MOVES_FOLDER,
        workers=workers,
        scheduler=scheduler,
        resume=resume,
        progress=progress,
    )
