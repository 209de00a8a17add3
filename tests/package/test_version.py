"""adept_traj.__version__ is the installed distribution's version (one source: pyproject.toml)."""

from __future__ import annotations

import subprocess
import sys
from importlib import metadata
from pathlib import Path

import adept_traj

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]


def test_version_is_the_distribution_version() -> None:
    declared = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert adept_traj.__version__ == metadata.version("adept-traj")
    assert adept_traj.__version__ == declared["project"]["version"]


def test_version_without_installed_metadata_is_unknown() -> None:
    code = (
        "import importlib.metadata as m\n"
        "found = m.version\n"
        "def version(name):\n"
        "    if name == 'adept-traj':\n"
        "        raise m.PackageNotFoundError(name)\n"
        "    return found(name)\n"
        "m.version = version\n"
        "import adept_traj\n"
        "print(adept_traj.__version__)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT
    )
    assert out.stdout.strip() == "0+unknown"
