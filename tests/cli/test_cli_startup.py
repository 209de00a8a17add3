"""``adept-traj --help`` and ``import adept_traj`` load nothing heavy; each command's
module is imported only when that command runs."""

from __future__ import annotations

import argparse
import importlib
import subprocess
import sys

import pytest

import adept_traj
from adept_traj.cli import app

_HEAVY = ("numpy", "pinocchio", "coal", "pymoo", "scipy", "matplotlib", "meshcat")

_CHECK = """
import sys
from adept_traj.cli import main
try:
    main({argv!r})
except SystemExit as exc:
    assert exc.code == 0, exc.code
loaded = sorted(m for m in {heavy!r} if m in sys.modules)
commands = sorted(m for m in sys.modules if m.startswith("adept_traj.cli."))
print(loaded, commands)
"""


def _loaded(argv: list[str]) -> str:
    code = _CHECK.format(argv=argv, heavy=_HEAVY)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return out.stdout.strip().splitlines()[-1]


def test_help_imports_nothing_heavy() -> None:
    assert _loaded(["--help"]) == "[] ['adept_traj.cli.app', 'adept_traj.cli.status']"


def test_a_command_s_help_imports_that_command_only() -> None:
    loaded = _loaded(["front", "--help"])
    assert "'adept_traj.cli.front'" in loaded
    assert "'adept_traj.cli.plan'" not in loaded
    assert "'adept_traj.cli.compare'" not in loaded


def test_import_adept_traj_is_light_and_the_public_names_resolve() -> None:
    code = (
        f"import sys, adept_traj as at\nprint(sorted(m for m in {_HEAVY!r} if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
    for name in adept_traj.__all__:
        value = getattr(adept_traj, name)
        assert value is not None
        assert getattr(value, "__name__", name) == name
    assert set(dir(adept_traj)) >= set(adept_traj.__all__)
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        adept_traj.nope  # noqa: B018


@pytest.mark.parametrize("name", list(app._COMMANDS))
def test_the_listing_shows_each_command_s_own_help_line(name: str) -> None:
    module_name, help_line = app._COMMANDS[name]
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers()
    importlib.import_module(f"adept_traj.cli.{module_name}").add_parser(sub)
    (action,) = sub._choices_actions
    assert (action.dest, action.help) == (name, help_line)
