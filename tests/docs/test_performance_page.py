"""Docs that do not drift (issue #27): ``docs/performance.md`` and every figure the README
and the tutorial quote are what ``benchmarks/make_performance_page.py`` makes of the
benchmarks' results files, and the benchmark scripts write those files
(``benchmarks/_results.py``).

The generator and the recorder are checked on sample results written here, against the
text they must produce; the repository's own page, README and tutorial against the
generator's output for the results files in ``benchmarks/results/``.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks"))

import _results  # noqa: E402  (benchmarks/_results.py)
import make_performance_page as page  # noqa: E402  (benchmarks/make_performance_page.py)


@pytest.fixture(autouse=True)
def short_speed_probe(monkeypatch):
    """Every recorded run here probes the machine's speed with a short loop."""
    monkeypatch.setattr(_results, "PROBE_LOOP", 1000)


def sample(name: str = "bench_demo", **extra) -> dict:
    record = {
        "benchmark": name,
        "title": "a demonstration",
        "source": "transcribed from notebook, date 2026-11-30 12:00 UTC",
        "command": f"python benchmarks/{name}.py --repeat 3",
        "date": "2026-11-30 12:00 UTC",
        "machine": {
            "cpu": "Test CPU 9000",
            "cores_available": 2,
            "cores": 4,
            "python": "3.11.7",
            "os": "Linux 6.0",
        },
        "load_average": {"start": [0.5, 0.4, 0.3], "end": [1.0, 0.5, 0.3]},
        "figures": [
            {"id": "run", "name": "the run", "value": 3.5, "digits": 2, "unit": "s",
             "target": "≤ 5 s", "met": True, "runs": [3.4, 3.5, 3.6], "note": ""},
            {"id": "rate", "name": "the rate", "value": 12345, "digits": None, "unit": "/s",
             "target": "≥ 20 000/s", "met": False, "runs": None, "note": "one core"},
            {"id": "span", "name": "a range", "value": "1.1–1.3", "digits": None,
             "unit": "×", "target": None, "met": None, "runs": None, "note": ""},
        ],
        "output": "",
    }  # fmt: skip
    record.update(extra)
    return record


def write(folder: Path, record: dict) -> None:
    (folder / f"{record['benchmark']}.json").write_text(json.dumps(record), encoding="utf-8")


# ------------------------------------------------------------------------------ generator
def test_page_shows_figures_machine_date_and_source(tmp_path):
    write(tmp_path, sample())
    (tmp_path / "bench_demo.quick.json").write_text("not even JSON", encoding="utf-8")
    results = page.load_results(tmp_path)
    assert list(results) == ["bench_demo"]  # the quick run's file is ignored
    text = page.render_page(results)
    assert "## `bench_demo`: a demonstration" in text
    assert "- command: `python benchmarks/bench_demo.py --repeat 3`" in text
    assert "- date: 2026-11-30 12:00 UTC" in text
    assert "- machine: Test CPU 9000, 2 of 4 cores, Python 3.11.7, Linux 6.0" in text
    assert "- load average (1, 5, 15 min): start 0.5, 0.4, 0.3; end 1, 0.5, 0.3" in text
    assert "- source: transcribed from notebook, date 2026-11-30 12:00 UTC" in text
    assert (
        "- machine speed (`_results.speed_probe`: a fixed pure-Python loop): not recorded" in text
    )
    assert "| the run | 3.50 s | ≤ 5 s | met | 3.40, 3.50, 3.60 |" in text
    assert "| the rate | 12 345/s | ≥ 20 000/s | **not met** | one core |" in text
    assert "| a range | 1.1–1.3× |  |  |  |" in text
    # The summary lists the figures with a target, with their date.
    assert "| `bench_demo` | the run | 3.50 s | ≤ 5 s | met | 2026-11-30 12:00 UTC |" in text
    assert "a range" not in text.split("## `bench_demo`")[0]
    # Every benchmark script without a results file is listed as such.
    assert "## Not yet recorded" in text
    assert "- `benchmarks/bench_job.py`:" in text


def test_page_shows_the_speed_probe(tmp_path):
    probe = {"start": {"alone": 0.052, "side_by_side": 0.0731}, "end": None}
    write(tmp_path, sample(speed_probe=probe))
    text = page.render_page(page.load_results(tmp_path))
    assert (
        "- machine speed (`_results.speed_probe`: a fixed pure-Python loop): "
        "start 0.052 s alone, 0.073 s two at once\n" in text
    )


def test_the_speed_probe_times_one_loop_alone_and_two_at_once(monkeypatch):
    """The loop's time grows with its length; side by side, the slower of the two
    processes counts: the second one's time comes back through the pipe."""
    monkeypatch.setattr(_results, "PROBE_LOOP", 100_000)
    short = _results.speed_probe(repeat=1)
    monkeypatch.setattr(_results, "PROBE_LOOP", 1_000_000)
    long = _results.speed_probe(repeat=1)
    assert long["alone"] > 3 * short["alone"] > 0
    assert long["side_by_side"] > 0.7 * long["alone"]
    here = os.getpid()  # a loop whose time says which process ran it
    monkeypatch.setattr(_results, "_probe_loop", lambda: 0.25 if os.getpid() == here else 4.0)
    assert _results.speed_probe(repeat=3) == {"alone": 0.25, "side_by_side": 4.0}


def test_quoted_figures_are_rewritten_and_unknown_ones_refused(tmp_path):
    write(tmp_path, sample())
    results = page.load_results(tmp_path)
    stale = (
        "took <!-- fig bench_demo:run -->9.99 s<!-- /fig --> and "
        "<!-- fig bench_demo:rate -->1/s<!-- /fig -->."
    )
    assert page.render_quotes(stale, results) == (
        "took <!-- fig bench_demo:run -->3.50 s<!-- /fig --> and "
        "<!-- fig bench_demo:rate -->12 345/s<!-- /fig -->."
    )
    block = "a\n<!-- performance-summary -->\nold table\n<!-- /performance-summary -->\nb"
    assert "old table" not in page.render_quotes(block, results)
    with pytest.raises(page.PageError, match="no figure 'gone'"):
        page.render_quotes("<!-- fig bench_demo:gone -->1 s<!-- /fig -->", results)
    with pytest.raises(page.PageError, match="no results file"):
        page.render_quotes("<!-- fig bench_none:run -->1 s<!-- /fig -->", results)


def test_a_damaged_results_file_is_refused(tmp_path):
    record = sample()
    del record["machine"]
    write(tmp_path, record)
    with pytest.raises(page.PageError, match="no 'machine'"):
        page.load_results(tmp_path)
    (tmp_path / "bench_demo.json").write_text("{", encoding="utf-8")
    with pytest.raises(page.PageError, match="not a readable results file"):
        page.load_results(tmp_path)
    (tmp_path / "bench_demo.json").unlink()
    (tmp_path / "bench_x.json").write_text(json.dumps(sample()), encoding="utf-8")
    with pytest.raises(page.PageError, match="is not the file's name"):
        page.load_results(tmp_path)


def test_the_repository_page_readme_and_tutorial_are_up_to_date():
    """Fails when a results file changed and the generator was not run, or when the page,
    the README's figures or the tutorial's were edited by hand."""
    wanted = page.outputs(page.load_results())
    stale = [str(p.relative_to(ROOT)) for p, text in wanted.items() if p.read_text("utf-8") != text]
    assert not stale, f"run python benchmarks/make_performance_page.py: {stale} are stale"
    readme = (ROOT / "README.md").read_text("utf-8")
    tutorial = (ROOT / "docs" / "tutorial.md").read_text("utf-8")
    assert "<!-- fig bench_job:plan -->" in readme
    assert "<!-- fig bench_job:plan -->" in tutorial


def test_every_results_file_names_its_machine_date_and_source():
    results = page.load_results()
    assert "bench_job" in results
    for name, r in results.items():
        assert r["date"].endswith("UTC"), name
        assert r["machine"]["cores"], name
        assert r["source"] == "measured" or r["source"].startswith("transcribed from"), name
        assert all(f["id"] and f["name"] for f in r["figures"]), name


# ------------------------------------------------------------------------------ recorder
def test_recorded_writes_the_figures_and_the_output(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("ADEPT_BENCH_RESULTS", str(tmp_path))
    monkeypatch.delenv("ADEPT_BENCH_NO_RECORD", raising=False)
    with _results.recorded("benchmarks/bench_demo.py", "a demonstration", ["--repeat", "2"]):
        print("| a row |")
        _results.figure("run", "the run", 3.14159, "s", target="≤ 5 s", met=True, digits=2)
        _results.figure("n", "a count", 7)
    record = json.loads((tmp_path / "bench_demo.json").read_text("utf-8"))
    assert record["benchmark"] == "bench_demo"
    assert record["command"] == "python benchmarks/bench_demo.py --repeat 2"
    assert record["source"] == "measured"
    assert record["output"] == "| a row |\n"
    assert record["machine"]["cores"] >= 1
    assert record["machine"]["cpu"]
    assert len(record["load_average"]["start"]) == 3
    assert len(record["load_average"]["end"]) == 3
    for when in ("start", "end"):  # the speed probe, before and after
        probe = record["speed_probe"][when]
        assert 0 < probe["alone"] < 60, probe
        assert 0 < probe["side_by_side"] < 60, probe
    assert [f["id"] for f in record["figures"]] == ["run", "n"]
    assert record["figures"][0]["value"] == 3.14
    assert record["figures"][0]["digits"] == 2
    assert "| a row |" in capsys.readouterr().out  # still printed
    # What it wrote is what the page reads.
    assert page.load_results(tmp_path)["bench_demo"]["figures"][1]["value"] == 7


def test_recorded_leaves_no_file_for_quick_child_or_failed_runs(tmp_path, monkeypatch):
    monkeypatch.setenv("ADEPT_BENCH_RESULTS", str(tmp_path))
    with _results.recorded("bench_demo.py", "t", ["--quick"]):
        _results.figure("a", "a", 1)
    assert [p.name for p in tmp_path.iterdir()] == ["bench_demo.quick.json"]
    with _results.recorded("bench_child.py", "t", ["--json"], child_flags=("--json",)):
        _results.figure("a", "a", 1)  # not recorded: no recording is running
    with pytest.raises(RuntimeError), _results.recorded("bench_fail.py", "t", []):
        raise RuntimeError("the benchmark failed")
    with pytest.raises(SystemExit), _results.recorded("bench_exit.py", "t", []):
        sys.exit(1)
    assert [p.name for p in tmp_path.iterdir()] == ["bench_demo.quick.json"]
    with pytest.raises(SystemExit), _results.recorded("bench_ok.py", "t", []):
        sys.exit(0)
    assert (tmp_path / "bench_ok.json").is_file()
    with _results.recorded("bench_dup.py", "t", []):
        _results.figure("a", "a", 1)
        with pytest.raises(ValueError, match="twice"):
            _results.figure("a", "a", 2)
