"""Helper processes forked from the caller: :class:`ForkedHelper` (the caller's side),
:func:`prepare_quietly` (a helper's preparation at the lowest priority), and what every
forked process of the package does the same way: :func:`end_with_parent` (SIGTERM when
the caller dies), :func:`stop_on_sigterm` (its SIGTERM handler) and :func:`error_report`
(an error sent to the caller).

The helpers of ``adept-traj plan`` (the finish's :class:`~adept_traj.viz.Finisher`, the
polish's :class:`~adept_traj.optimise.Polisher`, the front's
:class:`~adept_traj.optimise.EarlyCertificates`) are forked processes that talk to the
caller over one pipe. The caller's side is the same for all: fork with ``target(conn,
callers_end, parent, *args)`` (``conn`` the helper's end of the pipe, ``callers_end`` the
caller's end inherited by the fork, to be closed first, ``parent`` the caller's process
id), wait for the helper's ``"ready"``, stop it (terminated, then reaped) when the
``with`` block is left or at the interpreter's exit.
"""

from __future__ import annotations

import atexit
import multiprocessing
import os
import pickle
import signal
import sys
import threading
import traceback
from collections.abc import Callable
from typing import Any

__all__ = [
    "LOWEST_PRIORITY",
    "READY",
    "ForkedHelper",
    "end_with_parent",
    "error_report",
    "prepare_quietly",
    "stop_on_sigterm",
]

#: Niceness of a helper's preparing thread (the lowest priority).
LOWEST_PRIORITY = 19
#: The helper's first message once it is prepared.
READY = "ready"


class ForkedHelper:
    """A helper process forked from the caller with a pipe to it; a context manager that
    stops it when the block is left.

    Parameters
    ----------
    target: the helper's function, called as ``target(conn, callers_end, parent, *args)``
        (``None``: no helper is forked).
    args: its other arguments (inherited by the fork, nothing is pickled).

    Attributes
    ----------
    pid: the helper's process id (``None`` without ``fork``, or once it is reaped).
    """

    def __init__(self, target: Callable[..., None] | None, args: tuple = ()) -> None:
        self._process: Any = None
        self._conn: Any = None
        self._ready = False
        self._given_up = False
        self.pid: int | None = None
        if target is None or "fork" not in multiprocessing.get_all_start_methods():
            return
        context = multiprocessing.get_context("fork")
        self._conn, child = context.Pipe(duplex=True)
        process = context.Process(target=target, args=(child, self._conn, os.getpid(), *args))
        process.start()  # (flushes sys.stdout and sys.stderr before the fork)
        child.close()
        self._process, self.pid = process, process.pid
        # A caller that never cancels: stopped at the interpreter's exit, before
        # multiprocessing's own exit hook (registered earlier, run later) joins it.
        atexit.register(self.cancel)

    def ready(self, timeout: float = 0.0) -> bool:
        """Whether the helper has said :data:`READY` (waiting up to ``timeout`` [s]);
        ``False`` for a helper that died or was stopped, or that has done its work and
        was reaped (a helper serves once)."""
        if self._given_up or self._process is None:
            return False
        if not self._ready and self._process is not None:
            try:
                if self._conn.poll(timeout):
                    self._ready = self._conn.recv() == READY
            except (EOFError, OSError):  # died while preparing
                self._ready = False
        return self._ready

    def _answer(self) -> Any:
        """Wait for the helper's answer and reap it; ``None`` if it ended without a word
        (killed). Ctrl-C (or any error) while waiting stops the helper and is raised."""
        try:
            message = self._conn.recv()
        except EOFError:  # the helper ended without a word (killed)
            message = None
        except BaseException:  # e.g. Ctrl-C while waiting
            self.cancel()
            raise
        self._reap()
        return message

    def _give_up(self) -> None:
        """Stop a helper that will not be used without waiting for its end: killed now,
        reaped by :meth:`cancel` (e.g. at the end of the ``with`` block). On a busy machine
        the end of a helper still preparing at nice 19 waits for that thread to get a core
        (long, under load): the caller does not wait for it."""
        self._given_up = True
        if self._process is not None:
            self._process.kill()

    def cancel(self) -> None:
        """Stop the helper (a no-op once it is reaped): terminated, then waited for."""
        if self._process is None:
            return
        self._process.terminate()
        self._process.join(10.0)
        if self._process.is_alive():  # pragma: no cover - stuck in uninterruptible C code
            self._process.kill()
        self._reap()

    def _reap(self) -> None:
        """Wait for the ended helper and close the pipe (a no-op once reaped)."""
        if self._process is None:
            return
        self._process.join()
        self._conn.close()
        self._process, self._conn, self.pid = None, None, None
        atexit.unregister(self.cancel)

    def __enter__(self) -> ForkedHelper:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.cancel()


def prepare_quietly(work: Callable[[], None]) -> str:
    """Run ``work`` (e.g. heavy imports) in a thread of this process at niceness
    :data:`LOWEST_PRIORITY` (Linux niceness is per thread: it runs while a core idles) and
    wait for it; return its traceback, ``""`` when it succeeded."""
    failed: list[str] = []

    def quietly() -> None:
        try:
            os.setpriority(os.PRIO_PROCESS, threading.get_native_id(), LOWEST_PRIORITY)
            work()
        except BaseException:  # reported to the caller by not being ready
            failed.append(traceback.format_exc())

    thread = threading.Thread(target=quietly, daemon=True)
    thread.start()
    thread.join()
    return failed[0] if failed else ""


def error_report(exc: BaseException) -> tuple[str, bytes | None]:
    """In a forked process, while ``exc`` is handled: its traceback and ``exc`` pickled
    (``None`` if it does not pickle, e.g. an attribute that does not: then it is sent as
    text only), for the caller to raise (:func:`~adept_traj.errors.error_from_process`)."""
    text = traceback.format_exc()
    try:
        return text, pickle.dumps(exc)
    except Exception:  # an exception that does not pickle: its traceback text only
        return text, None


def end_with_parent() -> None:
    """Ask Linux for SIGTERM when this forked process' parent dies
    (``PR_SET_PDEATHSIG``): a parent stopped outright cannot terminate it. Elsewhere
    nothing (the process then ends when its pipe to the parent closes)."""
    if sys.platform.startswith("linux"):
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM, 0, 0, 0)


def stop_on_sigterm(*_: object) -> None:
    """SIGTERM handler of a forked process (``cancel``, its caller's death): stop the
    processes it forked and end at once. No exception is raised: a ``SystemExit`` raised
    where the signal lands (e.g. in a fork handler of :mod:`logging`) would be printed as
    "Exception ignored" and the process would go on."""
    for child in multiprocessing.active_children():
        child.terminate()
    os._exit(128 + signal.SIGTERM)
