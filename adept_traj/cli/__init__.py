"""The ``adept-traj`` command line: :func:`main` (in :mod:`adept_traj.cli.app`) parses the
arguments and runs one command module (``plan``, ``compare``, ``verify``, ``show``,
``robot``, ``build_urdf``); :func:`run` is the program (``main``, then the process ends)."""

from __future__ import annotations

from adept_traj.cli.app import main, run

__all__ = ["main", "run"]
