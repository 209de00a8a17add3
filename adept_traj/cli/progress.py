"""Progress of a planning run, written to standard error.

- On a terminal: one `tqdm <https://tqdm.github.io>`_ bar per run (generations done,
  evaluations, feasible individuals, best feasible travel time T [s]), redrawn in place.
- Anywhere else (CI logs, pipes, files): no carriage returns; one plain line every
  ``ceil(n_gen / 10)`` generations and one for the last, about ten lines per run::

      nsga2 gen 10/100  evals 1000  feasible 87  best T 1.274 s  12.3 s

- ``--quiet``: nothing.

The reporter is the ``progress`` callback of :func:`adept_traj.optimise.plan`; close it
(or use it as a context manager) when the run ends or is interrupted, so that a bar left
half-drawn ends its line.
"""

from __future__ import annotations

import math
import shutil
import sys
from typing import Any, TextIO

from adept_traj.optimise import GenerationInfo
from adept_traj.validation import as_integer

__all__ = ["PLAIN_LINES", "ProgressReporter"]

#: About this many plain lines are printed per run when the stream is not a terminal.
PLAIN_LINES = 10


def _stats(info: GenerationInfo) -> str:
    best = f"{info.best_time:.3f} s" if info.best_time is not None else "-"
    return f"evals {info.n_evaluations}  feasible {info.n_feasible}  best T {best}"


class ProgressReporter:
    """Reports each finished generation of one run to ``stream``.

    Parameters
    ----------
    label: the run's name, e.g. the algorithm (``"nsga2"``).
    stream: where to write (default: ``sys.stderr`` at the time of the call); a bar when
        ``stream.isatty()`` is true, plain lines otherwise.
    quiet: report nothing.
    lines: about this many plain lines per run (≥ 1).
    """

    def __init__(
        self,
        label: str,
        stream: TextIO | None = None,
        *,
        quiet: bool = False,
        lines: int = PLAIN_LINES,
    ):
        self.label = str(label)
        self.quiet = bool(quiet)
        self.stream = sys.stderr if stream is None else stream
        self.lines = as_integer(lines, "lines", minimum=1)
        isatty = getattr(self.stream, "isatty", None)
        self.interactive = bool(isatty()) if callable(isatty) else False
        self._bar: Any = None

    def __call__(self, info: GenerationInfo) -> None:
        """Report generation ``info.generation`` of ``info.n_gen``."""
        if self.quiet:
            return
        if self.interactive:
            self._draw(info)
        else:
            self._line(info)

    def _draw(self, info: GenerationInfo) -> None:
        if self._bar is None:
            # A terminal that reports no size (0 × 0, e.g. a bare pty) draws no tqdm bar.
            from tqdm import tqdm  # a terminal only: its import (~20 ms) off the quiet runs

            size = shutil.get_terminal_size((100, 24))
            self._bar = tqdm(
                total=info.n_gen,
                initial=info.generation - 1,  # a resumed run starts part-way
                desc=self.label,
                unit="gen",
                file=self.stream,
                ncols=size.columns,
                nrows=size.lines,
                leave=True,
            )
        self._bar.set_postfix_str(_stats(info), refresh=False)
        self._bar.update(info.generation - self._bar.n)
        if info.generation >= info.n_gen:
            self.close()

    def _line(self, info: GenerationInfo) -> None:
        every = math.ceil(info.n_gen / self.lines)
        if info.generation % every and info.generation != info.n_gen:
            return
        self.stream.write(
            f"{self.label} gen {info.generation}/{info.n_gen}  {_stats(info)}"
            f"  {info.elapsed_s:.1f} s\n"
        )
        self.stream.flush()

    def close(self) -> None:
        """End the bar's line (idempotent; nothing to do for plain lines)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> ProgressReporter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
