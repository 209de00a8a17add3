"""Cost of the front indicators: moocore (C, used by the library) against the hand-written
numpy code it replaced (now the test oracles in ``adept_traj.testing.indicator_oracles``).

Run: ``python benchmarks/bench_indicators.py [--repeat 5]``. Fronts of 50–500 mutually
non-dominated points on the positive unit sphere in 6 objectives (the hardest case for the
hypervolume, the size of the planner's fronts). Prints the median wall time of each.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import moocore
import numpy as np
from _results import figure, recorded  # benchmarks/_results.py

from adept_traj.testing.indicator_oracles import dominated_mask, wfg_hypervolume


def median_of(fn: Callable[[], object], repeat: int) -> float:
    """Median wall time [s] of ``repeat`` calls of ``fn``."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def sphere_front(n: int, m: int, seed: int) -> np.ndarray:
    """n mutually non-dominated points (n, m) on the positive unit sphere."""
    X = np.abs(np.random.default_rng(seed).normal(size=(n, m)))
    return X / np.linalg.norm(X, axis=1, keepdims=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=5, help="calls per measurement")
    parser.add_argument("--sizes", type=int, nargs="+", default=[50, 100, 200, 500])
    parser.add_argument("--m", type=int, default=6, help="number of objectives")
    args = parser.parse_args()
    ref = np.full(args.m, 1.1)
    print(f"{args.m} objectives, median of {args.repeat} calls [ms]")
    print(f"{'n':>5} {'HV moocore':>11} {'HV WFG':>11} {'ND moocore':>11} {'ND numpy':>11}")
    for n in args.sizes:
        F = sphere_front(n, args.m, seed=n)
        hv_c = median_of(lambda F=F: moocore.hypervolume(F, ref=ref), args.repeat)
        hv_w = median_of(lambda F=F: wfg_hypervolume(F, ref), max(1, args.repeat // 2))
        nd_c = median_of(lambda F=F: moocore.is_nondominated(F, keep_weakly=True), args.repeat)
        nd_w = median_of(lambda F=F: dominated_mask(F), args.repeat)
        ms = (1e3 * hv_c, 1e3 * hv_w, 1e3 * nd_c, 1e3 * nd_w)
        print(f"{n:>5} {ms[0]:>11.3f} {ms[1]:>11.1f} {ms[2]:>11.3f} {ms[3]:>11.3f}")
        figure(f"hv_{n}", f"hypervolume of {n} points, {args.m} objectives: moocore",
               round(ms[0], 3), "ms", note=f"WFG {ms[1]:.1f} ms")  # fmt: skip
        figure(f"dominance_{n}", f"dominance of {n} points, {args.m} objectives: moocore",
               round(ms[2], 3), "ms", note=f"numpy {ms[3]:.3f} ms")  # fmt: skip


if __name__ == "__main__":
    with recorded(__file__, "hypervolume and dominance: moocore vs the former numpy WFG"):
        main()
