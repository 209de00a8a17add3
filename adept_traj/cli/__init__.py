"""The ``adept-traj`` command line: :func:`main` (in :mod:`adept_traj.cli.app`) parses the
arguments and runs one command module (``plan``, ``compare``, ``verify``, ``show``,
``robot``, ``build_urdf``)."""

from __future__ import annotations

from adept_traj.cli.app import main

__all__ = ["main"]
