"""``python -m adept_traj.cli``: the ``adept-traj`` command."""

import sys

from adept_traj.cli.app import run

sys.exit(run())
