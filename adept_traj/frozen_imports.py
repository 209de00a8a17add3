"""The cyclic garbage collector around a process's heavy imports: :func:`frozen_imports`.

Importing numpy, pinocchio, coal, matplotlib and the package's modules allocates a great
many objects that live as long as the process and hold next to no garbage. With the
collector on, the imports trigger many young collections and full ones that scan every
object made so far, and each later full collection scans them all again. Imported with
the collector off and then frozen (:func:`gc.freeze`: moved to the permanent generation),
they are scanned by no collection; garbage made afterwards is collected as usual.

Used where this package owns the process: ``adept-traj`` around its command's imports
(:func:`adept_traj.cli.app.run`) and a run's finishing helper around the drawing
modules' (:mod:`adept_traj.viz.finisher`). A library call never freezes its caller's heap.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["frozen_imports"]


@contextmanager
def frozen_imports() -> Iterator[None]:
    """Run the block (imports) with the cyclic garbage collector off; then freeze every
    object alive (:func:`gc.freeze`) and turn the collector back on if it was on, also
    when the block raises."""
    was_on = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if was_on:
            gc.enable()
