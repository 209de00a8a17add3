"""Peak memory of ``adept-traj plan`` against the estimate that guards ``--pop``.

Run: ``python benchmarks/bench_memory.py [--pops 1000,2000,5000] [--gens 1]``. For each
population, runs ``adept-traj plan --pop N --gens G --quiet --no-plots --no-html`` in a
subprocess and prints its peak resident memory (``ru_maxrss`` of the child) beside
:func:`adept_traj.optimise.population_bytes`, the estimate the command checks before the
run. Measured on the 2-core development machine (NSGA-II, gens 1, median of 3): pop 5 000
peaked at 1 659 MB before the sampler and the repair worked in blocks, at 555 MB after
(pymoo's duplicate elimination: an (N, N) distance matrix), and at 187 MB with
:class:`~adept_traj.optimise.BlockedDuplicateElimination`.
"""

from __future__ import annotations

import argparse
import resource
import subprocess
import sys
import tempfile
import time

from _results import recorded  # benchmarks/_results.py

from adept_traj.optimise import population_bytes


def peak_rss_mb(argv: list[str]) -> tuple[float, float]:
    """(peak RSS [MB], wall time [s]) of ``python -m adept_traj.cli *argv`` in a child."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "adept_traj.cli", *argv], check=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    # ru_maxrss of the children is the largest of any child so far [KiB]: run the
    # populations in increasing order so that each reading is this child's.
    return max(before, after) / 1024, time.perf_counter() - t0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--pops", default="1000,2000,5000", help="populations, increasing")
    parser.add_argument("--gens", type=int, default=1)
    parser.add_argument("--algorithm", default="nsga2")
    args = parser.parse_args()
    print(f"{'pop':>6} {'peak RSS [MB]':>14} {'estimate [MB]':>14} {'time [s]':>9}")
    for pop in sorted(int(p) for p in args.pops.split(",")):
        with tempfile.TemporaryDirectory() as folder:
            argv = [
                "plan", "--algorithm", args.algorithm, "--pop", str(pop), "--gens",
                str(args.gens), "--quiet", "--no-plots", "--no-html", "--out", f"{folder}/r",
            ]  # fmt: skip
            rss, seconds = peak_rss_mb(argv)
        estimate = population_bytes(pop, args.gens) / 2**20
        print(f"{pop:>6} {rss:>14.0f} {estimate:>14.0f} {seconds:>9.1f}")


if __name__ == "__main__":
    with recorded(__file__, "memory of the evaluation and the certificate"):
        main()
