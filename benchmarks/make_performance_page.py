"""Generate ``docs/performance.md`` from the benchmarks' results, and the figures the README
and the tutorial quote.

Run: ``python benchmarks/make_performance_page.py [--check]``.

Every benchmark script writes ``benchmarks/results/<script>.json`` (``benchmarks/_results.py``:
the machine, the date, the load, the command and its figures). This script renders them as
one page, ``docs/performance.md``: a summary of every figure that has a target, then one
section per benchmark with its machine and date; benchmarks without a results file are
listed as not yet recorded. It also rewrites, in ``README.md`` and ``docs/tutorial.md``:

- every quoted figure, written ``<!-- fig bench_job:plan -->3.98 s<!-- /fig -->`` (the
  figure ``plan`` of ``bench_job.json``; the text between the marks is replaced);
- the block between ``<!-- performance-summary -->`` and ``<!-- /performance-summary -->``
  (the headline figures, as a table).

``--check``: write nothing; exit 1 naming the files that are not what the results give
(``tests/docs/test_performance_page.py`` runs this check). The results files are never edited by
this script.
"""

from __future__ import annotations

import argparse
import ast
import json
import re
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"
PAGE = ROOT / "docs" / "performance.md"
QUOTING = (ROOT / "README.md", ROOT / "docs" / "tutorial.md")

#: The benchmarks in the page's order (the rest follow by name).
ORDER = (
    "bench_job",
    "bench_tests",
    "bench_engine",
    "bench_problem",
    "bench_hard",
    "bench_polish",
    "bench_certify",
    "bench_robots",
    "bench_cells",
    "bench_cycle",
    "bench_cores",
    "bench_robot",
    "bench_indicators",
)

#: The figures of the README's summary table: (benchmark, figure id).
SUMMARY = (
    ("bench_job", "plan"),
    ("bench_job", "mode"),
    ("bench_job", "help"),
    ("bench_job", "save"),
    ("bench_job", "figures"),
    ("bench_job", "rate"),
    ("bench_job", "reference_ratio"),
    ("bench_job", "cell_share"),
    ("bench_tests", "default_tier"),
    ("bench_hard", "paper_time-optimal_wall"),
    ("bench_hard", "detour_nsga2_ratio"),
    ("bench_hard", "detour_time-optimal_wall"),
    ("bench_hard", "wall_crane_nsga2_ratio"),
    ("bench_hard", "post_two_pendulums_nsga2_ratio"),
    ("bench_polish", "time_optimal_T"),
    ("bench_polish", "nsga2_fastest"),
    ("bench_polish", "nsga2_polish_share"),
    ("bench_certify", "nsga2_front"),
    ("bench_certify", "mode_front"),
    ("bench_robots", "ur5_self_rate"),
    ("bench_robots", "ur5_self_certificate"),
    ("bench_cells", "mesh_cell"),
    ("bench_cycle", "bench12_speedup"),
    ("bench_engine", "nsga2_fastest_seed1"),
    ("bench_engine", "mode_fastest_seed1"),
)

_FIG = re.compile(r"<!-- fig (?P<bench>[\w-]+):(?P<fid>[\w.-]+) -->(?P<text>.*?)<!-- /fig -->")
_BLOCK = re.compile(r"(<!-- performance-summary -->\n)(.*?)(<!-- /performance-summary -->)", re.S)


class PageError(Exception):
    """A results file or a quoted figure the page cannot be made from."""


def load_results(folder: Path = RESULTS) -> dict[str, dict[str, Any]]:
    """Every ``<script>.json`` of ``folder`` (not the ``*.quick.json`` of check runs)."""
    out = {}
    for path in sorted(folder.glob("*.json")):
        if path.name.endswith(".quick.json"):
            continue
        try:
            record = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as exc:
            raise PageError(f"{path}: not a readable results file ({exc})") from exc
        for key in ("benchmark", "title", "date", "machine", "figures", "source", "command"):
            if key not in record:
                raise PageError(f"{path}: no {key!r}")
        if record["benchmark"] != path.stem:
            raise PageError(f"{path}: benchmark {record['benchmark']!r} is not the file's name")
        out[path.stem] = record
    return out


def shown(fig: dict[str, Any]) -> str:
    """A figure's value with its unit, as the page prints it (``3.98 s``, ``7 617/s``)."""
    value, unit, digits = fig["value"], fig.get("unit", ""), fig.get("digits")
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        text = f"{value:,.{digits}f}" if digits is not None else f"{value:,}"
        text = text.replace(",", " ") if abs(value) >= 10_000 else text.replace(",", "")
    else:
        text = str(value)
    if unit in ("", "×", "/s", "%"):
        return f"{text}{unit}" if unit != "%" else f"{text} %"
    return f"{text} {unit}"


def _number(x: float, digits: int | None) -> str:
    return f"{x:.{digits}f}" if digits is not None else f"{x:g}"


def _verdict(fig: dict[str, Any]) -> str:
    if fig.get("met") is None:
        return ""
    return "met" if fig["met"] else "**not met**"


def _machine(m: dict[str, Any]) -> str:
    known = lambda key: m.get(key) not in (None, "", "not recorded")  # noqa: E731
    parts = [m["cpu"] if known("cpu") else "CPU not recorded"]
    parts.append(f"{m.get('cores_available', '?')} of {m.get('cores', '?')} cores")
    parts.append(f"Python {m['python']}" if known("python") else "Python not recorded")
    parts.append(m["os"] if known("os") else "OS not recorded")
    return ", ".join(parts)


def _load(record: dict[str, Any]) -> str:
    load = record.get("load_average") or {}
    parts = []
    for when in ("start", "end"):
        if load.get(when):
            parts.append(f"{when} " + ", ".join(f"{x:g}" for x in load[when]))
    return "; ".join(parts) if parts else "not recorded"


def _probe(record: dict[str, Any]) -> str:
    probe = record.get("speed_probe") or {}
    parts = []
    for when in ("start", "end"):
        if probe.get(when):
            p = probe[when]
            parts.append(f"{when} {p['alone']:.3f} s alone, {p['side_by_side']:.3f} s two at once")
    return "; ".join(parts) if parts else "not recorded"


def _steal(record: dict[str, Any]) -> str:
    steal = record.get("steal")
    return "not recorded" if steal is None else f"{100 * steal:.1f} %"


def _cell(text: Any) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _ordered(results: dict[str, dict[str, Any]]) -> list[str]:
    first = [name for name in ORDER if name in results]
    return first + sorted(set(results) - set(first))


def _scripts() -> dict[str, str]:
    """Every benchmark script and the first line of its docstring."""
    out = {}
    for path in sorted(HERE.glob("bench_*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        doc = ast.get_docstring(tree) or ""
        if "__main__" in path.read_text(encoding="utf-8"):  # a script, not a helper module
            out[path.stem] = " ".join(doc.split("\n\n")[0].split())
    return out


def render_page(results: dict[str, dict[str, Any]]) -> str:
    """The text of ``docs/performance.md``."""
    lines = [
        "# Performance",
        "",
        "<!-- Generated by benchmarks/make_performance_page.py from benchmarks/results/*.json:",
        "     do not edit; run a benchmark, then the script. -->",
        "",
        "Every figure on this page comes from a results file of `benchmarks/results/`, written",
        "by the benchmark script named with it (`benchmarks/_results.py`), and is shown with",
        "the machine, the date and the load of its run. The page is generated by",
        "`python benchmarks/make_performance_page.py`, which also writes the figures that",
        "`README.md` and `docs/tutorial.md` quote; `tests/docs/test_performance_page.py` fails",
        "when any of them differs from the results. The machine is shared with other jobs: its",
        "speed moves by up to 2× between hours, so compare the ratios measured within one run,",
        "not absolute times across runs. Speed targets live here, never in timed unit tests.",
        "The lab notebook of the earlier measurements (profiles, paired comparisons against",
        "earlier versions, what was tried and left out) is `benchmarks/results/notebook.md`.",
        "",
        "A results file whose source is not `measured` was transcribed from that notebook or",
        "from the documentation of its time, with the original date and machine, until the",
        "benchmark is run again.",
        "",
        "## Summary",
        "",
        "Every figure with a target, as last recorded:",
        "",
        "| benchmark | figure | measured | target | | date |",
        "|---|---|---|---|---|---|",
    ]
    names = _ordered(results)
    for name in names:
        r = results[name]
        for fig in r["figures"]:
            if fig.get("target"):
                lines.append(
                    f"| `{name}` | {_cell(fig['name'])} | "
                    f"{_cell(shown(fig))} | {_cell(fig['target'])} | {_verdict(fig)} | "
                    f"{r['date']} |"
                )
    for name in names:
        r = results[name]
        lines += [
            "",
            f"## `{name}`: {r['title']}",
            "",
            f"- command: `{r['command']}`",
            f"- date: {r['date']}",
            f"- machine: {_machine(r['machine'])}",
            f"- load average (1, 5, 15 min): {_load(r)}",
            f"- CPU time taken by the hypervisor (steal) during the run: {_steal(r)}",
            f"- machine speed (`_results.speed_probe`: a fixed pure-Python loop): {_probe(r)}",
            f"- source: {r['source']}",
            "",
        ]
        if r["figures"]:
            lines += ["| figure | measured | target | | runs, note |", "|---|---|---|---|---|"]
            for fig in r["figures"]:
                runs = ", ".join(_number(x, fig.get("digits")) for x in fig.get("runs") or ())
                note = "; ".join(t for t in (runs, fig.get("note") or "") if t)
                lines.append(
                    f"| {_cell(fig['name'])} | {_cell(shown(fig))} | {_cell(fig['target'] or '')}"
                    f" | {_verdict(fig)} | {_cell(note)} |"
                )
        else:
            lines.append(
                f"No headline figure: the output is in `benchmarks/results/{name}.json` (`output`)."
            )
    missing = {k: v for k, v in _scripts().items() if k not in results}
    if missing:
        lines += [
            "",
            "## Not yet recorded",
            "",
            "These benchmarks have no results file yet (each writes one when run):",
            "",
        ]
        lines += [f"- `benchmarks/{name}.py`: {doc}" for name, doc in missing.items()]
    return "\n".join(lines) + "\n"


def find_figure(results: dict[str, dict[str, Any]], bench: str, fid: str) -> dict[str, Any]:
    if bench not in results:
        raise PageError(f"no results file benchmarks/results/{bench}.json")
    for fig in results[bench]["figures"]:
        if fig["id"] == fid:
            return fig
    raise PageError(f"benchmarks/results/{bench}.json has no figure {fid!r}")


def render_summary(results: dict[str, dict[str, Any]]) -> str:
    """The README's table of headline figures (what is recorded of :data:`SUMMARY`)."""
    lines = ["| figure | measured | target | | recorded |", "|---|---|---|---|---|"]
    for bench, fid in SUMMARY:
        if bench not in results:
            continue
        try:
            fig = find_figure(results, bench, fid)
        except PageError:
            continue
        lines.append(
            f"| {_cell(fig['name'])} | {_cell(shown(fig))} | {_cell(fig.get('target') or '')} | "
            f"{_verdict(fig)} | `{bench}`, {results[bench]['date']} |"
        )
    return "\n".join(lines) + "\n"


def render_quotes(text: str, results: dict[str, dict[str, Any]]) -> str:
    """``text`` with every quoted figure and the summary block as the results give them."""

    def one(m: re.Match) -> str:
        fig = find_figure(results, m["bench"], m["fid"])
        return f"<!-- fig {m['bench']}:{m['fid']} -->{shown(fig)}<!-- /fig -->"

    text = _FIG.sub(one, text)
    return _BLOCK.sub(lambda m: m[1] + render_summary(results) + m[3], text)


def outputs(results: dict[str, dict[str, Any]]) -> dict[Path, str]:
    """Every generated file and its text."""
    out = {PAGE: render_page(results)}
    for path in QUOTING:
        out[path] = render_quotes(path.read_text(encoding="utf-8"), results)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="write nothing; exit 1 if stale")
    args = parser.parse_args(argv)
    try:
        wanted = outputs(load_results())
    except PageError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    stale = [p for p, text in wanted.items() if not p.exists() or p.read_text("utf-8") != text]
    if args.check:
        for p in stale:
            print(f"{p.relative_to(ROOT)} is not what benchmarks/results/ gives", file=sys.stderr)
        return 1 if stale else 0
    for p in stale:
        p.write_text(wanted[p], encoding="utf-8")
        print(f"wrote {p.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
