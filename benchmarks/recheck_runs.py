"""An independent re-check of planning runs' certified members (issue #24: "every reported
member certified").

Run: ``python benchmarks/recheck_runs.py DIR [DIR ...] [--rate-hz 4000] [--random 0]``;
each ``DIR`` is a run folder (``result.json``) or a folder of run folders, e.g. the
``--out`` folder of ``benchmarks/bench_hard.py``.

For each run it re-checks the members a user is most likely to pick: the fastest certified
member of the front, the best trade-off (``best_x``) if it is certified, and ``--random``
more certified members drawn with a fixed seed. Each is sampled uniformly in time at
``--rate-hz`` (default 4 kHz, four times the certificate's rate) along the run's own
B-spline (``problem.trajectory.sample``: the move the result names), and checked by plain
loops sharing no code with the certificate but the libraries:

- the distance of every robot solid to every obstacle, by Pinocchio placements and one
  ``coal.distance`` per pair and sample, each moving obstacle at its pose at that instant of
  the scene's clock (:func:`check_scenes.coal_min_distance`), at least the certificate's
  margin [m];
- the distance between the solids of every link pair the result says it checked
  (``result.self_pairs.checked``), by ``coal.distance`` likewise, at least the margin;
- the joint positions within the result's limits, and the velocity, acceleration and jerk
  by central differences of those samples within theirs (a difference is an average of the
  next derivative over its window, so a move within its limits gives differences within
  them, up to rounding).

Not re-checked here: the torques (the robot's friction and rotor inertia make them
adept_traj's model, not a plain one), and the instants between samples (the certificate's
continuous bound covers those; this is a denser sampling, not a proof). Exit status 1 if a
check fails or a run has no certified member.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
from check_scenes import coal_min_distance  # benchmarks/check_scenes.py

from adept_traj.results import PlanningResult, Replay

#: Rounding allowance of the differences [rad or m per s^order]: q is about 1, eps 1e-16.
_ROUNDING = {1: 1e-9, 2: 1e-6, 3: 1e-3}


def run_folders(paths: list[Path]) -> list[Path]:
    """Every run folder (one holding ``result.json``) among ``paths`` and their children."""
    out: list[Path] = []
    for path in paths:
        if (path / "result.json").is_file():
            out.append(path)
        else:
            found = sorted(p.parent for p in path.glob("*/result.json"))
            if not found:
                raise SystemExit(f"{path}: no result.json in it or in its sub-folders")
            out += found
    return out


def self_min_distance(problem, x: np.ndarray, t: np.ndarray, pairs) -> tuple[float, float, tuple]:
    """(smallest distance [m], time [s], solids) between the solids of the link ``pairs``."""
    T = float(x[0])
    q = problem.trajectory.sample(x, t / T, orders=(0,)).q
    model, gm = problem.robot.model, problem.robot.collision_model
    data, gdata = model.createData(), gm.createData()
    link = [model.frames[g.parentFrame].name for g in gm.geometryObjects]
    wanted = {frozenset(p) for p in pairs}
    solid_pairs = [
        (a, b)
        for a in range(len(link))
        for b in range(a + 1, len(link))
        if frozenset((link[a], link[b])) in wanted
    ]
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    request.gjk_tolerance = 1e-9
    best = (np.inf, 0.0, ("", ""))
    for k in range(t.size):
        pin.updateGeometryPlacements(model, data, gm, gdata, q[k])
        tf = [coal.Transform3s(m.rotation, m.translation) for m in gdata.oMg]
        for a, b in solid_pairs:
            result.clear()
            ga, gb = gm.geometryObjects[a], gm.geometryObjects[b]
            d = coal.distance(ga.geometry, tf[a], gb.geometry, tf[b], request, result)
            if d < best[0]:
                best = (d, float(t[k]), (ga.name, gb.name))
    return best


def limit_excess(problem, x: np.ndarray, t: np.ndarray, limits) -> dict[str, float]:
    """The largest excess over each limit (negative: within) of the samples at ``t``."""
    T = float(x[0])
    q = problem.trajectory.sample(x, t / T, orders=(0,)).q  # (n, nq)
    h = float(t[1] - t[0])
    out = {"position": float(max((q - limits.upper).max(), (limits.lower - q).max()))}
    diffs = {
        1: (q[2:] - q[:-2]) / (2 * h),
        2: (q[2:] - 2 * q[1:-1] + q[:-2]) / h**2,
        3: (q[4:] - 2 * q[3:-1] + 2 * q[1:-3] - q[:-4]) / (2 * h**3),
    }
    for order, name in ((1, "velocity"), (2, "acceleration"), (3, "jerk")):
        bound = getattr(limits, name)
        out[name] = float((np.abs(diffs[order]) - bound - _ROUNDING[order]).max())
    return out


def members(result: PlanningResult, n_random: int, rng: np.random.Generator) -> dict:
    """``{label: decision vector}`` of the members to re-check (empty: none certified)."""
    feasible = np.flatnonzero(result.front.feasible)
    x = result.front.x
    picked: dict[str, np.ndarray] = {}
    if feasible.size:
        picked["fastest"] = x[feasible[np.argmin(x[feasible, 0])]]
    best = np.asarray(result.best_x)
    if result.feasible and not ("fastest" in picked and np.array_equal(best, picked["fastest"])):
        picked["best trade-off"] = best  # whether or not it is a row of the front
    if feasible.size:
        others = feasible[np.any(x[feasible] != picked["fastest"], axis=1)]
        for k in rng.choice(others, size=min(n_random, others.size), replace=False):
            picked[f"member {int(k)}"] = x[k]
    return picked


def recheck(folder: Path, rate_hz: float, n_random: int, rng: np.random.Generator) -> bool:
    """Print the re-check of one run folder; True if every check passes."""
    result = PlanningResult.load(folder)
    picked = members(result, n_random, rng)
    if not picked:
        print(f"{folder}: NO CERTIFIED MEMBER")
        return False
    start = Replay.of(result).start_time  # the scene's clock at the move's start [s]
    margin = float(result.certificate.margin)
    pairs = result.self_pairs.checked if result.self_pairs is not None else ()
    problem = result.problem()
    ok = True
    try:
        for label, x in picked.items():
            T = float(x[0])
            t = np.linspace(0.0, T, int(np.ceil(T * rate_hz)) + 1)
            d, t_d, pair = coal_min_distance(problem, x, rate_hz, start_time=start)
            own = self_min_distance(problem, x, t, pairs) if pairs else (np.inf, 0.0, None)
            excess = limit_excess(problem, x, t, result.limits)
            good = d >= margin and own[0] >= margin and max(excess.values()) <= 0.0
            ok &= good
            worst_limit = max(excess, key=excess.get)
            print(
                f"{folder.name:<28} {label:<15} T {T:.4f} s: obstacles {d - margin:+.5f} m "
                f"over the margin at {t_d:.3f} s {pair}; "
                + (f"self {own[0] - margin:+.5f} m {own[2]}" if pairs else "self not checked")
                + f"; limits: {worst_limit} {excess[worst_limit]:+.3g} "
                f"{'ok' if good else 'FAILED'}",
                flush=True,
            )
    finally:
        problem.close()
    return ok


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="+", type=Path)
    parser.add_argument("--rate-hz", type=float, default=4000.0)
    parser.add_argument("--random", type=int, default=0, help="more certified members per run")
    args = parser.parse_args()
    if not args.rate_hz >= 1000.0:
        parser.error(
            f"--rate-hz must be at least 1000 (the certificate's rate); got {args.rate_hz}"
        )
    if args.random < 0:
        parser.error(f"--random must be 0 or more; got {args.random}")
    rng = np.random.default_rng(0)
    folders = run_folders(args.folders)
    results = [recheck(f, args.rate_hz, args.random, rng) for f in folders]
    failed = results.count(False)
    print(f"{len(folders)} runs re-checked: {failed} failed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
