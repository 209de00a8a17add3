"""``adept-traj verify DIR``: re-run the dense verification of a saved result.

This is the one command that rebuilds the full problem (``result.problem()``, with its
collision checker): re-certification needs it. Exit status 0 if the best trade-off is
feasible, 1 if not.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from adept_traj.analysis import certify
from adept_traj.cli.arguments import check_rate
from adept_traj.results import PlanningResult

__all__ = ["add_parser", "run"]


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``verify`` and its options."""
    p = sub.add_parser("verify", help="re-run the dense verification of a saved result")
    p.add_argument("folder", type=Path, help="result folder (with result.json)")
    p.add_argument("--rate", type=float, default=1000.0, help="verification rate [Hz]")
    return p


def run(args: argparse.Namespace) -> int:
    """Run ``verify``; return the exit status (0 feasible, 1 not)."""
    rate = check_rate(args.rate)
    result = PlanningResult.load(args.folder)
    problem = result.problem()
    try:
        t0 = time.perf_counter()
        cert = certify(problem, result.best_x, rate_hz=rate)
        elapsed = time.perf_counter() - t0
    finally:
        problem.close()
    print(
        f"{args.folder}: re-verified at {rate:g} Hz ({cert.n_samples} samples, "
        f"{elapsed:.2f} s): {'FEASIBLE' if cert.feasible else 'NOT FEASIBLE'}"
        f"; min distance {cert.min_distance:.4f} m (margin {cert.margin} m)"
    )
    for check in cert.checks:
        print(f"  {check.kind:<13} worst {np.max(check.worst):.4f} (bound {check.bound:g})")
    for violation in cert.violations:
        print(f"  violation: {violation}")
    if cert.feasible != result.certificate.feasible:
        print("  note: the saved certificate said otherwise")
    return 0 if cert.feasible else 1
