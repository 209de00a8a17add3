"""A cycle planned as it runs: every move of every pass certified at its real start time on
the scene clock, dwells included (issue 25).

The planned cycle is re-checked by an evaluator that shares no code with the planner's
scene clock: start times re-derived from ``cycle.json``'s dwells and the moves' stored
dense trajectories (``best_trajectory.csv``, read as plain numbers), the pendulum placed by
hand and coal called directly (:mod:`adept_traj.testing.scene_clock`).
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from adept_traj.cli import main
from adept_traj.cycle import (
    MAX_CLOCKED_MOVES,
    clock_playback,
    plan_phase_grid,
    read_cycle_file,
    scene_period,
)
from adept_traj.cycle.clock import plan_on_clock
from adept_traj.errors import CycleError
from adept_traj.results import PlanningResult
from adept_traj.robot import Robot
from adept_traj.scene import Scene
from adept_traj.testing.cycle_files import HOME, PLACE, cycle_text, write_cycle
from adept_traj.testing.scene_clock import clearance_by_hand, pendulum_bob_by_hand

distributed = pytest.importorskip("distributed")

#: A scene the project had not seen: a pendulum whose bob, at one end of its swing, reaches
#: the middle of the straight move between the two locations (the moves collide with it
#: at some start phases only).
SWING = """\
name = "swing"

[[pendulum]]
name = "pendulum"
pivot = [0.9729, -0.783, 1.1031]
length = 0.75
v0 = 2.0
omega = 3.14
swing_axis = [0.7779, -0.6283, 0.0]
bob_radius = 0.08
"""

CYCLE = cycle_text(
    "swing-cycle",
    scene="swing.toml",
    repeat=3,
    plan={"pop_size": 8, "n_gen": 3, "seed": 1},
    dwell={"step": 0.5, "max": 1.5},
    locations={"home": {"joints": HOME}, "place": {"joints": PLACE}},
    moves=[("home", "place"), ("place", "home")],
)

MARGIN = 0.01  # the default ProblemSettings margin [m]


def _files(folder: Path, cycle: str = CYCLE, scene: str = SWING) -> Path:
    return write_cycle(folder, cycle, scenes={"swing.toml": scene})


@pytest.fixture(scope="module")
def planned(tmp_path_factory, cluster) -> Path:
    folder = tmp_path_factory.mktemp("clock")
    path = _files(folder)
    out = folder / "out"
    code = main(
        [
            *("cycle", str(path), "--out", str(out)),
            *("--scheduler", cluster.scheduler_address, "--quiet", "--no-playback"),
        ]
    )
    assert code == 0
    return out


def _dense(folder: Path) -> tuple[np.ndarray, np.ndarray]:
    """(t (n,), q (n, nq)) of a move's stored dense trajectory, read as plain CSV."""
    text = (folder / "best_trajectory.csv").read_text().splitlines()
    header = [h.split(" [")[0].strip() for h in text[0].split(",")]  # "t [s]", "q_joint1 [rad]"
    rows = np.array([[float(v) for v in line.split(",")] for line in text[1:]])
    q_cols = [i for i, h in enumerate(header) if h.startswith("q_")]
    return rows[:, header.index("t")], rows[:, q_cols]


def _clear_by_hand(out: Path, scene: dict, period: float) -> int:
    """Re-check the cycle saved in ``out`` with the oracle (module doc): the start times
    re-derived from the dwells and the stored trajectories (periodic: the pass time a
    multiple of P, later passes shifted by it; back to back: every pass recorded, no
    final dwell), then every move of every pass and every dwell (the robot at rest at the
    move's start) and final dwell clear of the obstacles of the scene file's mapping
    ``scene`` at its real scene times. Returns the moves checked."""
    summary = json.loads((out / "cycle.json").read_text())
    robot, clock = Robot.adept_one_xl(), summary["clock"]
    periodic = clock["scene_clock"] == "periodic"
    if periodic:
        assert clock["period"] == pytest.approx(period, rel=1e-12)
    else:
        assert clock["mode"].endswith("back to back)")
        assert clock["final_dwell"] == 0.0
        assert len(clock["passes"]) == summary["repeat"]
    # the start times by hand: dwells + travel times (+ the final dwell, a multiple of P)
    runs, t = [], 0.0
    for moves in clock["passes"]:
        for m in moves:
            dense_t, _ = _dense(out / m["folder"])
            t += m["dwell"]
            assert m["start_time"] == pytest.approx(t, abs=1e-9)
            runs.append((m, t))
            t += dense_t[-1]
    if periodic:
        pass_time = t + clock["final_dwell"]
        assert pass_time / period == pytest.approx(round(pass_time / period), abs=1e-9)
        assert summary["cycle_time"] == pytest.approx(summary["repeat"] * pass_time, rel=1e-12)
        runs = [(m, s + p * pass_time) for p in range(summary["repeat"]) for m, s in runs]
    else:
        assert summary["cycle_time"] == pytest.approx(t, rel=1e-12)
    checked = 0
    for n, (m, start) in enumerate(runs):
        dense_t, dense_q = _dense(out / m["folder"])
        rows = np.r_[np.arange(0, len(dense_t), 12), len(dense_t) - 1]
        hand, _ = clearance_by_hand(robot, scene, dense_q[rows], start + dense_t[rows])
        assert hand.min() >= MARGIN - 1e-6, (n, m["name"], hand.min())
        # the dwell before it: the robot at rest at its start while the bob moves
        rest = start - m["dwell"] + np.linspace(0.0, m["dwell"], 40)
        still = np.repeat(dense_q[:1], len(rest), axis=0)
        hand, _ = clearance_by_hand(robot, scene, still, rest)
        assert hand.min() >= MARGIN - 1e-6, (n, m["name"], "dwell", hand.min())
        checked += 1
        if periodic and m is clock["passes"][0][-1]:
            final = start + dense_t[-1] + np.linspace(0.0, clock["final_dwell"], 40)
            still = np.repeat(dense_q[-1:], len(final), axis=0)
            assert clearance_by_hand(robot, scene, still, final)[0].min() >= MARGIN - 1e-6
    assert checked == summary["repeat"] * len(clock["passes"][0])
    return checked


@pytest.mark.slow  # the planned cycle: ~10 s for the module's plan
def test_every_move_of_every_pass_is_clear_at_its_real_start_time(planned: Path) -> None:
    scene = Scene.from_file(planned.parent / "swing.toml").to_dict()
    period = 2 * math.pi / scene["pendulum"][0]["omega"]  # by hand, from the file
    assert _clear_by_hand(planned, scene, period) == 6


@pytest.mark.slow  # the planned cycle: ~10 s for the module's plan
def test_the_default_schedule_is_never_longer_than_back_to_back(planned: Path) -> None:
    """The periodic schedule (one pass rounded up to whole periods) and every pass back to
    back are both made; the kept one is the shorter (cycle.json's choice, cycle.md), here
    back to back: without the rounding the passes need no final dwell."""
    summary = json.loads((planned / "cycle.json").read_text())
    choice = summary["clock"]["choice"]
    times = {
        name: float(t)
        for name, t in re.findall(r"(periodic|every pass back to back)[^:]*: ([0-9.]+) s", choice)
    }
    assert set(times) == {"periodic", "every pass back to back"}, choice
    assert summary["cycle_time"] == pytest.approx(min(times.values()), abs=1e-3)
    assert summary["cycle_time"] < times["periodic"]  # this cycle: back to back is shorter
    assert choice.startswith("every pass back to back")
    assert f"Schedule kept: {choice}." in (planned / "cycle.md").read_text()


@pytest.mark.slow  # the planned cycle: ~10 s for the module's plan
def test_the_clock_decides_the_dwells(planned: Path) -> None:
    """The chosen moves are certified for their own start times, not for any: started a
    quarter, half or three quarters of a period later, a move hits the pendulum (by hand;
    a move the local solver took clear of the swing at every phase may not)."""
    summary = json.loads((planned / "cycle.json").read_text())
    candidates = [c for m in summary["clock"]["passes"][0] for c in m["candidates"]]
    assert len(candidates) == 8
    scene = Scene.from_file(planned.parent / "swing.toml").to_dict()
    period = 2 * math.pi / scene["pendulum"][0]["omega"]  # by hand, from the file
    robot = Robot.adept_one_xl()
    hits = []
    for m in summary["clock"]["passes"][0]:
        t, q = _dense(planned / m["folder"])
        rows = np.r_[np.arange(0, len(t), 12), len(t) - 1]
        shifted = [
            clearance_by_hand(robot, scene, q[rows], m["start_time"] + f * period + t[rows])[0]
            for f in (0.25, 0.5, 0.75)
        ]
        hits.append(min(d.min() for d in shifted) < 0.0)
    assert any(hits), hits
    periodic = summary["clock"]["scene_clock"] == "periodic"
    for m in summary["clock"]["passes"][0]:
        result = PlanningResult.load(planned / m["folder"])
        assert result.feasible
        if periodic:  # pass 0 as planned: the earliest certified end of the dwell grid
            assert result.problem_settings.start_time == m["start_time"]
            best = min(c["dwell"] + c["T"] for c in m["candidates"] if c["certified"])
            assert m["dwell"] + m["T"] == best
        else:  # back to back: a plan of the dwell grid of pass 0, run at its real start
            assert re.fullmatch(re.escape(m["name"]) + r"\.p0\.w\d", m["folder"].split("/")[-1])
            assert m["T"] in [c["T"] for c in m["candidates"] if c["certified"]]
    assert (planned / "cycle_gantt.png").stat().st_size > 0
    text = (planned / "cycle.md").read_text()
    assert "## Scene clock" in text
    assert "dwell [s]" in text


@pytest.mark.slow  # the planned cycle: ~10 s for the module's plan
def test_verify_recertifies_every_pass(planned: Path, capsys, tmp_path: Path, cluster) -> None:
    capsys.readouterr()
    assert main(["verify", str(planned)]) == 0
    text = capsys.readouterr().out
    assert text.count(": certified (min") == 3 * 2
    assert "pass 2 place-home" in text
    assert "every move and dwell certified" in text
    # the same lines with the moves certified as Dask tasks (verify --scheduler)
    assert main(["verify", str(planned), "--scheduler", cluster.scheduler_address]) == 0
    assert capsys.readouterr().out == text
    copy = tmp_path / "copy"
    import shutil

    shutil.copytree(planned, copy)
    summary = json.loads((copy / "cycle.json").read_text())
    summary["clock"]["passes"][0][1]["dwell"] += 0.25  # a start time that does not add up
    (copy / "cycle.json").write_text(json.dumps(summary))
    assert main(["verify", str(copy)]) == 3
    assert "mismatch: pass 0 place-home: starts at" in capsys.readouterr().out


@pytest.mark.slow
def test_playback_runs_on_one_continuous_clock(planned: Path, cluster) -> None:
    cycle = read_cycle_file(planned.parent / "c.toml")
    summary = json.loads((planned / "cycle.json").read_text())
    passes = summary["clock"]["passes"]
    results = [[PlanningResult.load(planned / m["folder"]) for m in ms] for ms in passes]
    from adept_traj.cycle.clock import CycleClock

    clock, again = plan_on_clock(cycle, planned, resume=True, scheduler=cluster.scheduler_address)
    assert isinstance(clock, CycleClock)
    assert len(again) == len(passes)
    play = clock_playback(clock, results, robot=Robot.adept_one_xl(), scene=cycle.scene, fps=20)
    assert np.all(np.diff(play.times) > 0)
    assert play.times[0] == 0.0
    assert play.duration == pytest.approx(summary["clock"]["pass_time"], abs=1e-12)
    bob = next(o for o in play.objects if o.path == "obstacles/pendulum.bob")
    entry = cycle.scene.to_dict()["pendulum"][0]
    hand = np.array([pendulum_bob_by_hand(entry, t) for t in play.times])
    np.testing.assert_allclose(bob.poses[:, :3, 3], hand, atol=1e-12)  # never jumps
    step = np.linalg.norm(np.diff(bob.poses[:, :3, 3], axis=0), axis=1)
    assert step.max() < 2.5 * 0.05 + 1e-9  # ≤ bob speed × the longest frame gap


def test_scene_period() -> None:
    one = Scene.from_dict({"pendulum": [json.loads(json.dumps(_pendulum(3.14)))]})
    assert scene_period(one) == pytest.approx(2 * math.pi / 3.14, rel=1e-15)
    both = Scene.from_dict({"pendulum": [_pendulum(3.14, "a"), _pendulum(6.28, "b")]})
    assert scene_period(both) == pytest.approx(2 * math.pi / 3.14, rel=1e-15)
    odd = Scene.from_dict({"pendulum": [_pendulum(3.14, "a"), _pendulum(2.0, "b")]})
    assert scene_period(odd) is None
    assert scene_period(Scene.from_dict({"name": "empty"})) is None


def _pendulum(omega: float, name: str = "p") -> dict:
    return {"name": name, "pivot": [2.0, 2.0, 2.0], "length": 0.5, "v0": 1.0, "omega": omega,
            "bob_radius": 0.05}  # fmt: skip


@pytest.mark.parametrize(
    ("edit", "words"),
    [
        (lambda c, s: (c.replace('from = "place"\nto = "home"', 'from = "home"\nto = "place"'), s),
         "starts at 'home' but the move before it ends at 'place'"),
        (lambda c, s: (c.replace("repeat = 3", "repeat = 150"), s.replace(
            "bob_radius = 0.08", "bob_radius = 0.08\n\n[[pendulum]]\nname = \"q\"\n"
            "pivot = [3.0, 3.0, 2.0]\nlength = 0.5\nv0 = 1.0\nomega = 2.0\nbob_radius = 0.05")),
         f"more than MAX_CLOCKED_MOVES = {MAX_CLOCKED_MOVES}"),
        (lambda c, s: (c.replace("max = 1.5", "max = 50.0"), s), "more than MAX_DWELL_CANDIDATES"),
    ],
)  # fmt: skip
def test_cycles_the_clock_cannot_plan_are_refused(tmp_path: Path, edit, words) -> None:
    cycle, scene = edit(CYCLE, SWING)
    path = _files(tmp_path, cycle, scene)
    with pytest.raises(CycleError, match=words):
        plan_on_clock(read_cycle_file(path), tmp_path / "out", workers=1)


def test_dwell_on_a_fixed_scene_is_refused(tmp_path: Path) -> None:
    path = _files(tmp_path, scene='name = "empty"\n')
    with pytest.raises(CycleError, match="has no moving obstacle: its moves never dwell"):
        read_cycle_file(path)


ONE_MOVE = cycle_text(
    "one",
    scene="empty.toml",
    plan={"pop_size": 16, "n_gen": 4, "seed": 1},
    locations={"home": {"joints": HOME}, "place": {"joints": PLACE}},
    moves=[{"from": "home", "to": "place", "choose": "fastest"}],
)


def test_a_move_asks_for_what_its_weights_say(tmp_path: Path) -> None:
    """``choose``: the best trade-off (the planner's), the fastest certified member, or the
    certified member of least f_c alone (f_c written out here by hand)."""
    from dataclasses import replace

    from adept_traj.cycle import chosen_member, cycle_summary, cycle_tasks, plan_move

    cycle = read_cycle_file(write_cycle(tmp_path, ONE_MOVE, file="one.toml"))
    move = cycle.moves[0]
    assert move.choose == "fastest"
    result = plan_move(cycle_tasks(cycle)[0])
    front = result.front
    ok = np.flatnonzero(front.feasible)
    assert len(ok) > 2
    T = front.objectives[:, 0]
    fastest = chosen_member(result, move)
    assert T[fastest] == T[ok].min()
    only_time = replace(move, choose="weighted-sum", weights=(1.0, 0, 0, 0, 0, 0))
    assert T[chosen_member(result, only_time)] == T[ok].min()
    assert chosen_member(result, replace(move, choose="trade-off")) == result.best.index
    paper = replace(move, choose="weighted-sum", weights=(0.25, 0.25, 0.1, 0.1, 0.15, 0.15))
    z = front.objectives
    lo, hi = z.min(axis=0), z.max(axis=0)
    span = np.where(hi > lo, hi - lo, 1.0)
    score = np.where([False, False, False, True, False, False], (z - lo) / span, (hi - z) / span)
    score = np.where(hi > lo, score, 1.0)
    f_c = (1.0 - score) @ np.array(paper.weights)
    assert chosen_member(result, paper) == ok[np.argmin(f_c[ok])]
    summary = cycle_summary(cycle, [result])
    assert summary["moves"][0]["choose"] == "fastest"
    assert summary["moves"][0]["T"] == T[ok].min()
    assert summary["cycle_time"] == T[ok].min()


def _brute_force(options, P: float, rest_ok, repeat: int, banned=frozenset()) -> float:
    """The least pass time over every sequence of plans, written out again: move k with
    plan (phase φ, T, certified) starts at the first time ≥ the previous end in phase φ."""
    import itertools

    best = math.inf
    for seq in itertools.product(*(range(len(o)) for o in options)):
        end, fine = 0.0, True
        for k, i in enumerate(seq):
            phase, T, ok = options[k][i]
            start = phase
            while start < end - 1e-12:
                start += P
            if not ok or (k, i, start) in banned or not rest_ok(k, end, start - end):
                fine = False
                break
            end = start + T
        span = math.ceil(end / P - 1e-9) * P if repeat > 1 else end
        if fine and (repeat == 1 or rest_ok(len(options), end, span - end)):
            best = min(best, span)
    return best


def _random_plans(seed: int, K: int = 4, N: int = 5, P: float = 2.0):
    """Per move the N grid phases and two off-grid phases (as the arrivals' plans), each
    with a random T and certificate; banned rest phases per location."""
    from adept_traj.cycle import PhaseOption

    rng = np.random.default_rng(seed)
    options = []
    for _ in range(K):
        phases = [*(P * np.arange(N) / N).tolist(), *rng.uniform(0, P, 2).tolist()]
        options.append(
            [
                PhaseOption(f, float(rng.uniform(0.5, 2.6)), bool(rng.uniform() > 0.3))
                for f in phases
            ]
        )
    banned = {(k, j) for k in range(K + 1) for j in range(8) if rng.uniform() < 0.2}

    def rest_ok(k, start, duration):  # a dwell meeting a banned eighth of P is refused
        if duration <= 1e-12:
            return True
        cells = range(math.floor(start / P * 8), math.floor((start + duration) / P * 8) + 1)
        return all((k, c % 8) not in banned for c in cells)

    return options, rest_ok


def _pass_time(path, options, P, repeat):
    i, s = path[-1]
    end = s + options[len(path) - 1][i].T
    return math.ceil(end / P - 1e-9) * P if repeat > 1 else end


@pytest.mark.parametrize("seed", [0, 1, 2, 3, 4, 5])
@pytest.mark.parametrize("repeat", [1, 3])
def test_phase_grid_dynamic_programming_equals_brute_force(seed: int, repeat: int) -> None:
    """Without a beam the dynamic programming over end times finds the least pass time of
    every plan sequence; with one it never beats that, nor does the naive back-to-back
    schedule beat it; every step it takes starts in its plan's phase, at or after the
    previous end, with an allowed dwell and a certified plan, and no banned step."""
    from adept_traj.cycle import phase_schedules

    P = 2.0
    options, rest_ok = _random_plans(seed, P=P)
    raw = [[(o.phase, o.T, o.certified) for o in row] for row in options]
    expected = _brute_force(raw, P, rest_ok, repeat)
    full = phase_schedules(options, P, rest_ok, beam=10**6, repeat=repeat)
    if expected == math.inf:
        assert full["optimised"] is None
        return
    assert _pass_time(full["optimised"], options, P, repeat) == pytest.approx(expected)
    narrow = phase_schedules(options, P, rest_ok, beam=2, repeat=repeat)
    for name in ("optimised", "naive"):
        path = narrow[name]
        if path is None:
            continue
        assert _pass_time(path, options, P, repeat) >= expected - 1e-9
        end = 0.0
        for k, (i, s) in enumerate(path):
            o = options[k][i]
            assert o.certified
            assert s >= end - 1e-9
            assert rest_ok(k, end, s - end)
            assert abs((s - o.phase) / P - round((s - o.phase) / P)) < 1e-9
            end = s + o.T
    if narrow["naive"] is not None:
        span = _pass_time(narrow["naive"], options, P, repeat)
        assert _pass_time(narrow["optimised"], options, P, repeat) <= span + 1e-9
    # A banned step is never taken; the optimum without it is the brute force's.
    i, s = full["optimised"][0]
    ban = frozenset({(0, i, s)})
    again = phase_schedules(options, P, rest_ok, beam=10**6, repeat=repeat, banned=ban)
    expected = _brute_force(raw, P, rest_ok, repeat, ban)
    if again["optimised"] is None:
        assert expected == math.inf
    else:
        assert again["optimised"][0] != (i, s)
        assert _pass_time(again["optimised"], options, P, repeat) == pytest.approx(expected)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_back_to_back_waits_only_where_it_must(seed: int) -> None:
    """Every pass back to back: each move starts at the previous end with the fastest
    plan certified there, and waits (to a plan's phase, with an allowed dwell) only where
    no plan is certified at the previous end; no final dwell. Where every plan is
    certified at every start, the cycle time is repeat × Σ_k min T (closed form)."""
    from adept_traj.cycle import back_to_back

    P, repeat = 2.0, 3
    options, rest_ok = _random_plans(seed, P=P)

    def move_ok(k, i, s):  # certified at its own phase, elsewhere on a random share
        o = options[k][i]
        at_phase = abs((s - o.phase) / P - round((s - o.phase) / P)) < 1e-9
        return o.certified and (at_phase or math.cos(3.7 * s + 1.3 * i + k) > 0.2)

    runs = back_to_back(options, P, repeat, move_ok, rest_ok)
    assert runs is not None  # these seeds have a certified step for every move
    assert len(runs) == repeat
    assert all(len(path) == len(options) for path in runs)
    end = 0.0
    for path in runs:
        for k, (i, s) in enumerate(path):
            ready = [j for j in range(len(options[k])) if move_ok(k, j, end)]
            assert move_ok(k, i, s)
            if ready:
                assert s == end
                assert min(options[k][j].T for j in ready) == options[k][i].T
            else:
                assert s > end
                assert rest_ok(k, end, s - end)
            end = s + options[k][i].T
    always = back_to_back(options, P, repeat, lambda k, i, s: options[k][i].certified, rest_ok)
    fastest = sum(min(o.T for o in row if o.certified) for row in options)
    i, s = always[-1][-1]
    assert s + options[-1][i].T == pytest.approx(repeat * fastest, rel=1e-12)


def _preferred_chain(options, P, repeat, move_ok, rest_ok):
    """The back-to-back schedule written out again, as a search over every sequence: each
    move's step is (plan, start) with start = the previous end (no dwell) or the first time
    after it in the plan's phase (a dwell); a sequence is valid where every plan is
    certified at its phase, ``move_ok`` at its start and ``rest_ok`` for its dwell; the
    preferred valid sequence is the least by its steps' keys, (0, T, plan) without a
    dwell and (1, start, T, plan) with one, compared move by move."""
    import itertools

    K = len(options)
    best = None
    for seq in itertools.product(*[range(2 * len(options[n % K])) for n in range(repeat * K)]):
        end, keys, steps = 0.0, [], []
        for n, c in enumerate(seq):
            k = n % K
            i, wait = c % len(options[k]), c >= len(options[k])
            o = options[k][i]
            start = end
            if wait:
                start = o.phase
                while start <= end + 1e-12:
                    start += P
                while start - P > end + 1e-12:
                    start -= P
            if not (o.certified and move_ok(k, i, start) and rest_ok(k, end, start - end)):
                break
            keys.append((1, start, o.T, i) if wait else (0, o.T, i))
            steps.append((i, start))
            end = start + o.T
        else:
            if best is None or keys < best[0]:
                best = (keys, steps)
    return None if best is None else [tuple(best[1][p * K : (p + 1) * K]) for p in range(repeat)]


def test_back_to_back_backtracks_to_a_certified_chain() -> None:
    """Where the fastest step leaves the next move with no certified step (no plan
    certified at that instant, the robot not allowed to wait there), back_to_back goes
    back and takes the next step: its schedule is the preferred one of a search over every
    sequence of steps (no schedule where that search finds none), on seeds where the
    first steps alone fail too; the prefetch is asked first about the first query."""
    from adept_traj.cycle import PhaseOption, back_to_back

    P, repeat, K = 2.0, 2, 2
    backtracked = 0
    for seed in range(12):
        rng = np.random.default_rng(seed)
        options = [
            [PhaseOption(float(f), float(T), True)
             for f, T in zip(rng.uniform(0, P, 2), rng.uniform(0.4, 1.3, 2))]
            for _ in range(K)
        ]  # fmt: skip

        def move_ok(k, i, s, options=options, seed=seed):  # at its phase; elsewhere at random
            o = options[k][i]
            at_phase = abs((s - o.phase) / P - round((s - o.phase) / P)) < 1e-9
            return at_phase or math.cos(5.3 * s + 2.1 * i + 3 * k + seed) > 0.3

        def rest_ok(k, start, duration):  # the robot may wait at move 0's start only
            return duration <= 1e-12 or k == 0

        asked, prefetched = [], set()

        def counted(k, i, s, asked=asked, move_ok=move_ok):
            asked.append((k, i, s))
            return move_ok(k, i, s)

        runs = back_to_back(options, P, repeat, counted, rest_ok, prefetch=prefetched.update)
        expected = _preferred_chain(options, P, repeat, move_ok, rest_ok)
        assert asked[0] in prefetched
        if expected is None:
            assert runs is None
            continue
        assert [list(p) for p in runs] == [list(p) for p in expected], seed
        try:  # the first steps alone (no step undone)
            back_to_back(options, P, repeat, move_ok, rest_ok, max_undone=0)
        except CycleError:
            backtracked += 1
    assert backtracked >= 2  # the seeds exercise the backtracking


def test_back_to_back_backtracking_is_bounded() -> None:
    """A chain with no certified schedule undoes at most max_undone steps and then says so,
    naming the limit; within the limit it reports that no schedule exists."""
    from adept_traj.cycle import PhaseOption, back_to_back

    options = [[PhaseOption(0.0, 0.5, True), PhaseOption(1.0, 0.7, True)]] * 2

    def never_last(k, i, s):  # the last move of the cycle is never certified
        return not (k == 1 and s > 2.0)

    def rest_ok(k, start, duration):
        return duration <= 1e-12

    with pytest.raises(CycleError, match="MAX_UNDONE = 3"):
        back_to_back(options, 2.0, 3, never_last, rest_ok, max_undone=3)
    assert back_to_back(options, 2.0, 3, never_last, rest_ok) is None


def test_rest_profile_is_conservative() -> None:
    """A dwell the rest profile allows is certified by certify_rest at its real scene
    times (several periods later too); the profile refuses the dwells certify_rest
    refuses (the pendulum of the detour scene swings through its goal)."""
    from adept_traj.cycle import RestProfile, certify_rest
    from adept_traj.problem import ProblemSettings

    scene, robot = Scene.shipped("detour"), Robot.adept_one_xl()
    P = scene_period(scene)
    q = np.array([-0.761, 0.245, 0.2, 1.0095])
    settings = ProblemSettings()
    profile = RestProfile.at(robot, scene, q, P, settings=settings, rate_hz=1000.0)
    rng = np.random.default_rng(4)
    seen = set()
    for start, duration in zip(rng.uniform(0, 3 * P, 8), rng.uniform(0.01, 0.6, 8)):
        exact = certify_rest(robot, scene, q, start, duration, settings=settings, rate_hz=1000.0)
        allowed = profile.allows(start, duration)
        seen.add(allowed)
        assert not allowed or exact.certified
    assert seen == {True, False}
    assert profile.allows(1.0, 0.0)
    assert not profile.allows(0.0, P)


@pytest.mark.slow
def test_phase_grid_cycle_is_certified_at_its_start_times(tmp_path: Path, cluster, capsys) -> None:
    path = _files(tmp_path, CYCLE.replace("[dwell]\nstep = 0.5\nmax = 1.5\n", ""))
    out = tmp_path / "out"
    argv = ["cycle", str(path), "--out", str(out), "--scheduler", cluster.scheduler_address]
    capsys.readouterr()
    assert main([*argv, "--quiet", "--no-playback", "--no-plots", "--phase-grid", "4"]) == 0
    line = capsys.readouterr().err
    summary = json.loads((out / "cycle.json").read_text())
    clock = summary["clock"]
    assert clock["mode"].startswith("phase grid (optimised")
    assert len(clock["phase_grid"]) == 4
    # the shorter of the periodic and the back-to-back schedules (both printed)
    found = re.search(
        r"periodic ([0-9.]+|–) s(?: \(not re-certified\))?, back to back ([0-9.]+|–) s", line
    )
    times = [float(v) for v in found.groups() if v != "–"]
    assert summary["cycle_time"] == pytest.approx(min(times), abs=1e-3)
    back = clock["period"] is None
    assert back == ("back to back" in clock["mode"])
    assert len(clock["passes"]) == (summary["repeat"] if back else 1)
    scene = Scene.from_file(tmp_path / "swing.toml").to_dict()
    robot = Robot.adept_one_xl()
    for p in range(summary["repeat"]):
        for m in clock["passes"][p if back else 0]:
            t, q = _dense(out / m["folder"])
            rows = np.r_[np.arange(0, len(t), 12), len(t) - 1]
            start = m["start_time"] + (0.0 if back else p * clock["pass_time"])
            hand, _ = clearance_by_hand(robot, scene, q[rows], start + t[rows])
            assert hand.min() >= MARGIN - 1e-6
            rest = start - m["dwell"] + np.linspace(0.0, m["dwell"], 40)
            still = np.repeat(q[:1], len(rest), axis=0)
            assert clearance_by_hand(robot, scene, still, rest)[0].min() >= MARGIN - 1e-6
    # the naive schedule is every pass back to back: played on one continuous clock, each
    # move at the scene time it runs (not the phase it was planned at: the bob never jumps)
    cycle = read_cycle_file(path)
    clock, passes, _ = plan_phase_grid(
        cycle, out, phases=4, schedule="naive", resume=True, scheduler=cluster.scheduler_address
    )
    assert clock.period is None
    assert len(clock.passes) == summary["repeat"]
    play = clock_playback(clock, passes, robot=robot, scene=cycle.scene, fps=20)
    assert np.all(np.diff(play.times) > 0)
    assert play.duration == pytest.approx(clock.cycle_time, abs=1e-12)
    bob = next(o for o in play.objects if o.path == "obstacles/pendulum.bob")
    hand = np.array([pendulum_bob_by_hand(scene["pendulum"][0], t) for t in play.times])
    np.testing.assert_allclose(bob.poses[:, :3, 3], hand, atol=1e-12)
    capsys.readouterr()
    assert main(["verify", str(out)]) == 0
    assert "every move and dwell certified" in capsys.readouterr().out


@pytest.mark.slow
def test_a_scene_that_is_not_periodic_plans_every_pass(tmp_path: Path, cluster, capsys) -> None:
    """Two pendulums of incommensurate periods: no common period, so both passes are
    planned, the second starting where the first ends (plus its dwell)."""
    two = SWING + (
        '\n[[pendulum]]\nname = "far"\npivot = [3.0, 3.0, 2.0]\nlength = 0.5\nv0 = 1.0\n'
        "omega = 2.0\nbob_radius = 0.05\n"
    )
    cycle = CYCLE.replace("repeat = 3", "repeat = 2").replace("max = 1.5", "max = 0.5")
    path = _files(tmp_path, cycle, two)
    out = tmp_path / "out"
    argv = ["cycle", str(path), "--out", str(out), "--scheduler", cluster.scheduler_address]
    main([*argv, "--quiet", "--no-playback", "--no-plots"])
    summary = json.loads((out / "cycle.json").read_text())
    clock = summary["clock"]
    assert clock["scene_clock"] == "every pass planned"
    assert clock["period"] is None
    assert len(clock["passes"]) == 2
    first, second = clock["passes"]
    assert second[0]["start_time"] == pytest.approx(first[-1]["end_time"] + second[0]["dwell"])
    assert summary["cycle_time"] == pytest.approx(second[-1]["end_time"])
    scene = Scene.from_file(tmp_path / "swing.toml").to_dict()
    robot = Robot.adept_one_xl()
    for m in first + second:
        t, q = _dense(out / m["folder"])
        rows = np.r_[np.arange(0, len(t), 12), len(t) - 1]
        hand, _ = clearance_by_hand(robot, scene, q[rows], m["start_time"] + t[rows])
        if m["move_certified"]:
            assert hand.min() >= MARGIN - 1e-6
    capsys.readouterr()
    code = main(["verify", str(out)])
    assert code == (0 if summary["all_certified"] else 1)
    assert capsys.readouterr().out.count("start ") == 4


#: Issue 25's cycle on the shipped detour scene (a, b: its start and goal; repeat 5, seed 3)
#: at a small budget, on a grid of 2 phases. The pendulum swings through b, so a robot that
#: waits there is hit at some phases: before the arrivals' plans the phase grid found no
#: certified schedule (every b → a started on the grid, after a dwell at b; measured: "no
#: certified optimised schedule on a grid of 2 phases … a dwell was not certified at b").
DETOUR_CYCLE = cycle_text(
    "detour",
    scene="detour",
    repeat=5,
    plan={"pop_size": 8, "n_gen": 3, "seed": 3},
    locations={"a": {"joints": HOME}, "b": {"joints": PLACE}},
    moves=[("a", "b"), ("b", "a")],
)


@pytest.fixture(scope="module")
def detour_planned(tmp_path_factory, cluster) -> Path:
    folder = tmp_path_factory.mktemp("detour")
    out = folder / "out"
    argv = ["cycle", str(write_cycle(folder, DETOUR_CYCLE, scenes={})), "--out", str(out)]
    argv += ["--scheduler", cluster.scheduler_address, "--quiet", "--no-playback", "--no-plots"]
    assert main([*argv, "--phase-grid", "2"]) == 0
    return out


@pytest.mark.slow  # the detour cycle on the phase grid: minutes
def test_detour_cycle_on_the_phase_grid_is_certified_at_its_real_start_times(
    detour_planned: Path, capsys
) -> None:
    """Every move and dwell of every pass of the phase-grid plan clear of the detour
    scene's obstacles at its real scene time, by hand; ``verify`` agrees."""
    summary = json.loads((detour_planned / "cycle.json").read_text())
    assert summary["clock"]["mode"].startswith("phase grid (optimised")  # or back to back
    assert summary["all_certified"]
    scene = Scene.shipped("detour").to_dict()
    pend = scene["pendulum"][0]
    assert _clear_by_hand(detour_planned, scene, 2 * math.pi / pend["omega"]) == 10
    capsys.readouterr()
    assert main(["verify", str(detour_planned)]) == 0
    assert "every move and dwell certified" in capsys.readouterr().out


@pytest.mark.slow  # the detour cycle on the phase grid: minutes
def test_phase_grid_schedule_is_deterministic(detour_planned: Path, tmp_path: Path, capsys) -> None:
    """The same plans give the same schedule: the saved moves planned again by resume
    into another folder (nothing planned anew) give the same cycle.json, bit for bit; a
    refinement made is said as it starts and in the summary line."""
    import shutil

    out = tmp_path / "again"
    shutil.copytree(detour_planned / "moves", out / "moves")
    source = json.loads((detour_planned / "cycle.json").read_text())["source"]
    argv = ["cycle", source, "--out", str(out), "--workers", "1", "--resume"]
    capsys.readouterr()
    assert main([*argv, "--no-playback", "--no-plots", "--phase-grid", "2"]) == 0
    err = capsys.readouterr().err
    first = json.loads((detour_planned / "cycle.json").read_text())
    second = json.loads((out / "cycle.json").read_text())
    assert first == second
    m = len(first["clock"]["phase_grid"])
    said = [f"refined to {n} phases" for n in (4, 8, 16, 32) if n <= m]
    assert all(f"no certified schedule; {words}" in err for words in said)
    assert (f"phase grid of 2, refined to {m} (" in err) == (m > 2)


@pytest.mark.slow  # the detour cycle on the phase grid: minutes
def test_phase_grid_refines_only_where_its_grid_has_no_certified_schedule(
    detour_planned: Path, tmp_path: Path, capsys
) -> None:
    """The grid of the detour cycle's plan is 2 phases, or a refinement of it (4, 8, …:
    the phases halfway between, saved as NAME.phJofM) made because the 2-phase grid had
    no certified schedule: planned again from its saved 2-phase plans with
    ``--max-phases 2`` (no refinement allowed) the cycle is then refused, naming the grid
    and the bound; else it is the same cycle.json."""
    import shutil

    summary = json.loads((detour_planned / "cycle.json").read_text())
    P = scene_period(Scene.shipped("detour"))
    phases = summary["clock"]["phase_grid"]
    m = len(phases)
    assert m in (2, 4, 8, 16, 32)
    np.testing.assert_allclose(phases, P * np.arange(m) / m, rtol=0, atol=1e-12)
    folders = {p.name for p in (detour_planned / "moves").iterdir()}
    refined = {f for f in folders if re.fullmatch(r"(a-b|b-a)\.ph\d+of\d+", f)}
    assert {"a-b.ph0", "a-b.ph1", "b-a.ph0", "b-a.ph1"} <= folders
    assert len(refined) == 2 * (m - 2)  # every move at each of the m - 2 refined phases
    out = tmp_path / "coarse"
    out.mkdir()
    for f in folders - refined:
        shutil.copytree(detour_planned / "moves" / f, out / "moves" / f)
    source = summary["source"]
    argv = ["cycle", source, "--out", str(out), "--workers", "1", "--resume", "--quiet"]
    argv += ["--no-playback", "--no-plots", "--phase-grid", "2", "--max-phases", "2"]
    capsys.readouterr()
    status = main(argv)
    err = capsys.readouterr().err
    if m > 2:
        assert status == 2
        assert "no optimised schedule certified" in err
        assert "a grid of 2 phases (max_phases = 2)" in err
    else:
        assert status == 0
        assert json.loads((out / "cycle.json").read_text())["clock"] == summary["clock"]


def test_phase_grid_bounds_are_checked_before_any_plan(tmp_path: Path, capsys) -> None:
    """``max_phases`` below ``phases`` or above 1024, and ``--max-phases`` without
    ``--phase-grid``: a CycleError naming the value and its range, nothing planned."""
    path = write_cycle(tmp_path, DETOUR_CYCLE, scenes={})
    cycle = read_cycle_file(path)
    for bad, words in ((3, "max_phases"), (2000, "max_phases")):
        with pytest.raises(CycleError, match=words) as info:
            plan_phase_grid(cycle, tmp_path / "out", phases=4, max_phases=bad)
        assert str(bad) in str(info.value)
    assert not (tmp_path / "out").exists()
    argv = ["cycle", str(path), "--out", str(tmp_path / "cli"), "--max-phases", "4"]
    assert main(argv) == 2
    assert "--max-phases 4" in capsys.readouterr().err
    assert not (tmp_path / "cli").exists()


def _certifier_case() -> tuple:
    """A plan at 0 s of the paper scene, the scene times to ask about it, its own answer at
    0 s (deliberately not certify's) and certify's answers, called directly on a problem
    started at each time: (source, scene, plans, starts, answers)."""
    from adept_traj.certification import certify
    from adept_traj.cycle import PlannedMove
    from adept_traj.problem import TrajectoryProblem
    from adept_traj.robot import RobotSource
    from adept_traj.testing.paper_moves import lift_then_lower

    robot, scene = Robot.adept_one_xl(), Scene.shipped("paper")
    start, goal = np.array(HOME), np.array(PLACE)
    x = lift_then_lower(TrajectoryProblem(robot, scene, start, goal, workers=1))
    starts = [0.0, 0.35, 0.8, 1.4]
    expected = []
    for s in starts:
        problem = TrajectoryProblem(robot, scene, start, goal, workers=1, start_time=s)
        expected.append(bool(certify(problem, x, rate_hz=1000.0).certified))
        problem.close()
    assert len(set(expected)) == 2  # the pendulum: certified at some starts only
    own = not expected[0]
    plans = [[PlannedMove(start, goal, x, 0.0, own)]]
    return RobotSource(), scene, plans, starts, [own, *expected[1:]]


def test_move_certifier_answers_as_certify_at_the_real_start() -> None:
    """A plan asked about at the very time it was planned takes its own certificate (no
    new one); at other scene times the answer is certify's, called directly on a problem
    started there."""
    from adept_traj.cycle import MoveCertifier

    source, scene, plans, starts, answers = _certifier_case()
    here = MoveCertifier(source, scene, 1000.0, plans)
    assert [here(0, 0, s) for s in starts] == answers
    assert here.computed == len(starts) - 1


@pytest.mark.slow  # the same answers in Dask tasks: the cluster's part is the slow one
def test_move_certifier_on_dask_answers_as_certify(cluster) -> None:
    """The answers of :func:`test_move_certifier_answers_as_certify_at_the_real_start`,
    computed in Dask tasks (batches, prefetched)."""
    from distributed import Client

    from adept_traj.cycle import MoveCertifier

    source, scene, plans, starts, answers = _certifier_case()
    with Client(cluster.scheduler_address) as client:
        there = MoveCertifier(source, scene, 1000.0, plans, client=client)
        there.prefetch([(0, 0, s) for s in starts])
        assert there.computed == len(starts) - 1
        assert [there(0, 0, s) for s in starts] == answers


def test_back_to_back_beyond_its_limit_names_it() -> None:
    """More than MAX_BACK_TO_BACK_MOVES moves to chain: not tried (no certificate asked),
    and the reason names the limit; within it, the chain of every plan certified
    everywhere is repeat × the fastest plan's T."""
    from adept_traj.cycle import MAX_BACK_TO_BACK_MOVES, PhaseOption, chain_passes

    options = [[PhaseOption(0.0, 0.5, True), PhaseOption(1.0, 0.7, True)]]
    asked = []

    def move_ok(k, i, s):
        asked.append(s)
        return True

    runs, why = chain_passes(options, 2.0, MAX_BACK_TO_BACK_MOVES + 1, move_ok, lambda *a: True)
    assert runs is None
    assert not asked
    assert f"MAX_BACK_TO_BACK_MOVES = {MAX_BACK_TO_BACK_MOVES}" in why
    runs, why = chain_passes(options, 2.0, 7, move_ok, lambda *a: True)
    assert why is None
    assert [p[0] for p in runs] == [(0, 0.5 * p) for p in range(7)]


def _check_moves_case() -> tuple:
    """``verify``'s checks of a saved move at five scene start times, with rests before
    and after it, and the verdicts of certify and certify_rest called directly:
    (source, scene, checks, expected (feasible, min distance, before, after) per check)."""
    from adept_traj.certification import certify
    from adept_traj.cycle import MoveCheck, certify_rest
    from adept_traj.problem import ProblemSettings, TrajectoryProblem
    from adept_traj.robot import RobotSource
    from adept_traj.testing.paper_moves import lift_then_lower

    robot, scene = Robot.adept_one_xl(), Scene.shipped("paper")
    start, goal = np.array(HOME), np.array(PLACE)
    x = lift_then_lower(TrajectoryProblem(robot, scene, start, goal, workers=1))
    checks, expected = [], []
    for n, s in enumerate([0.0, 0.35, 0.8, 1.4, 0.6]):
        settings = ProblemSettings(start_time=s, workers=1)
        before, after = (max(s - 0.3, 0.0), min(s, 0.3)), (s + x[0], 0.5) if n % 2 else None
        checks.append(MoveCheck(settings, start, goal, x, 1000.0, before, after))
        problem = TrajectoryProblem(robot, scene, start, goal, settings)
        c = certify(problem, x, rate_hz=1000.0)
        problem.close()
        rest = {"settings": settings, "rate_hz": 1000.0}
        kept = certify_rest(robot, scene, start, *before, **rest).certified
        later = None if after is None else certify_rest(robot, scene, goal, *after, **rest)
        expected.append(
            (c.feasible, c.min_distance, kept, None if later is None else later.certified)
        )
    assert len({e[0] for e in expected}) == 2  # the pendulum: certified at some starts only
    return RobotSource(), scene, checks, expected


def test_check_moves_answers_as_certify() -> None:
    """``verify``'s checks (a saved move at a scene start time, the rests before and after
    it) in this process: the verdicts of certify and certify_rest called directly, in
    order."""
    from adept_traj.cycle import check_moves

    source, scene, checks, expected = _check_moves_case()
    found = [
        (v.feasible, v.min_distance, v.before, v.after) for v in check_moves(source, scene, checks)
    ]
    assert found == expected


@pytest.mark.slow  # the same verdicts in Dask tasks: the cluster's part is the slow one
def test_check_moves_on_dask_answers_as_certify(cluster, monkeypatch) -> None:
    """The verdicts of :func:`test_check_moves_answers_as_certify` as Dask tasks (two
    checks per task here: three tasks, the last of one), in order."""
    from distributed import Client

    from adept_traj.cycle import check_moves, recertify

    source, scene, checks, expected = _check_moves_case()
    monkeypatch.setattr(recertify, "CHECKS_PER_TASK", 2)
    with Client(cluster.scheduler_address) as client:
        there = check_moves(source, scene, checks, client)
    assert [(v.feasible, v.min_distance, v.before, v.after) for v in there] == expected
