"""Lint and format checks (ruff, configured in pyproject.toml) as part of the test suite."""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("args", [["check"], ["format", "--check"]])
def test_ruff(args: list[str]) -> None:
    ruff = shutil.which("ruff")
    if ruff is None:
        pytest.fail("ruff is not installed; it is part of the [test] extra")
    result = subprocess.run([ruff, *args, "."], cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr


# ------------------------------------------------------------------------------ docstrings
# One docstring style (numpy: "Parameters" + a line of dashes), and no measured timings in
# docstrings: timings go stale; they live in the benchmarks' results and docs/performance.md.
PACKAGE = ROOT / "adept_traj"

GOOGLE_SECTION = re.compile(
    r"^\s*(?:Args|Arguments|Parameters|Returns?|Raises|Yields|Attributes|Examples?|Notes?"
    r"|Keyword Args|Keyword Arguments|Other Parameters|Warns|Warnings?|See Also|References"
    r"|Todo|Methods):\s*$",
    re.M,
)

_RANGE = r"\d[\d.,]*(?:\s*[–-]\s*\d[\d.,]*)?"
MEASURED_TIMING = re.compile(
    "|".join(
        [
            # a sub-second duration, unless it is a setting ("dt = 1 ms", "default 1 ms")
            # or a resolution ("rounded to 1 ns")
            rf"(?<![\w.=])(?<!= )(?<!default )(?<!to ){_RANGE}\s*(?:ms|µs|ns)\b",
            # a duration said to be taken or measured
            rf"(?:≈|~|about|around|roughly|takes?|took|costs?|measured|in)\s+{_RANGE}\s*"
            r"(?:s|min|seconds?|minutes?|hours?)\b",
            rf"{_RANGE}\s*(?:s|ms)\s+(?:measured|of CPU|CPU|instead of|wall)",
            r"CPU time.{0,40}?\d\s*s\b",
            r"→\s*\d[\d.]*\s*(?:s|ms)\b",
            # a measured speed ratio or rate
            rf"{_RANGE}\s*(?:×|x|times)\s*(?:faster|slower|less time|quicker)",
            r"\bfactor of \d",
            r"\d[\d ,.]*\s*(?:evaluations|evals|calls|members|samples|configurations)/s\b",
        ]
    )
)


def docstrings(path: Path) -> list[tuple[int, str]]:
    """``(line, text)`` of the module's, every class's and every function's docstring, and
    of every ``#:`` comment block (the documentation of a constant or attribute, which
    Sphinx renders as its docstring)."""
    source = path.read_text(encoding="utf-8")
    tree = ast.parse(source)
    out = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            text = ast.get_docstring(node, clean=False)
            if text:
                out.append((node.body[0].lineno, text))
    block: list[str] = []
    for number, line in enumerate([*source.splitlines(), ""], start=1):
        if line.lstrip().startswith("#:"):
            block.append(line.lstrip()[2:])
        elif block:
            out.append((number - len(block), "\n".join(block)))
            block = []
    return out


def google_sections(text: str) -> list[str]:
    return [m.group(0).strip() for m in GOOGLE_SECTION.finditer(text)]


def measured_timings(text: str) -> list[str]:
    # Docstrings wrap lines anywhere: match on the text with its whitespace collapsed.
    return [m.group(0) for m in MEASURED_TIMING.finditer(" ".join(text.split()))]


def _offenders(find) -> list[str]:
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for line, text in docstrings(path):
            found += [f"{path.relative_to(ROOT)}:{line}: {hit!r}" for hit in find(text)]
    return found


def test_docstrings_have_no_google_sections():
    offenders = _offenders(google_sections)
    assert not offenders, "Google-style sections (write numpy ones):\n" + "\n".join(offenders)


def test_docstrings_quote_no_measured_timings():
    offenders = _offenders(measured_timings)
    assert not offenders, (
        "measured timings in docstrings (put them in the benchmarks' results, point to "
        "docs/performance.md):\n" + "\n".join(offenders)
    )


def test_the_docstring_checks_can_fail():
    """Both checks flag what they are for and pass what they must pass."""
    google = """One line.

    Args:
        x: (n, 4) configurations [rad].

    Returns:
        (n,) distances [m].
    """
    numpy = """One line.

    Parameters
    ----------
    x: (n, 4) configurations [rad]; see the Notes below. Returns: never written so.

    Returns
    -------
    (n,) distances [m].
    """
    assert google_sections(google) == ["Args:", "Returns:"]
    assert google_sections(numpy) == []
    # Measured timings, as they stood in the package's docstrings before issue #27.
    for text in (
        "hypervolume 0.6 / 3.7 / 49 / 821 ms for 50 points",
        "with this broad phase takes 37 ms and makes 1 428 coal calls",
        "about 8–9 ms of CPU a member",
        "imports ``scipy.spatial`` (≈ 0.2 s at the start of every run)",
        "evaluate_batch of 100 trajectories 172 → 170 ms",
        "a 200-box cell is built in 1 s instead of 9 s",
        "100 certificates: 0.85 s instead of 1.6 s",
        "waits for that thread to get a core (0.7 s measured at load 3)",
        "the sum of the five best f_w and the CPU time were 2.942 / 16.8 s",
        "moocore is 20–450 times faster",
        "measured 3.3 × faster than batched central differences",
        "compress 2–3× faster into smaller files",
        "computed on first access: about 0.1–5 s per link",
        "a factor of 22",
        "2 237 evaluations/s on one core",
    ):
        assert measured_timings(text), text
    # Units, settings, travel times and rates of a sampling grid are not timings.
    for text in (
        "t: times [s], any shape (...); qd: (n, nq) joint speeds [rad/s | m/s]",
        "with ``dt = 0.001 s`` a move of T = 2.1 s has 2 101 samples",
        "dt: time step [s] (default 1 ms); h = 1 ms: under 1 µrad",
        "``builtin_interfaces/Duration`` of ``t`` ≥ 0 [s], rounded to 1 ns.",
        "certified at 1 kHz; ``sampled at N Hz``; fps [1/s]",
        "Drake's 1.0766 s; NOT FEASIBLE at t = 0.000 s; v0 = 2 m/s",
        "several times faster than a loop",
    ):
        assert not measured_timings(text), text


def test_attribute_comments_are_docstrings(tmp_path: Path) -> None:
    """A ``#:`` block (Sphinx's documentation of a constant) is checked like a docstring."""
    module = tmp_path / "m.py"
    module.write_text('"""Doc."""\n\nX = 1\n#: Block size: a block takes\n#: 37 ms.\nY = 2\n')
    found = docstrings(module)
    assert (4, " Block size: a block takes\n 37 ms.") in found
    assert measured_timings(found[-1][1]) == ["37 ms"]
