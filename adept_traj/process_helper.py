"""The caller's handle on one helper process: :class:`Helper`.

The finish (:class:`~adept_traj.viz.finisher.Finisher`), the figures
(:class:`~adept_traj.viz.plots.all_figures.BackgroundFigures`), the polish
(:class:`~adept_traj.optimise.Polisher`) and the early certificates
(:class:`~adept_traj.optimise.EarlyCertificates`) each hold at most one
:class:`~adept_traj.process_pool.Worker` and are stopped the same way; this is their
common part.
"""

from __future__ import annotations

from typing import Any

from adept_traj.process_pool import Worker

__all__ = ["Helper"]


class Helper:
    """The base of an object that holds at most one
    :class:`~adept_traj.process_pool.Worker` beside the caller (the finish, the figures,
    the polish, the early certificates): a context manager that stops the worker when the
    block is left. A subclass starts its worker in its ``__init__``
    (``self._worker``; ``None``: none, the caller does the work itself).

    Attributes
    ----------
    pid : int or None
        The worker's process id (``None`` without one, or once it is reaped).
    """

    _worker: Worker | None = None

    @property
    def pid(self) -> int | None:
        return None if self._worker is None else self._worker.pid

    def ready(self, timeout: float = 0.0) -> bool:
        """Whether the worker is prepared (waiting up to ``timeout`` [s]); ``False``
        without one, once it is stopped or used, or if it failed
        (:meth:`~adept_traj.process_pool.Worker.ready`)."""
        return self._worker is not None and self._worker.ready(timeout)

    def cancel(self) -> None:
        """Stop the worker (a no-op without one, or once it is reaped): killed, then
        reaped."""
        if self._worker is not None:
            self._worker.close()

    def __enter__(self) -> Any:  # the subclass's instance
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.cancel()
