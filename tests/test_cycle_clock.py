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
from pathlib import Path

import numpy as np
import pytest

from adept_traj.cli import main
from adept_traj.cycle import (
    MAX_CLOCKED_MOVES,
    clock_playback,
    read_cycle_file,
    scene_period,
)
from adept_traj.cycle.clock import plan_on_clock
from adept_traj.errors import CycleError
from adept_traj.results import PlanningResult
from adept_traj.robot import Robot
from adept_traj.scene import Scene
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

CYCLE = """\
name = "swing-cycle"
scene = "swing.toml"
repeat = 3

[plan]
pop_size = 8
n_gen = 3
seed = 1

[dwell]
step = 0.5
max = 1.5

[[location]]
name = "home"
joints = [0.1682, 1.3849, 0.08, -0.7555]

[[location]]
name = "place"
joints = [-0.761, 0.245, 0.2, 1.0095]

[[move]]
from = "home"
to = "place"

[[move]]
from = "place"
to = "home"
"""

MARGIN = 0.01  # the default ProblemSettings margin [m]


def _files(folder: Path, cycle: str = CYCLE, scene: str = SWING) -> Path:
    (folder / "swing.toml").write_text(scene)
    path = folder / "c.toml"
    path.write_text(cycle)
    return path


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as c:
        yield c


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


@pytest.mark.slow  # the planned cycle: ~10 s for the module's plan
def test_every_move_of_every_pass_is_clear_at_its_real_start_time(planned: Path) -> None:
    summary = json.loads((planned / "cycle.json").read_text())
    scene = Scene.from_file(planned.parent / "swing.toml").to_dict()
    robot = Robot.adept_one_xl()
    clock = summary["clock"]
    assert clock["scene_clock"] == "periodic"
    period = 2 * math.pi / scene["pendulum"][0]["omega"]  # by hand, from the file
    assert clock["period"] == pytest.approx(period, rel=1e-12)
    moves = clock["passes"][0]
    # the pass time by hand: dwells + travel times + the final dwell, a multiple of P
    ends, t = [], 0.0
    for m in moves:
        dense_t, _ = _dense(planned / m["folder"])
        t += m["dwell"]
        assert m["start_time"] == pytest.approx(t, abs=1e-12)
        t += dense_t[-1]
        ends.append(t)
    pass_time = t + clock["final_dwell"]
    assert pass_time / period == pytest.approx(round(pass_time / period), abs=1e-9)
    assert summary["cycle_time"] == pytest.approx(summary["repeat"] * pass_time, rel=1e-12)
    checked = 0
    for p in range(summary["repeat"]):
        for m in moves:
            dense_t, dense_q = _dense(planned / m["folder"])
            start = m["start_time"] + p * pass_time
            rows = np.r_[np.arange(0, len(dense_t), 12), len(dense_t) - 1]
            hand, _ = clearance_by_hand(robot, scene, dense_q[rows], start + dense_t[rows])
            assert hand.min() >= MARGIN - 1e-6, (p, m["name"], hand.min())
            # the dwell before it: the robot at rest at its start while the bob moves
            rest = start - m["dwell"] + np.linspace(0.0, m["dwell"], 40)
            still = np.repeat(dense_q[:1], len(rest), axis=0)
            hand, _ = clearance_by_hand(robot, scene, still, rest)
            assert hand.min() >= MARGIN - 1e-6
            checked += 1
        final = ends[-1] + p * pass_time + np.linspace(0.0, clock["final_dwell"], 40)
        still = np.repeat(_dense(planned / moves[-1]["folder"])[1][-1:], len(final), axis=0)
        assert clearance_by_hand(robot, scene, still, final)[0].min() >= MARGIN - 1e-6
    assert checked == summary["repeat"] * len(moves)


@pytest.mark.slow  # the planned cycle: ~10 s for the module's plan
def test_the_clock_decides_the_dwells(planned: Path) -> None:
    """The chosen moves are certified for their own start times, not for any: started a
    quarter, half or three quarters of a period later, a move hits the pendulum (by hand;
    a move the local solver took clear of the swing at every phase may not)."""
    summary = json.loads((planned / "cycle.json").read_text())
    candidates = [c for m in summary["clock"]["passes"][0] for c in m["candidates"]]
    assert len(candidates) == 8
    scene = Scene.from_file(planned.parent / "swing.toml").to_dict()
    period, robot = summary["clock"]["period"], Robot.adept_one_xl()
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
    for m in summary["clock"]["passes"][0]:
        result = PlanningResult.load(planned / m["folder"])
        assert result.problem_settings.start_time == m["start_time"]
        assert result.feasible
        best = min(c["dwell"] + c["T"] for c in m["candidates"] if c["certified"])
        assert m["dwell"] + m["T"] == best  # the earliest certified end
    assert (planned / "cycle_gantt.png").stat().st_size > 0
    text = (planned / "cycle.md").read_text()
    assert "## Scene clock" in text
    assert "dwell [s]" in text


@pytest.mark.slow  # the planned cycle: ~10 s for the module's plan
def test_verify_recertifies_every_pass(planned: Path, capsys, tmp_path: Path) -> None:
    capsys.readouterr()
    assert main(["verify", str(planned)]) == 0
    text = capsys.readouterr().out
    assert text.count(": certified (min") == 3 * 2
    assert "pass 2 place-home" in text
    assert "every move and dwell certified" in text
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
    results = [[PlanningResult.load(planned / m["folder"]) for m in summary["clock"]["passes"][0]]]
    from adept_traj.cycle.clock import CycleClock

    clock, _ = plan_on_clock(cycle, planned, resume=True, scheduler=cluster.scheduler_address)
    assert isinstance(clock, CycleClock)
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


ONE_MOVE = """\
name = "one"
scene = "empty.toml"

[plan]
pop_size = 16
n_gen = 4
seed = 1

[[location]]
name = "home"
joints = [0.1682, 1.3849, 0.08, -0.7555]

[[location]]
name = "place"
joints = [-0.761, 0.245, 0.2, 1.0095]

[[move]]
from = "home"
to = "place"
choose = "fastest"
"""


def test_a_move_asks_for_what_its_weights_say(tmp_path: Path) -> None:
    """``choose``: the best trade-off (the planner's), the fastest certified member, or the
    certified member of least f_c alone (f_c written out here by hand)."""
    from dataclasses import replace

    from adept_traj.cycle import chosen_member, cycle_summary, cycle_tasks, plan_move

    (tmp_path / "empty.toml").write_text('name = "empty"\n')
    (tmp_path / "one.toml").write_text(ONE_MOVE)
    cycle = read_cycle_file(tmp_path / "one.toml")
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


def _brute_force(T: np.ndarray, ok: np.ndarray, P: float, phases: np.ndarray, rest_ok) -> float:
    """The least pass time over every sequence of start phases, written out again."""
    import itertools

    best = math.inf
    for seq in itertools.product(range(len(phases)), repeat=T.shape[0]):
        end, fine = 0.0, True
        for k, j in enumerate(seq):
            if not ok[k, j]:
                fine = False
                break
            start = phases[j]
            while start < end - 1e-12:  # the first time ≥ end in phase j
                start += P
            if not rest_ok(k, end, start - end):
                fine = False
                break
            end = start + T[k, j]
        if fine:
            best = min(best, math.ceil(end / P - 1e-9) * P)
    return best


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_phase_grid_dynamic_programming_equals_brute_force(seed: int) -> None:
    from adept_traj.cycle import PhaseTable, phase_schedules

    rng = np.random.default_rng(seed)
    K, N, P = 4, 5, 2.0
    phases = P * np.arange(N) / N
    T = rng.uniform(0.5, 2.6, size=(K, N))
    ok = rng.uniform(size=(K, N)) > 0.3
    banned = {(k, j) for k in range(K) for j in range(N) if rng.uniform() < 0.15}

    def rest_ok(k, start, duration):  # a dwell ending in a banned phase is not certified
        return duration <= 1e-12 or (k, round(((start + duration) % P) / P * N) % N) not in banned

    table = PhaseTable(P, phases, T, ok, np.zeros((K, N), dtype=int))
    found = phase_schedules(table, rest_ok)
    expected = _brute_force(T, ok, P, phases, rest_ok)
    if found["optimised"] is None:
        assert expected == math.inf
        return
    j, start = found["optimised"][-1]
    assert math.ceil((start + T[K - 1, j]) / P - 1e-9) * P == pytest.approx(expected)
    if found["naive"] is not None:  # back to back: never better than the optimum
        jn, sn = found["naive"][-1]
        assert math.ceil((sn + T[K - 1, jn]) / P - 1e-9) * P >= expected - 1e-9


@pytest.mark.slow
def test_phase_grid_cycle_is_certified_at_its_start_times(tmp_path: Path, cluster, capsys) -> None:
    path = _files(tmp_path, CYCLE.replace("[dwell]\nstep = 0.5\nmax = 1.5\n", ""))
    out = tmp_path / "out"
    argv = ["cycle", str(path), "--out", str(out), "--scheduler", cluster.scheduler_address]
    assert main([*argv, "--quiet", "--no-playback", "--no-plots", "--phase-grid", "4"]) == 0
    summary = json.loads((out / "cycle.json").read_text())
    clock = summary["clock"]
    assert clock["mode"] == "phase grid (optimised)"
    assert len(clock["phase_grid"]) == 4
    scene = Scene.from_file(tmp_path / "swing.toml").to_dict()
    robot = Robot.adept_one_xl()
    for p in range(summary["repeat"]):
        for m in clock["passes"][0]:
            t, q = _dense(out / m["folder"])
            rows = np.r_[np.arange(0, len(t), 12), len(t) - 1]
            start = m["start_time"] + p * clock["pass_time"]
            hand, _ = clearance_by_hand(robot, scene, q[rows], start + t[rows])
            assert hand.min() >= MARGIN - 1e-6
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
