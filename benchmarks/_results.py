"""Machine-readable results of the benchmark scripts: ``benchmarks/results/<script>.json``.

Every benchmark script runs its ``main()`` inside :func:`recorded`, and states its headline
figures with :func:`figure` beside what it prints. At the end of a run that did not fail,
:func:`recorded` writes one JSON file::

    {
      "benchmark": "bench_job",              # the script's name
      "title": "...",                        # what it measures, one line
      "source": "measured",                  # or "transcribed from ..., date ..."
      "command": "python benchmarks/bench_job.py --repeat 3",
      "date": "2026-12-01 01:24 UTC",
      "machine": {"cpu": ..., "cores_available": 2, "cores": 2, "python": ..., "os": ...},
      "load_average": {"start": [1, 5, 15 min], "end": [...]},
      "speed_probe": {"start": {"alone": s, "side_by_side": s}, "end": {...}},
      "figures": [{"id", "name", "value", "digits", "unit", "target", "met", "runs",
                   "note"}, ...],
      "output": "what the script printed"
    }

``docs/performance.md`` is generated from these files by
``benchmarks/make_performance_page.py`` (never edited by hand). A run with ``--quick`` (or
``ADEPT_BENCH_NO_RECORD=1``) is a check that the script works, not a measurement: it writes
``<script>.quick.json``, which the page ignores. ``ADEPT_BENCH_RESULTS=DIR`` writes to
another folder.
"""

from __future__ import annotations

import contextlib
import datetime
import io
import json
import os
import platform
import shlex
import statistics
import struct
import sys
import time
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from adept_traj.problem import available_cores

RESULTS = Path(__file__).resolve().parent / "results"

_current: dict[str, Any] | None = None


def machine() -> dict[str, Any]:
    """CPU model, cores available to this process and in the machine, Python and OS."""
    model = platform.processor() or "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {
        "cpu": model,
        "cores_available": available_cores(),
        "cores": os.cpu_count(),
        "python": platform.python_version(),
        "os": f"{platform.system()} {platform.release()}",
    }


def _load() -> list[float]:
    return [round(x, 2) for x in os.getloadavg()]


def _now() -> str:
    return f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC"


def figure(
    fid: str,
    name: str,
    value: float | int | str,
    unit: str = "",
    *,
    target: str | None = None,
    met: bool | None = None,
    runs: Sequence[float] | None = None,
    note: str = "",
    digits: int | None = None,
) -> None:
    """Record one figure of the running benchmark (nothing happens outside :func:`recorded`).

    ``fid`` is its short identifier, unique within the script (the README and the tutorial
    quote a figure as ``bench_job:plan``); ``value`` in ``unit`` (e.g. ``"s"``, ``"/s"``,
    ``"×"``); ``target`` as text (``"≤ 5 s"``) and ``met`` whether this run met it;
    ``runs`` the single measurements a median was taken of; ``digits``, if given, the
    decimals the value is rounded to and shown with.
    """
    if _current is None:
        return
    if any(f["id"] == fid for f in _current["figures"]):
        raise ValueError(f"figure {fid!r} recorded twice")
    if digits is not None and isinstance(value, (int, float)):
        value = round(float(value), digits)
    _current["figures"].append(
        {
            "id": fid,
            "name": name,
            "value": value,
            "digits": digits,
            "unit": unit,
            "target": target,
            "met": met,
            "runs": None if runs is None else [float(r) for r in runs],
            "note": note,
        }
    )


def cpu_times() -> list[int] | None:
    """The machine's CPU times since boot (``/proc/stat``'s ``cpu`` line, in clock ticks:
    user, nice, system, idle, iowait, irq, softirq, steal, …); ``None`` where there is none."""
    try:
        fields = Path("/proc/stat").read_text().splitlines()[0].split()
    except (OSError, IndexError):
        return None
    return [int(v) for v in fields[1:]] if fields and fields[0] == "cpu" else None


def steal_share(start: list[int] | None, end: list[int] | None) -> float | None:
    """The share of the machine's CPU time between two :func:`cpu_times` that the
    hypervisor gave to other machines (*steal*, 0–1; ``None`` where unknown). On a shared
    virtual machine a high share makes every wall time of the run longer than the
    machine's own speed: the page shows it beside the load average."""
    if start is None or end is None or len(start) < 8 or len(end) < 8:
        return None
    spent = [b - a for a, b in zip(start[:8], end[:8])]
    total = sum(spent)
    return round(spent[7] / total, 3) if total > 0 else None


#: Iterations of the speed probe's pure-Python loop.
PROBE_LOOP = 1_000_000


def _probe_loop() -> float:
    """Wall time [s] of a fixed pure-Python loop (no allocation, no I/O)."""
    tic = time.perf_counter()
    total = 0
    for i in range(PROBE_LOOP):
        total += i & 7
    return time.perf_counter() - tic


def speed_probe(repeat: int = 3) -> dict[str, float] | None:
    """The machine's speed now, to read a run's wall times by: the median over ``repeat``
    runs of :data:`PROBE_LOOP` iterations of a fixed pure-Python loop, alone
    (``"alone"`` [s]) and in two processes at once (``"side_by_side"`` [s], the slower of
    the two). On a shared virtual machine both vary with the hour; their ratio is about 1
    where the two vCPUs are two cores and up to 2 where they share one core's time.
    ``None`` without ``fork``."""
    if not hasattr(os, "fork"):
        return None
    alone = statistics.median(_probe_loop() for _ in range(repeat))
    pairs = []
    for _ in range(repeat):
        read, write = os.pipe()
        pid = os.fork()
        if pid == 0:  # the second process: its loop's time through the pipe
            os.close(read)
            os.write(write, struct.pack("d", _probe_loop()))
            os._exit(0)
        os.close(write)  # a second process that dies unheard gives an end of file, not a hang
        mine = _probe_loop()
        with os.fdopen(read, "rb") as pipe:
            sent = pipe.read()
        os.waitpid(pid, 0)
        if len(sent) != 8:
            raise RuntimeError("the speed probe's second process ended without its time")
        pairs.append(max(mine, struct.unpack("d", sent)[0]))
    return {"alone": round(alone, 6), "side_by_side": round(statistics.median(pairs), 6)}


class _Tee(io.TextIOBase):
    def __init__(self, *streams: Any) -> None:
        self._streams = streams

    def write(self, text: str) -> int:
        for s in self._streams:
            s.write(text)
        return len(text)

    def flush(self) -> None:
        for s in self._streams:
            s.flush()


@contextlib.contextmanager
def recorded(
    script: str,
    title: str,
    argv: Sequence[str] | None = None,
    *,
    child_flags: Sequence[str] = (),
) -> Iterator[dict | None]:
    """Run a benchmark's body, collecting its :func:`figure` calls and its printed output,
    and write its results file when the body ends without an exception (or with
    ``sys.exit(0)``). A run whose arguments hold one of ``child_flags`` (the script started
    by itself as a measuring child), or ``-h``/``--help`` (nothing measured), is not
    recorded."""
    global _current
    argv = list(sys.argv[1:] if argv is None else argv)
    if any(flag in argv for flag in (*child_flags, "-h", "--help")):
        yield None
        return
    name = Path(script).stem
    record: dict[str, Any] = {
        "benchmark": name,
        "title": title,
        "source": "measured",
        "command": shlex.join(["python", f"benchmarks/{name}.py", *argv]),
        "date": _now(),
        "machine": machine(),
        "load_average": {"start": _load(), "end": None},
        "speed_probe": {"start": speed_probe(), "end": None},
        "steal": None,
        "figures": [],
        "output": "",
    }
    captured = io.StringIO()
    cpu_start = cpu_times()
    stdout = sys.stdout
    _current, sys.stdout = record, _Tee(stdout, captured)
    ok = False
    try:
        yield record
        ok = True
    except SystemExit as exc:  # sys.exit(0) at the end of a script is a success
        ok = exc.code in (0, None)
        raise
    finally:
        sys.stdout, _current = stdout, None
        if ok:
            record["steal"] = steal_share(cpu_start, cpu_times())
            _write(record, captured.getvalue(), name, argv)


def _write(record: dict[str, Any], output: str, name: str, argv: list[str]) -> None:
    record["load_average"]["end"] = _load()
    record["speed_probe"]["end"] = speed_probe()
    record["output"] = output
    quick = "--quick" in argv or os.environ.get("ADEPT_BENCH_NO_RECORD") == "1"
    folder = Path(os.environ.get("ADEPT_BENCH_RESULTS", RESULTS))
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / (f"{name}.quick.json" if quick else f"{name}.json")
    path.write_text(json.dumps(record, indent=1, ensure_ascii=False) + "\n", encoding="utf-8")
    print(f"results written to {path}", file=sys.stderr)
