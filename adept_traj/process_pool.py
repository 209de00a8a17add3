"""Every process that adept_traj runs beside the calling one: :class:`Worker`.

A :class:`Worker` is one process forked from the caller (Linux ``fork``) that runs
``target(channel, *args)`` and talks to the caller over one pipe: the one mechanism of the
package for parallel work. The evaluation workers (:class:`~adept_traj.problem.ParallelEvaluator`),
the finish (:class:`~adept_traj.viz.finisher.Finisher`), the figures
(:func:`~adept_traj.viz.plots.save_all`, :func:`~adept_traj.viz.plots.start_save_all`),
the polish (:class:`~adept_traj.optimise.Polisher`) and the front's certificates
(:class:`~adept_traj.optimise.EarlyCertificates`,
:func:`~adept_traj.optimise.certify_front_members`) and the local solver's screenings and
refinements (:func:`map_forked` in :func:`~adept_traj.optimise.screen_starts`,
:func:`~adept_traj.optimise.refine_starts`) are workers; only Dask (cycles, seed
studies) and meshcat's viewer run processes of their own.

Every worker, the same way:

- **Inherits**: ``target`` and ``args`` (a problem, a closure) are the caller's objects
  at the fork; only what goes over the pipe afterwards is pickled.
- **Ends with its parent**: the child asks Linux for SIGKILL when its parent dies
  (``PR_SET_PDEATHSIG``), however the parent ends (even by SIGKILL), and ends at once if
  the parent is gone already; a worker's own workers end with it in turn. (Linux sends the
  signal when the *thread* that forked the worker ends: fork workers from a thread that
  outlives them, e.g. the main thread.) Ctrl-C is the caller's: a worker ignores SIGINT,
  held from before the fork until then (else a SIGINT at the fork's instant would raise in
  the new process, which would run on as a copy of the caller); a Ctrl-C held meanwhile
  is the caller's, raised just after the fork, the new worker stopped.
- **Holds no other worker's pipe**: every process forked after a worker (another worker,
  or any fork) closes, at once, its copies of the caller's ends of every worker's pipe
  (:func:`os.register_at_fork`), so workers may be started in any order and a worker's
  pipe ends when its caller closes it.
- **Carries its error back**: an exception escaping ``target`` (or ``prepare``) is sent
  to the caller (traceback and pickled exception) and raised by the caller's
  :meth:`Worker.recv`: the same exception with the worker's traceback as a note
  (:func:`~adept_traj.errors.error_from_process`), or an
  :class:`~adept_traj.errors.WorkerError` holding the traceback if it does not
  unpickle. A worker that ends without a word (killed) raises
  :class:`~adept_traj.errors.WorkerDiedError` there.
- **Is stopped the same way**: :meth:`Worker.close` (SIGKILL, then reaped), on leaving
  its ``with`` block, when the :class:`Worker` is garbage-collected and at the
  interpreter's exit; only the process that forked it stops it (a forked copy of the
  caller leaves its parent's workers alone). The worker itself ends with ``os._exit``:
  none of the caller's exit handlers runs in it.
- **May prepare at the lowest priority**: with ``prepare`` (e.g. heavy imports), the
  worker first runs it in a thread at nice :data:`LOWEST_PRIORITY` (Linux niceness is
  per thread: it runs while a core idles and never takes one from the caller), then says
  it is ready (:meth:`Worker.ready`) and runs ``target`` at the caller's priority
  (:meth:`Worker.hurry` raises a preparation the caller waits for, and its processes).
"""

from __future__ import annotations

import contextlib
import os
import pickle
import signal
import sys
import threading
import traceback
import weakref
from collections.abc import Callable, Sequence
from multiprocessing.connection import Connection, Pipe
from typing import Any

from adept_traj.errors import ConfigurationError, WorkerDiedError, WorkerError, error_from_process
from adept_traj.process_tree import raise_priority

__all__ = [
    "LOWEST_PRIORITY", "Channel", "Worker", "can_fork", "children", "map_forked",
    "prepare_quietly", "serve",
]  # fmt: skip

#: Niceness of a worker's preparing thread (the lowest priority).
LOWEST_PRIORITY = 19

# Messages of a worker to its caller: (kind, payload...).
_READY, _VALUE, _ERROR = 0, 1, 2
_PROTOCOL = pickle.HIGHEST_PROTOCOL

#: The ends of pipes this process holds for its workers, and a worker's own end to its
#: caller: closed in every process forked from this one (:func:`_forget_inherited`).
_HELD: set[Connection] = set()
#: The workers this process forked and has not reaped: pid → Worker (weakly).
_LIVE: weakref.WeakValueDictionary[int, Worker] = weakref.WeakValueDictionary()
#: Workers killed by a finalizer but not reaped yet (they had not ended at once).
_UNREAPED: set[int] = set()


def _reap_pending() -> None:
    """Reap the killed workers that have ended since (no waiting)."""
    for pid in list(_UNREAPED):
        with contextlib.suppress(ChildProcessError):
            if os.waitpid(pid, os.WNOHANG)[0] == 0:
                continue
        _UNREAPED.discard(pid)


def _forget_inherited() -> None:
    """In a process just forked: close the copies of the pipe ends held for workers."""
    for connection in list(_HELD):
        with contextlib.suppress(OSError):  # already closed
            connection.close()
    for held in (_HELD, _LIVE, _UNREAPED):
        held.clear()


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forget_inherited)


def can_fork() -> bool:
    """Whether this platform forks (Linux, macOS); else no worker starts: callers work."""
    return hasattr(os, "fork")


def children() -> list[int]:
    """The process ids of the workers this process forked and has not stopped yet."""
    _reap_pending()
    return sorted(_LIVE)


class Channel:
    """A worker's end of its pipe, handed to ``target``: :meth:`send` values to the
    caller (pickled), :meth:`recv` what the caller sends, :meth:`poll` for it."""

    def __init__(self, connection: Connection) -> None:
        self._connection = connection

    def send(self, value: Any) -> None:
        """Send ``value`` to the caller (:meth:`Worker.recv`); end quietly if it is gone."""
        payload = pickle.dumps((_VALUE, value), protocol=_PROTOCOL)
        try:
            self._connection.send_bytes(payload)
        except OSError:  # EPIPE: the caller closed its end: nothing more to do
            os._exit(0)

    def recv(self) -> Any:
        """The next value the caller sent (:meth:`Worker.send`), waiting for it; the
        worker ends quietly once the caller has closed the pipe."""
        try:
            return pickle.loads(self._connection.recv_bytes())
        except (EOFError, OSError):  # the caller closed its end: nothing more to do
            os._exit(0)

    def poll(self, timeout: float = 0.0) -> bool:
        """Whether a value from the caller (or the pipe's end) waits, within ``timeout`` [s]."""
        return self._connection.poll(timeout)


def serve(channel: Channel, function: Callable[..., Any]) -> None:
    """A worker's ``target`` that serves calls: for each argument tuple the caller sends,
    send back ``function(*args)``, until the caller closes the pipe."""
    while True:
        channel.send(function(*channel.recv()))


def map_forked(
    function: Callable[[Any], Any],
    items: Sequence[Any],
    processes: int,
    note: str = "raised in map_forked",
) -> list:
    """``[function(item) for item in items]`` on up to ``processes`` processes at once: the
    first item of every group of ``processes`` in this one, the others each in a
    :class:`Worker` forked for it (it inherits ``function``; its value comes back pickled,
    its error is raised here with ``note``). In order, the loop's values for a
    deterministic ``function``; one process (or no ``fork``): the loop itself."""
    out: list = []
    step = max(1, int(processes)) if can_fork() else 1
    for i in range(0, len(items), step):
        forked: list[Worker] = []
        try:
            for item in items[i + 1 : i + step]:
                forked.append(Worker(_call, function, item, note=note))
            out.append(function(items[i]))
            out.extend(worker.recv() for worker in forked)
        finally:  # Ctrl-C or an error included: the workers are stopped at once
            for worker in forked:
                worker.close()
    return out


def _call(channel: Channel, function: Callable[[Any], Any], item: Any) -> None:
    """A worker of :func:`map_forked`: send ``function(item)``."""
    channel.send(function(item))


class Worker:
    """One process forked from the caller running ``target(channel, *args)`` (see the
    module); a context manager that stops it when the block is left.

    Parameters
    ----------
    target : callable
        The worker's function, called in the worker as ``target(channel, *args)`` with its
        :class:`Channel`; the worker ends when it returns (or raises: the error is sent
        to the caller).
    *args
        Its other arguments, inherited by the fork (nothing is pickled).
    prepare : callable, optional
        Run first, in a thread of the worker at nice ``prepare_niceness`` (``None``: the
        caller's); the worker is :meth:`ready` once it has returned; its error is sent.
    note : str
        The note put before the worker's traceback on its error (what the worker does).

    Attributes
    ----------
    pid : int or None
        The worker's process id (``None`` once it is reaped).

    Raises
    ------
    ConfigurationError
        The platform cannot fork (:func:`can_fork`).
    OSError
        The fork failed (e.g. no memory).
    """

    def __init__(
        self,
        target: Callable[..., None],
        *args: Any,
        prepare: Callable[[], None] | None = None,
        prepare_niceness: int | None = LOWEST_PRIORITY,
        note: str = "raised in a worker process",
    ) -> None:
        if not can_fork():
            raise ConfigurationError("worker processes need the 'fork' start method (Linux)")
        _reap_pending()
        self.pid: int | None = None
        self.note = note
        self._ready = prepare is None
        self._creator = os.getpid()
        mine, theirs = Pipe(duplex=True)
        _HELD.add(mine)
        for stream in (sys.stdout, sys.stderr):  # not written twice by the fork
            with contextlib.suppress(AttributeError, ValueError, OSError):  # closed streams
                stream.flush()
        held = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            pid = os.fork()
        except BaseException:
            signal.pthread_sigmask(signal.SIG_SETMASK, held)
            _HELD.discard(mine)
            mine.close()
            theirs.close()
            raise
        if pid == 0:  # the worker (never returns)
            _run(theirs, self._creator, target, args, prepare, prepare_niceness, held)
        theirs.close()
        self.pid, self._connection = pid, mine
        _LIVE[pid] = self
        self._finalizer = weakref.finalize(self, _stop, pid, mine, self._creator, False)
        try:
            signal.pthread_sigmask(signal.SIG_SETMASK, held)  # a Ctrl-C held is raised here
        except BaseException:  # the worker must not outlive its Worker
            self.close()
            raise

    # ------------------------------------------------------------------ talking
    def send(self, *args: Any) -> None:
        """Send ``args`` to the worker (its :meth:`Channel.recv` returns the tuple).

        Raises
        ------
        WorkerDiedError
            The worker is gone (its end of the pipe closed; what it sent before can still
            be read with :meth:`recv`).
        """
        if self.pid is None:
            raise WorkerDiedError("the worker process is stopped")
        try:
            self._connection.send_bytes(pickle.dumps(args, protocol=_PROTOCOL))
        except OSError as exc:  # EPIPE: the worker's end is gone
            raise WorkerDiedError(f"a worker process (pid {self.pid}) ended abruptly") from exc

    def poll(self, timeout: float = 0.0) -> bool:
        """Whether a message of the worker (or the end of its pipe: it ended) waits,
        within ``timeout`` [s]; ``False`` once it is stopped."""
        return self.pid is not None and self._connection.poll(timeout)

    def recv(self) -> Any:
        """The next value the worker sent (:meth:`Channel.send`), waiting for it.

        Raises
        ------
        Exception
            The worker's error (see the module), once it is reaped.
        WorkerDiedError
            The worker ended without a word (e.g. killed), once it is reaped.
        """
        while True:
            message = self._message()
            if message[0] == _VALUE:
                return message[1]
            if message[0] == _ERROR:
                self.close()
                _, text, pickled = message
                raise error_from_process(
                    text,
                    pickled,
                    self.note,
                    WorkerError(f"{self.note}, with an error that does not unpickle:\n{text}"),
                )
            self._ready = True

    def ready(self, timeout: float = 0.0) -> bool:
        """Whether the worker has finished ``prepare`` (waiting up to ``timeout`` [s]);
        ``False`` for a worker stopped, or whose preparation failed or that died (it is
        then reaped: the caller does the work itself)."""
        if not self._ready and self.pid is not None and self.poll(timeout):
            with contextlib.suppress(WorkerDiedError):
                self._ready = self._message()[0] == _READY
            if not self._ready:  # its preparation failed, or it died
                self.close()
        return self._ready and self.pid is not None

    def hurry(self) -> bool:
        """Raise a worker still preparing, and the processes it forked, to the calling
        thread's niceness (:func:`~adept_traj.process_tree.raise_priority`: a caller about
        to wait for it); whether it was done (not for a stopped worker)."""
        if self.pid is None or os.getpid() != self._creator:
            return False
        return raise_priority(self.pid, os.getpriority(os.PRIO_PROCESS, threading.get_native_id()))

    def _message(self) -> tuple:
        """The worker's next message; a :class:`WorkerDiedError` at the pipe's end.
        Anything escaping here (Ctrl-C while waiting) stops the worker first."""
        if self.pid is None:
            raise WorkerDiedError("the worker process is stopped")
        try:
            return pickle.loads(self._connection.recv_bytes())
        except (EOFError, OSError) as exc:  # ended without a word
            raise self._died() from exc
        except BaseException:  # e.g. Ctrl-C while waiting
            self.close()
            raise

    def _died(self) -> WorkerDiedError:
        """The error for a worker that ended without a word, once it is reaped."""
        pid, code = self.pid, self.close()
        return WorkerDiedError(f"a worker process (pid {pid}) ended abruptly (exit code {code})")

    # ------------------------------------------------------------------ stopping
    def kill(self) -> None:
        """Stop the worker without waiting for its end (:meth:`close` reaps it; one still
        preparing at nice 19 on a busy machine may wait long for a core to end)."""
        if self.pid is not None and os.getpid() == self._creator:
            with contextlib.suppress(ProcessLookupError):  # ended already
                os.kill(self.pid, signal.SIGKILL)
            self._ready = False

    def close(self) -> int | None:
        """Stop the worker (SIGKILL) if it still runs, reap it and close the pipe; return
        its exit status (negative: the signal that ended it; ``None`` once closed)."""
        if self.pid is None:
            return None
        pid, self.pid = self.pid, None
        self._ready = False
        self._finalizer.detach()
        _LIVE.pop(pid, None)
        return _stop(pid, self._connection, self._creator, True)

    def __enter__(self) -> Worker:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def _stop(pid: int, connection: Connection, creator: int, wait: bool) -> int | None:
    """Kill worker ``pid`` (in the process that forked it only), reap it (waiting for its
    end if ``wait``) and close the caller's end of its pipe; its exit status."""
    _HELD.discard(connection)
    connection.close()
    if os.getpid() != creator:  # a forked copy of the caller: not its worker
        return None
    try:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done == 0:
            os.kill(pid, signal.SIGKILL)
            done, status = os.waitpid(pid, 0 if wait else os.WNOHANG)
        if not done:  # killed, not ended yet: reaped later (_reap_pending)
            _UNREAPED.add(pid)
        code = os.waitstatus_to_exitcode(status) if done else None
    except (ChildProcessError, ProcessLookupError):  # pragma: no cover - reaped elsewhere
        return None
    return code


# ====================================================================== the worker's side
def _end_with_parent(parent: int) -> None:
    """SIGKILL when the parent dies (Linux ``PR_SET_PDEATHSIG``); end now if it is gone."""
    if sys.platform.startswith("linux"):
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:
        os._exit(0)


def _run(
    connection: Connection,
    parent: int,
    target: Callable[..., None],
    args: tuple,
    prepare: Callable[[], None] | None,
    niceness: int | None,
    mask: set[signal.Signals],
) -> None:
    """In the forked worker: end with the parent, ignore Ctrl-C (then take the caller's
    signal ``mask``), prepare at ``niceness``, say ready, run ``target``; send its error."""
    code = 0
    try:
        _end_with_parent(parent)
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C: the caller stops its workers
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)  # a SIGINT held is now dropped
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        _HELD.add(connection)  # the worker's own workers do not keep it
        if prepare is not None:
            failed = prepare_quietly(prepare, niceness)
            message = (_ERROR, failed, None) if failed else (_READY,)
            connection.send_bytes(pickle.dumps(message, protocol=_PROTOCOL))
            if failed:
                os._exit(1)  # its error is sent
        target(Channel(connection), *args)
    except BaseException as exc:  # every error is sent to the caller, which raises it
        code = 1
        with contextlib.suppress(BaseException):  # the caller is gone
            connection.send_bytes(pickle.dumps((_ERROR, *_report(exc)), protocol=_PROTOCOL))
    finally:
        os._exit(code)


def _report(exc: BaseException) -> tuple[str, bytes | None]:
    """While ``exc`` is handled: its traceback and ``exc`` pickled (``None``: it does not)."""
    text = traceback.format_exc()
    try:
        return text, pickle.dumps(exc)
    except Exception:  # an exception that does not pickle: its traceback text only
        return text, None


def prepare_quietly(work: Callable[[], None], niceness: int | None = LOWEST_PRIORITY) -> str:
    """Run ``work`` (e.g. heavy imports) in a thread at nice ``niceness`` (``None``: this
    thread's) and wait for it; return its traceback, ``""`` when it succeeded."""
    failed: list[str] = []

    def quietly() -> None:
        try:
            if niceness is not None:
                os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), niceness)
            work()
        except BaseException:  # reported to the caller
            failed.append(traceback.format_exc())

    thread = threading.Thread(target=quietly, daemon=True)
    thread.start()
    thread.join()
    return failed[0] if failed else ""
