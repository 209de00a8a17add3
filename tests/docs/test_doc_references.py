"""Every module path and dotted name the docs and the README mention exists in the package
(the layout moved once: a stale name in the docs is a broken promise to a reader)."""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGES = [*sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]

#: ``adept_traj.a.b.c`` (dotted) and ``adept_traj/a/b.py`` (paths) in prose and code.
DOTTED = re.compile(r"(?<![\"'])\badept_traj(?:\.[A-Za-z_][A-Za-z0-9_]*)+")  # not in "strings"
PATH = re.compile(r"\badept_traj/[A-Za-z0-9_/]+\.(?:py|toml)\b")


def _resolves(dotted: str) -> bool:
    """True when ``dotted`` is a module, or an attribute chain of one."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for name in parts[cut:]:
            if not hasattr(obj, name):
                return False
            obj = getattr(obj, name)
        return True
    return False


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_dotted_names_exist(page: Path):
    text = page.read_text(encoding="utf-8")
    missing = sorted({m for m in DOTTED.findall(text) if not _resolves(m.rstrip("."))})
    assert not missing, f"{page.name} names what does not exist: {missing}"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_file_paths_exist(page: Path):
    text = page.read_text(encoding="utf-8")
    missing = sorted({m for m in PATH.findall(text) if not (ROOT / m).exists()})
    assert not missing, f"{page.name} names files that do not exist: {missing}"


def test_architecture_page_names_every_module():
    """docs/architecture.md lists every public module of every subpackage by name."""
    page = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    package = ROOT / "adept_traj"
    missing = []
    for path in sorted(package.rglob("*.py")):
        rel = path.relative_to(package)
        if len(rel.parts) < 2 or path.name.startswith("_") or rel.parts[0] == "urdf":
            continue  # top-level modules are named in prose; private ones are not listed
        if f"`{path.stem}`" not in page:
            missing.append(str(rel))
    assert not missing, f"docs/architecture.md does not name {missing}"
