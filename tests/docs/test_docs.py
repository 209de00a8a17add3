"""The documentation cannot rot: the tutorial's code runs, and the Sphinx build is clean.

1. Every ```` ```python ```` block of ``docs/tutorial.md`` is executed, in order, in one
   namespace, in an empty temporary working directory (files the tutorial writes land
   there). A block whose first line starts with ``# tutorial: skip`` (it opens a browser or
   starts a server) is left out.
2. The HTML documentation is built with ``sphinx -W --keep-going`` (every warning is an
   error: broken cross-references, bad docstring markup, pages missing from the toctree);
   the API page must document the public API. Sphinx and myst-parser are part of the
   ``test`` extra: without them these tests fail, they are not skipped.
"""

from __future__ import annotations

import pkgutil
import re
import subprocess
import sys
from pathlib import Path

import pytest

import adept_traj

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
TUTORIAL = DOCS / "tutorial.md"
SKIP_MARK = "# tutorial: skip"

_FENCE_OPEN = re.compile(r"^```python\s*$")
_FENCE_CLOSE = re.compile(r"^```\s*$")


def python_blocks(path: Path) -> list[tuple[int, str]]:
    """``(first line number, code)`` of every ```` ```python ```` block of a Markdown file."""
    blocks: list[tuple[int, str]] = []
    start, body = None, []
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if start is None:
            if _FENCE_OPEN.match(line):
                start, body = number + 1, []
        elif _FENCE_CLOSE.match(line):
            blocks.append((start, "\n".join(body) + "\n"))
            start = None
        else:
            body.append(line)
    assert start is None, f"{path.name}: unclosed ```python block starting at line {start}"
    return blocks


def is_skipped(code: str) -> bool:
    return code.lstrip().startswith(SKIP_MARK)


# ------------------------------------------------------------------------------ tutorial
def test_tutorial_blocks_are_found():
    blocks = python_blocks(TUTORIAL)
    run = [code for _, code in blocks if not is_skipped(code)]
    skipped = [code for _, code in blocks if is_skipped(code)]
    assert len(run) >= 10, "the tutorial should be mostly executable code"
    # Only what starts a server and opens a browser is skipped: the one viz.server.show block.
    assert len(skipped) == 1, skipped
    assert "viz.server.show(loaded, open_browser=True)" in skipped[0]


def test_python_blocks_parser(tmp_path):
    page = tmp_path / "page.md"
    page.write_text(
        "text\n```python\na = 1\n```\n```bash\nls\n```\n"
        "```python\n# tutorial: skip\nopen()\n```\n```python\nb = a + 1\n```\n",
        encoding="utf-8",
    )
    blocks = python_blocks(page)
    assert blocks == [(3, "a = 1\n"), (9, "# tutorial: skip\nopen()\n"), (13, "b = a + 1\n")]
    assert [is_skipped(code) for _, code in blocks] == [False, True, False]


@pytest.mark.slow  # default-tier time (≤ 3 min): the slow tier runs it in CI (.ci/run)
def test_tutorial_runs(tmp_path, monkeypatch):
    """Run the tutorial as a reader would: block after block, one session."""
    monkeypatch.chdir(tmp_path)
    namespace: dict[str, object] = {"__name__": "__tutorial__"}
    ran = 0
    for line, code in python_blocks(TUTORIAL):
        if is_skipped(code):
            continue
        # Blank lines in front keep the line numbers of tracebacks those of tutorial.md.
        compiled = compile("\n" * (line - 1) + code, str(TUTORIAL), "exec")
        exec(compiled, namespace)
        ran += 1
    assert ran >= 10
    # What the tutorial promises to leave behind, in the working directory.
    out = tmp_path / "out"
    for name in ("result.json", "front.csv", "best_trajectory.csv", "playback.html"):
        assert (out / name).is_file(), name
    assert namespace["result"].feasible


# ------------------------------------------------------------------------------ Sphinx
def public_modules() -> list[str]:
    """Every importable module of the package whose name has no leading underscore."""
    names = []
    for info in pkgutil.walk_packages(adept_traj.__path__, "adept_traj."):
        if not any(part.startswith("_") for part in info.name.split(".")):
            names.append(info.name)
    return sorted(names)


def test_api_page_lists_every_public_module_and_export():
    api = (DOCS / "api.md").read_text(encoding="utf-8")
    documented = set(re.findall(r"^\.\. automodule:: (\S+)", api, flags=re.M))
    missing = [m for m in public_modules() if m not in documented]
    assert not missing, f"docs/api.md has no automodule for {missing}"
    exports = [n for n in adept_traj.__all__ if n != "__version__"]
    absent = [n for n in exports if not re.search(rf"\.{re.escape(n)}`", api)]
    assert not absent, f"docs/api.md's table of re-exports lacks {absent}"


@pytest.fixture(scope="module")
def html(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("docs_html")
    doctrees = tmp_path_factory.mktemp("doctrees")
    cmd = [
        sys.executable, "-m", "sphinx",
        "-W", "--keep-going",      # every warning is an error; report them all
        "-E", "-q",                # fresh environment; print warnings only
        "-d", str(doctrees),
        "-b", "html", str(DOCS), str(out),
    ]  # fmt: skip
    proc = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, (
        f"sphinx -W failed (exit {proc.returncode}):\n{proc.stderr}\n{proc.stdout}"
    )
    assert not proc.stderr.strip(), proc.stderr
    return out


@pytest.mark.slow  # default-tier time (≤ 3 min): the slow tier runs it in CI (.ci/run)
def test_docs_build_without_warnings(html):
    for page in ("index", "tutorial", "api", *(p.stem for p in DOCS.glob("*.md"))):
        assert (html / f"{page}.html").is_file(), page


@pytest.mark.slow  # default-tier time (≤ 3 min): the slow tier runs it in CI (.ci/run)
def test_api_page_documents_the_public_api(html):
    api = (html / "api.html").read_text(encoding="utf-8")
    for anchor in (
        'id="adept_traj.problem.trajectory_problem.TrajectoryProblem"',
        'id="adept_traj.robot.robot.Robot"',
        'id="adept_traj.robot.robot.Robot.inverse_dynamics"',
        'id="adept_traj.scene.scene.Scene"',
        'id="adept_traj.optimise.planner.plan"',
        'id="adept_traj.results.record.PlanningResult"',
        'id="adept_traj.certification.certificate.certify"',
        'id="adept_traj.problem.bspline.BSplineTrajectory"',
        'id="adept_traj.collision.checker.CollisionChecker"',
        'id="module-adept_traj.analysis.indicators"',
        'id="module-adept_traj.analysis.decision"',
    ):
        assert anchor in api, anchor
    # Napoleon turned the numpy sections into fields (not literal "Parameters" headings
    # underlined with dashes).
    assert re.search(r'<dt class="field-(?:odd|even)">Parameters<span', api)
    assert "----------" not in api


@pytest.mark.slow  # default-tier time (≤ 3 min): the slow tier runs it in CI (.ci/run)
def test_pages_render_math_and_need_no_network(html):
    """Math is rendered by MathJax in the reader's browser: the pages only link it."""
    tutorial = (html / "tutorial.html").read_text(encoding="utf-8")
    assert "math notranslate" in tutorial  # $...$ went through myst's dollarmath
    assert "mathjax" in tutorial.lower()
    assert "Traceback" not in tutorial
