"""The ``adept-traj`` command line."""

from __future__ import annotations

from adept_traj.cli.commands import main

__all__ = ["main"]
