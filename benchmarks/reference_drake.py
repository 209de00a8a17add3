"""The best known moves of the benchmark scenes by Drake + SNOPT, each certified by
``adept_traj.certify`` (issue #24).

Run: ``python benchmarks/reference_drake.py [--scenes paper,detour,FILE.toml,...]
[--members DIR,...] [--vias N] [--out benchmarks/reference]``.

What it is, exactly. Not Drake's ``KinematicTrajectoryOptimization`` class: a Drake
``MathematicalProgram`` over **adept_traj's own decision vector** ``x = [T, free B-spline
control points]`` (``adept_traj/problem/bspline.py``: uniform cubic B-spline, 20 knots,
three control points fixed at each end — the variables KTO has, the duration and the
control points of a B-spline, in adept_traj's basis, so no fit is needed to map a result
back), solved by SNOPT (Drake's binary; IPOPT if SNOPT is not available). Cost: T.
Constraints: the smooth per-sample rows of :func:`adept_traj.problem.local_constraints`
with their exact Jacobians — velocity, acceleration, jerk, torque at the samples, and the
signed distance between every robot solid and every obstacle at ``(q(t_k), t_k = T s_k)``,
the pendulums at their pose at ``t_k``: the pendulum is a time-dependent constraint whose
gradient in T (``∂d/∂t · s_k``) couples the timing to the path. The control points' box
bounds keep every joint inside its limits (convex hull). What it shares with the library
is therefore the constraint model (coal distances, Pinocchio dynamics, the spline); the
solver, the multi-start and the adaptive samples are its own.

Each start is solved on the problem's 116 samples; then, until the move is certified
(``adept_traj.certify`` at 1 kHz with its continuous distance bound), the instants where
the certified distance dips below margin + search buffer + 1 mm are added as constraint
samples and it is solved again (at most ``ROUNDS`` times); only then an extra distance
buffer (``BUFFERS``). T is raised to the spline's exact kinematic minimum before every
certificate (the velocity rows are samples). The move kept is the fastest certified one
over all starts.

Starts (multi-start, all seeded, seed 0): straight joint-space moves at five T; ramps (the
straight path, waiting at the start or arriving early); the optimum of the same scene
without its moving obstacles, stretched in time (× 1, 1.1, 1.25, 1.5, 2); moves through
``--vias`` random via configurations (the least infeasible of a larger batch, by the
problem's evaluator); and the front members of adept_traj result folders (``--members``,
the fastest certified members and the least infeasible ones). Every start is screened by
a short solve (``SCREEN_ITERATIONS`` SNOPT major iterations) and the ``REFINED`` most
promising are solved to the end.

Writes ``OUT/reference_moves.json`` (per scene: the best certified T, its start, how it was
made, the date, the machine, the number of starts) and ``OUT/reference_vectors.json``
(the decision vectors). ``benchmarks/bench_hard.py`` reads the first as its best known
moves. Drake is an optional benchmark dependency (``pip install drake``), never imported by
the library or the tests.
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np

import adept_traj as at
from adept_traj.optimise import kinematic_time
from adept_traj.problem import local_constraints

#: SNOPT major iterations of a screening solve and of a full solve.
SCREEN_ITERATIONS = 40
FULL_ITERATIONS = 400

#: Starts solved to the end after screening.
REFINED = 6

#: Rounds of added constraint samples before a buffer is tried.
ROUNDS = 6

#: Extra distance buffers [m] tried, in order, when the rounds end uncertified.
BUFFERS = (0.0, 0.003, 0.006)

#: A certified distance below margin + search buffer + DIP_TOLERANCE [m] adds a sample.
DIP_TOLERANCE = 0.001

#: No buffer is tried when the best move of the rounds is more than FAR [m] inside an
#: obstacle.
FAR = 0.02

#: Stretch factors of the fixed-obstacle optimum.
STRETCHES = (1.0, 1.1, 1.25, 1.5, 2.0)

#: Random generator seed of the via points.
SEED = 0

#: The previous best known moves [s] of the shipped scenes (docs/reference-moves.md): kept
#: unless a certified move here is faster.
PREVIOUS = {
    "paper": (1.0766, "Drake KTO + SNOPT (issue #12); adept_traj 1.0765924 s"),
    "detour": (1.1027, "adept_traj's time-optimal mode (tests/data/detour_best_moves.json)"),
}


def load_problem(name: str, *, fixed_only: bool = False) -> at.TrajectoryProblem:
    """The AdeptOne XL problem of a shipped scene name or a scene file (with its task);
    ``fixed_only``: without the scene's moving obstacles."""
    scene = at.Scene.from_file(name) if name.endswith(".toml") else at.Scene.shipped(name)
    if fixed_only:
        scene = dataclasses.replace(scene, obstacles=scene.fixed, name=scene.name + "-fixed")
    return at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal)


class Rows:
    """The constraint rows g(x) ≤ 0 of one problem with one cached evaluation per x."""

    def __init__(self, problem: at.TrajectoryProblem, extra: np.ndarray, buffer: float):
        self.problem, self.extra, self.buffer = problem, extra, buffer
        self.key: bytes | None = None
        self.calls = 0

    def evaluate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(m,) values and (m, n_var) Jacobian at x."""
        key = x.tobytes()
        if key != self.key:
            self.calls += 1
            lc = local_constraints(self.problem, x, extra_samples=self.extra)
            values, jac = lc.values[0].copy(), lc.jacobian[0]
            values[lc.kind == 4] += self.buffer / self.problem.settings.influence
            self.key, self.cache = key, (values, jac)
        return self.cache

    def __call__(self, x):
        from pydrake.autodiffutils import ExtractGradient, ExtractValue, InitializeAutoDiff

        if x.dtype == object:  # AutoDiffXd: the chain rule through the given derivatives
            value = ExtractValue(x).ravel()
            values, jac = self.evaluate(value)
            return InitializeAutoDiff(values, jac @ ExtractGradient(x)).ravel()
        return self.evaluate(np.asarray(x, dtype=float))[0]


def snopt(
    problem: at.TrajectoryProblem, x0: np.ndarray, extra: np.ndarray, buffer: float, iters: int
) -> np.ndarray:
    """One SNOPT solve of min T s.t. the rows, from x0 (clipped into the box)."""
    from pydrake.solvers import IpoptSolver, MathematicalProgram, SnoptSolver, SolverOptions

    prog = MathematicalProgram()
    x = prog.NewContinuousVariables(problem.n_var, "x")
    lo, hi = np.asarray(problem.xl, float), np.asarray(problem.xu, float)
    prog.AddBoundingBoxConstraint(lo, hi, x)
    prog.AddLinearCost(np.eye(1, problem.n_var)[0], 0.0, x)
    rows = Rows(problem, extra, buffer)
    m = rows.evaluate(np.clip(x0, lo, hi))[0].size
    prog.AddConstraint(rows, np.full(m, -np.inf), np.zeros(m), x, "adept_traj rows")
    snopt_solver = SnoptSolver()
    options = SolverOptions()
    if snopt_solver.available() and snopt_solver.enabled():
        solver, sid = snopt_solver, SnoptSolver.id()
        options.SetOption(sid, "Major iterations limit", iters)
        options.SetOption(sid, "Iterations limit", 200000)
        options.SetOption(sid, "Major optimality tolerance", 1e-6)
        options.SetOption(sid, "Major feasibility tolerance", 1e-7)
    else:
        solver, sid = IpoptSolver(), IpoptSolver.id()
        options.SetOption(sid, "max_iter", iters)
    result = solver.Solve(prog, np.clip(x0, lo, hi), options)
    return np.clip(result.GetSolution(x), lo, hi)


def finish(problem: at.TrajectoryProblem, x: np.ndarray) -> np.ndarray:
    """x with T raised to the spline's exact kinematic minimum where it is below it."""
    out = np.array(x, dtype=float)
    t_kin = float(kinematic_time(problem, out[None])[0])
    out[0] = min(max(out[0], t_kin * (1.0 + 1e-9)), float(problem.xu[0]))
    return out


def dips(problem: at.TrajectoryProblem, cert) -> np.ndarray:
    """Normalised times of the certificate's distance dips below margin + buffer + tol."""
    st = problem.settings
    d, t = cert.dense.min_distance, cert.dense.t
    low = d < st.margin + st.search_buffer + DIP_TOLERANCE
    inner = np.r_[True, d[1:-1] <= d[:-2], True] & np.r_[True, d[1:-1] <= d[2:], True]
    pick = np.flatnonzero(low & inner)
    if cert.t_min_distance is not None and np.isfinite(cert.t_min_distance):
        extra = [float(cert.t_min_distance)]
    else:
        extra = []
    s = np.unique(np.r_[t[pick], extra] / t[-1])
    return np.clip(s, 0.0, 1.0)


def refine(problem: at.TrajectoryProblem, x0: np.ndarray, iters: int, rounds: int):
    """(x, certificate, how) after adaptive samples and, last, buffers."""
    best = None
    for buffer in BUFFERS:
        extra = np.zeros(0)
        x = np.array(x0, dtype=float)
        for k in range(rounds):
            x = finish(problem, snopt(problem, x, extra, buffer, iters))
            cert = at.certify(problem, x)
            how = f"buffer {buffer * 1e3:.0f} mm, {extra.size} added samples, round {k + 1}"
            if cert.feasible:
                return x, cert, how
            if best is None or cert.min_distance > best[1].min_distance:
                best = (x, cert, how)
            new = dips(problem, cert)
            if new.size == 0 and cert.min_distance >= problem.settings.margin:
                break  # not a distance failure (a torque or a limit): no sample to add
            extra = np.unique(np.r_[extra, new])
        if iters <= SCREEN_ITERATIONS or best[1].min_distance < -FAR:
            break  # a buffer does not help a move that far inside an obstacle
    return best


def smooth_step(u: np.ndarray) -> np.ndarray:
    """Rest-to-rest S-curve on [0, 1]."""
    u = np.clip(u, 0.0, 1.0)
    return u**3 * (10.0 + u * (-15.0 + 6.0 * u))


def path_move(problem: at.TrajectoryProblem, knots, points, speed: float = 1.0) -> np.ndarray:
    """A move through ``points`` (k, nq) at normalised times ``knots`` (k,) (piecewise
    linear, timed by an S-curve), at ``speed`` × its kinematic minimum T."""
    traj = problem.trajectory
    u = smooth_step(traj.free_abscissae)
    free = np.stack([np.interp(u, knots, points[:, j]) for j in range(traj.nq)], axis=-1)
    x = traj.encode(1.0, free)
    x[0] = float(kinematic_time(problem, x[None])[0]) * speed
    x[0] = float(np.clip(x[0], problem.xl[0] * 1.0001, problem.xu[0]))
    return x


def starts(problem: at.TrajectoryProblem, scene_arg: str, members, n_vias: int):
    """(label, x) of every start."""
    traj, out = problem.trajectory, []
    t_lo, t_hi = float(problem.xl[0]), float(problem.xu[0])
    for T in np.linspace(t_lo * 1.02, t_hi * 0.97, 5):
        out.append((f"straight T={T:.3f}", traj.straight_line(T)))
    q0, q1 = traj.start, traj.goal
    for a, b in ((0.25, 0.0), (0.45, 0.0), (0.0, 0.25), (0.0, 0.45)):
        knots, pts = [0.0], [q0]
        if a:
            knots.append(a), pts.append(q0)
        knots.append(1.0 - b), pts.append(q1)
        if b:
            knots.append(1.0), pts.append(q1)
        for speed in (1.0, 1.4):
            x = path_move(problem, np.array(knots), np.array(pts), speed)
            out.append((f"ramp wait {a:.2f} early {b:.2f} x{speed}", x))
    if problem.scene.moving:
        fixed = load_problem(scene_arg, fixed_only=True)
        x_fixed, cert, _ = refine(fixed, traj.straight_line(t_lo * 1.3), FULL_ITERATIONS, 3)
        print(f"  fixed-obstacle optimum: T = {x_fixed[0]:.4f} s, certified {cert.feasible}")
        for f in STRETCHES:
            x = x_fixed.copy()
            x[0] = min(x[0] * f, t_hi)
            out.append((f"fixed-obstacle optimum x{f}", x))
    rng = np.random.default_rng(SEED)
    lo, hi = np.asarray(problem.xl[1:], float), np.asarray(problem.xu[1:], float)
    qlo = lo.reshape(traj.nq, -1).min(axis=1)
    qhi = hi.reshape(traj.nq, -1).max(axis=1)
    inset = 0.1 * (qhi - qlo)
    batch = []
    for _ in range(max(8 * n_vias, 1)):
        k = rng.integers(1, 3)
        s = np.sort(rng.uniform(0.2, 0.8, k))
        via = rng.uniform(qlo + inset, qhi - inset, (k, traj.nq))
        knots = np.r_[0.0, s, 1.0]
        pts = np.vstack([q0, via, q1])
        batch.append(path_move(problem, knots, pts, rng.choice((1.0, 1.25, 1.6))))
    if batch and n_vias:
        ev = problem.evaluate_batch(np.array(batch))
        d_min = np.asarray(ev.min_distance).reshape(len(batch), -1).min(axis=1)
        order = np.lexsort((np.array(batch)[:, 0], -d_min))
        for i in order[:n_vias]:
            out.append((f"via points #{i} (d_min {d_min[i]:+.3f} m)", batch[i]))
    for folder in members:
        result = json.loads((Path(folder) / "result.json").read_text())
        front = sorted(result["front"], key=lambda m: (not m["feasible"], m["x"][0]))
        for j, member in enumerate(front[:3]):
            tag = "certified" if member["feasible"] else "not certified"
            out.append((f"{folder} member {j} ({tag})", np.array(member["x"], float)))
    return out


def reference(scene_arg: str, members, n_vias: int) -> dict:
    """The best certified move of one scene over every start."""
    problem = load_problem(scene_arg)
    tic = time.perf_counter()
    candidates = starts(problem, scene_arg, members, n_vias)
    print(f"  {len(candidates)} starts; screening ({SCREEN_ITERATIONS} SNOPT iterations)")
    screened = []
    for label, x0 in candidates:
        x, cert, how = refine(problem, x0, SCREEN_ITERATIONS, 1)
        score = (0 if cert.feasible else 1, -min(cert.min_distance, 0.0), x[0])
        screened.append((score, label, x))
        print(f"    {label:<48} T = {x[0]:.4f} s  d_min {cert.min_distance:+.4f} m  "
              f"{'certified' if cert.feasible else ''}", flush=True)  # fmt: skip
    screened.sort(key=lambda item: item[0])
    best = None
    for _, label, x0 in screened[:REFINED]:
        x, cert, how = refine(problem, x0, FULL_ITERATIONS, ROUNDS)
        print(f"  refined {label:<40} T = {x[0]:.5f} s  certified {cert.feasible}  ({how})")
        if cert.feasible and (best is None or x[0] < best["T"]):
            best = {"T": float(x[0]), "start": label, "solve": how, "x": x.tolist()}
    return {
        "best": best,
        "starts": len(candidates),
        "refined": min(REFINED, len(candidates)),
        "seconds": time.perf_counter() - tic,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--scenes",
        default="paper,detour,benchmarks/scenes/wall_crane.toml,"
        "benchmarks/scenes/post_two_pendulums.toml",
    )
    parser.add_argument("--members", default="", help="result folders per scene: a;b,c;...")
    parser.add_argument("--vias", type=int, default=8)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "reference")
    args = parser.parse_args()
    scenes = args.scenes.split(",")
    members = [m.split(";") if m else [] for m in args.members.split(",")] if args.members else []
    members += [[]] * (len(scenes) - len(members))
    args.out.mkdir(parents=True, exist_ok=True)
    moves_path, vectors_path = (
        args.out / "reference_moves.json",
        args.out / "reference_vectors.json",
    )
    moves = json.loads(moves_path.read_text()) if moves_path.exists() else {}
    vectors = json.loads(vectors_path.read_text()) if vectors_path.exists() else {}
    machine = f"{platform.node()} {platform.machine()} {platform.processor() or ''}".strip()
    for scene_arg, folders in zip(scenes, members, strict=True):
        key = Path(scene_arg).stem
        print(f"{key}:", flush=True)
        found = reference(scene_arg, folders, args.vias)
        best = found["best"]
        drake = None if best is None else round(best["T"], 6)
        entry = {
            "drake_T": drake,
            "drake_start": None if best is None else best["start"],
            "drake_solve": None if best is None else best["solve"],
            "how": "Drake MathematicalProgram + SNOPT on adept_traj's decision vector and "
            "per-sample rows (pendulums as time-dependent distance rows), multi-start "
            f"({found['starts']} starts, {found['refined']} refined), adaptive samples, "
            "certified by adept_traj.certify (1 kHz, continuous bound)",
            "date": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"),
            "machine": machine,
            "seconds": round(found["seconds"], 1),
            "scene": scene_arg,
        }
        previous = PREVIOUS.get(key)
        if previous and (drake is None or previous[0] * (1.0 - 1e-4) <= drake):
            entry["T"], entry["source"] = previous[0], previous[1]
        elif drake is not None:
            entry["T"], entry["source"] = drake, "Drake + SNOPT (this script)"
        else:
            entry["T"], entry["source"] = None, "no certified move found"
        moves[key] = entry
        if best is not None:
            vectors[key] = {"T": best["T"], "source": "Drake + SNOPT", "x": best["x"]}
        print(f"{key}: best certified T = {drake} s (best known {entry['T']})", flush=True)
        moves_path.write_text(json.dumps(moves, indent=2) + "\n")
        vectors_path.write_text(json.dumps(vectors, indent=1) + "\n")
    print(f"written {moves_path} and {vectors_path}", file=sys.stderr)


if __name__ == "__main__":
    main()
