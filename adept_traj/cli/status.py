"""The exit statuses of the ``adept-traj`` commands (``docs/cli.md``)."""

from __future__ import annotations

import signal

__all__ = ["BAD_INPUT", "INTERRUPTED", "MISMATCH", "NOT_CERTIFIED", "OK", "TERMINATED"]

#: Success (``show``: stopped with Ctrl-C).
OK = 0
#: ``verify``: the best trade-off is not feasible; ``plan``: the run finished and its
#: result folder is written, but its best trade-off is not certified (no certified move
#: was found; with ``--ros`` the ROS file was not written).
NOT_CERTIFIED = 1
#: Bad input: one line ``adept-traj: error: …`` on standard error.
BAD_INPUT = 2
#: ``verify``: a value stored in the result folder differs from its recomputation (the
#: folder was altered, or the robot's files changed since the run); takes precedence over
#: :data:`NOT_CERTIFIED`.
MISMATCH = 3
#: ``plan``, ``compare``: stopped with Ctrl-C (128 + SIGINT).
INTERRUPTED = 128 + signal.SIGINT
#: ``show``: stopped with SIGTERM (128 + SIGTERM); its meshcat server is stopped too.
TERMINATED = 128 + signal.SIGTERM
