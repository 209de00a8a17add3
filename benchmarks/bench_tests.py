"""The test suite's default tier as CI runs it: its wall time and its number of tests.

Run: ``python benchmarks/bench_tests.py [--slow]`` from a checkout (takes minutes: the
default tier is ``python -m pytest``, ``.ci/run``'s first command; ``--slow`` also times
the slow tier, ``python -m pytest -m slow -n 0``, about a quarter of an hour). Each tier runs in
a fresh process in the checkout's root, timed from start to exit; the count is pytest's
own summary line. Target of the default tier: ≤ 3 min on the 2-core machine.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import time
from pathlib import Path

from _results import figure, recorded  # benchmarks/_results.py

ROOT = Path(__file__).resolve().parents[1]

#: Target wall time [s] of the default tier.
DEFAULT_TIER_TARGET = 180.0


def tier(args: list[str]) -> tuple[float, str]:
    """Wall time [s] and pytest's last line of ``python -m pytest ARGS`` in the root."""
    t0 = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *args],
        cwd=ROOT, capture_output=True, text=True, check=False,
    )  # fmt: skip
    wall = time.perf_counter() - t0
    lines = [line for line in done.stdout.splitlines() if line.strip()]
    summary = lines[-1].strip("= ") if lines else "no output"
    if done.returncode != 0:
        raise SystemExit(f"pytest {' '.join(args)} failed (exit {done.returncode}): {summary}")
    return wall, summary


def passed(summary: str) -> int:
    m = re.search(r"(\d+) passed", summary)
    return int(m.group(1)) if m else 0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--slow", action="store_true", help="also time the slow tier")
    args = parser.parse_args()
    wall, summary = tier([])
    print(f"default tier: {wall:.0f} s ({summary})")
    figure(
        "default_tier", "`python -m pytest` (default tier)", round(wall), "s",
        target=f"≤ {DEFAULT_TIER_TARGET:.0f} s", met=wall <= DEFAULT_TIER_TARGET,
        note=f"{passed(summary)} tests passed",
    )  # fmt: skip
    if args.slow:
        wall, summary = tier(["-m", "slow", "-n", "0"])
        print(f"slow tier: {wall:.0f} s ({summary})")
        figure(
            "slow_tier", "`python -m pytest -m slow -n 0`", round(wall), "s",
            note=f"{passed(summary)} tests passed",
        )  # fmt: skip


if __name__ == "__main__":
    with recorded(__file__, "the test suite's default tier as CI runs it"):
        main()
