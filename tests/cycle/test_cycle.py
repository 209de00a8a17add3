"""Cycle files and ``adept-traj cycle``: moves planned as Dask tasks.

One local Dask cluster (two single-threaded worker processes) is shared by the module;
the commands reach it with ``--scheduler``."""

from __future__ import annotations

import json
import os
import shutil
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from adept_traj.cli import main
from adept_traj.cycle import (
    ALGORITHM_PAIR,
    BOXPLOT_FIGURE,
    CYCLE_FILE,
    METRICS,
    MOVE_FILE,
    MOVES_FOLDER,
    RUNS_FOLDER,
    STUDY_FILE,
    cycle_playback,
    cycle_tasks,
    parse_seeds,
    plan_move,
    read_cycle_file,
    run_cycle,
    study_statistics,
    write_study_report,
)
from adept_traj.errors import ConfigurationError, CycleError, UnreachableLocationError
from adept_traj.results import PlanningResult
from adept_traj.robot import Robot
from adept_traj.scene import Scene
from adept_traj.testing.cycle_files import HOME, PLACE, cycle_text, write_cycle

distributed = pytest.importorskip("distributed")

#: Three moves in an obstacle-free scene with a tiny budget (8 × 3: certified, 0.1 s each);
#: the slow tier plans them in the paper scene at 16 × 8.
THREE_MOVES = cycle_text(
    "three",
    scene="empty.toml",
    plan={"pop_size": 8, "n_gen": 3, "seed": 1},
    locations={
        "home": {"joints": HOME},
        "pick": {"pose": [0.3, 0.5, 0.55, 0.0], "elbow": "righty"},
        "place": {"joints": PLACE},
    },
    moves=[("home", "pick"), ("pick", "home"), {"from": "home", "to": "place", "seed": 1}],
)


@pytest.fixture(scope="module")
def cycle_file(tmp_path_factory) -> Path:
    return write_cycle(tmp_path_factory.mktemp("cycle"), THREE_MOVES, file="three.toml")


@pytest.fixture(scope="module")
def cycle_run(cycle_file, cluster) -> Path:
    """The three-move cycle planned once by the command on the shared cluster."""
    out = cycle_file.parent / "out"
    code = main(
        [
            "cycle",
            str(cycle_file),
            "--out",
            str(out),
            "--scheduler",
            cluster.scheduler_address,
            "--quiet",
            "--no-plots",
            "--no-playback",
        ]
    )
    assert code == 0
    return out


def _write(tmp_path: Path, text: str) -> Path:
    return write_cycle(tmp_path, text)


# --------------------------------------------------------------------------- the file
def test_locations_resolved_with_the_chosen_elbow(cycle_file):
    cycle = read_cycle_file(cycle_file)
    pick = cycle.locations["pick"]
    assert pick.elbow == "righty"
    pose = Robot.adept_one_xl().tool_pose(pick.joints)
    np.testing.assert_allclose(pose[:3, 3], [0.3, 0.5, 0.55], atol=1e-12)
    assert [m.seed for m in cycle.moves] == [1, 2, 1]  # cycle seed + index, or the override
    assert [m.name for m in cycle.moves] == ["home-pick", "pick-home", "home-place"]


@pytest.mark.parametrize(
    ("edit", "error", "words"),
    [
        (('pose = [0.3, 0.5, 0.55, 0.0]', 'pose = [1.3, 0.5, 0.55, 0.0]'),
         UnreachableLocationError, "field 'location\\[1\\].pose'.*beyond the arm's reach"),
        (('pose = [0.3, 0.5, 0.55, 0.0]', 'pose = [0.3, 0.5, 0.55]'),
         CycleError, "field 'location\\[1\\].pose': must be a list of 4"),
        (('elbow = "righty"', 'elbow = "up"'),
         CycleError, "field 'location\\[1\\].elbow': must be 'lefty' or 'righty'"),
        (('to = "place"', 'to = "shelf"'),
         CycleError, "field 'move\\[2\\].to': must be one of 'home', 'pick', 'place'"),
        (('n_gen = 3', 'n_gen = 0'),
         CycleError, "field 'plan.n_gen': must be an integer in \\[1, 100000\\]"),
        (('joints = [0.1682, 1.3849', 'joints = [3.1682, 1.3849'),
         CycleError, "field 'location\\[0\\].joints'.*joint1.*outside its limits"),
        (("[plan]\n", "[plan]\nspeed = 1\n"), CycleError, "field 'plan.speed': unknown field"),
    ],
)  # fmt: skip
def test_bad_cycle_files_are_refused_naming_file_and_field(tmp_path, edit, error, words):
    path = _write(tmp_path, THREE_MOVES.replace(*edit, 1))
    with pytest.raises(error, match=words) as info:
        read_cycle_file(path)
    assert str(path) in str(info.value)


# --------------------------------------------------------------------------- running
def test_three_move_cycle_is_certified_and_reported(cycle_run):
    summary = json.loads((cycle_run / CYCLE_FILE).read_text())
    assert [m["name"] for m in summary["moves"]] == ["home-pick", "pick-home", "home-place"]
    assert summary["all_certified"]
    assert summary["locations"]["pick"]["elbow"] == "righty"
    total = 0.0
    for m in summary["moves"]:
        result = PlanningResult.load(cycle_run / m["folder"])
        assert result.feasible
        assert result.certificate.certified
        assert m["T"] == result.best_objectives[0]
        total += m["T"]
    assert summary["cycle_time"] == pytest.approx(total)
    assert (cycle_run / "cycle.md").read_text().count("| yes |") == 3


def test_verify_on_dask_prints_what_it_prints_alone(cycle_run, cluster, capsys):
    """``verify CYCLE_DIR --scheduler``: each move certified as a Dask task, the same lines
    as in the command; ``--workers`` on a result folder (not a cycle's) is refused."""
    capsys.readouterr()
    assert main(["verify", str(cycle_run)]) == 0
    alone = capsys.readouterr().out
    assert alone.count(": certified (min") == 3
    assert main(["verify", str(cycle_run), "--scheduler", cluster.scheduler_address]) == 0
    assert capsys.readouterr().out == alone
    assert main(["verify", str(cycle_run / "moves" / "home-pick"), "--workers", "2"]) == 2
    assert "apply to a cycle folder" in capsys.readouterr().err


def test_resume_plans_only_the_missing_moves(cycle_run, cycle_file, cluster, tmp_path):
    out = tmp_path / "out"
    shutil.copytree(cycle_run, out)
    shutil.rmtree(out / MOVES_FOLDER / "pick-home")
    kept = (out / MOVES_FOLDER / "home-pick" / MOVE_FILE).stat().st_mtime_ns
    done: list[str] = []
    cycle = read_cycle_file(cycle_file)
    results = run_cycle(
        cycle, out, scheduler=cluster.scheduler_address, resume=True, progress=done.append
    )
    assert done[-1] == "pick-home"  # the two kept moves are reported first, loaded
    assert sorted(done[:2]) == ["home-pick", "home-place"]
    assert (out / MOVES_FOLDER / "home-pick" / MOVE_FILE).stat().st_mtime_ns == kept
    again = PlanningResult.load(cycle_run / MOVES_FOLDER / "pick-home")
    np.testing.assert_array_equal(results[1].front.x, again.front.x)  # same seed, same front
    with pytest.raises(CycleError, match="holds an earlier run"):
        run_cycle(cycle, out, scheduler=cluster.scheduler_address)


def test_cycle_playback_joins_the_moves_at_rest(cycle_run, cycle_file):
    cycle = read_cycle_file(cycle_file)
    names = [m.name for m in cycle.moves]
    results = [PlanningResult.load(cycle_run / MOVES_FOLDER / n) for n in names]
    robot = Robot.adept_one_xl()
    playback = cycle_playback(results, names, robot=robot, scene=cycle.scene)
    assert np.all(np.diff(playback.frame_numbers) > 0)
    assert np.all(np.diff(playback.times) > 0)
    assert playback.duration == pytest.approx(sum(r.best_objectives[0] for r in results), abs=0.2)
    assert all(o.poses.shape[0] == playback.n_frames for o in playback.objects if o.animated)
    # the robot passes through every location, at rest, in the order of the moves
    at = 0
    for m in cycle.moves:
        for name in (m.start, m.goal):
            there = np.abs(playback.q[at:] - cycle.locations[name].joints).max(axis=1) < 1e-9
            assert there.any(), f"{m.name} does not pass through {name} after frame {at}"
            at += int(np.argmax(there))
    assert at == playback.n_frames - 1
    paths = [o.path for o in playback.objects]
    assert [p for p in paths if p.endswith("/line")] == [
        "tool_path/00-home-pick/line",
        "tool_path/01-pick-home/line",
        "tool_path/02-home-place/line",
    ]


def test_result_does_not_depend_on_the_worker(cycle_run, cycle_file):
    """A move planned in this process equals the one planned on the cluster."""
    task = cycle_tasks(read_cycle_file(cycle_file))[0]
    here = plan_move(task)
    there = PlanningResult.load(cycle_run / MOVES_FOLDER / task.move.name)
    np.testing.assert_array_equal(here.front.x, there.front.x)
    np.testing.assert_array_equal(here.best_x, there.best_x)


@pytest.fixture(scope="module")
def paper_cycle(cluster, tmp_path_factory) -> tuple[Path, list[PlanningResult]]:
    """The three moves in the paper scene at 16 × 8 (about 1.5 s each), planned once on the
    shared cluster: (cycle file, results)."""
    folder = tmp_path_factory.mktemp("paper_cycle")
    text = THREE_MOVES.replace('"empty.toml"', '"paper"').replace("pop_size = 8", "pop_size = 16")
    path = folder / "paper.toml"
    path.write_text(text.replace("n_gen = 3", "n_gen = 8"))
    address = cluster.scheduler_address
    return path, run_cycle(read_cycle_file(path), folder / "out", scheduler=address)


@pytest.mark.slow
def test_paper_scene_cycle_is_certified(paper_cycle):
    _, results = paper_cycle
    assert all(r.certificate.certified for r in results)


@pytest.mark.slow
def test_killing_a_worker_mid_cycle_still_completes(paper_cycle, tmp_path):
    """A worker killed (SIGKILL) while it plans a move: its nanny restarts it, the
    scheduler reschedules the move, and the cycle ends with the same results."""
    path, reference = paper_cycle
    cycle = read_cycle_file(path)
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        pids = client.run(os.getpid)  # worker address -> pid
        killed: list[tuple[int, tuple[str, ...]]] = []

        def kill_busy_worker() -> None:
            deadline = time.monotonic() + 120
            while time.monotonic() < deadline and not killed:
                busy = {w: t for w, t in client.processing().items() if t}
                if busy:
                    worker, tasks = next(iter(busy.items()))
                    os.kill(pids[worker], signal.SIGKILL)
                    killed.append((pids[worker], tuple(tasks)))
                time.sleep(0.02)

        killer = threading.Thread(target=kill_busy_worker)
        killer.start()
        results = run_cycle(cycle, tmp_path / "out", scheduler=cluster.scheduler_address)
        killer.join()
    assert len(killed) == 1
    assert killed[0][1]  # the killed worker was processing a move
    for result, ref in zip(results, reference, strict=True):
        np.testing.assert_array_equal(result.front.x, ref.front.x)
        assert result.certificate.certified


# --------------------------------------------------------------------------- seed studies
@pytest.mark.slow
def test_compare_seeds_produces_statistics_and_plots(cluster, tmp_path):
    out = tmp_path / "study"
    argv = ["compare", "--seeds", "1-3", "--gens", "2", "--pop-nsga2", "6", "--pop-mode", "6"]
    argv += [
        "--rate",
        "100",
        "--out",
        str(out),
        "--scheduler",
        cluster.scheduler_address,
        "--quiet",
    ]
    assert main(argv) == 0
    doc = json.loads((out / STUDY_FILE).read_text())
    assert doc["seeds"] == [1, 2, 3]
    rows = {r["metric"]: r for r in doc["statistics"]}
    assert list(rows) == [m.key for m in METRICS]
    for alg in ALGORITHM_PAIR:
        z1 = [PlanningResult.load(out / RUNS_FOLDER / f"{alg}-seed{s}").best_objectives[0]
              for s in (1, 2, 3)]  # fmt: skip
        assert doc["runs"][alg]["z1"] == z1
        assert rows["z1"][alg]["median"] == sorted(z1)[1]
        assert rows["z1"][alg]["n"] == 3
    assert 0.0 <= rows["z1"]["p"] <= 1.0
    assert (out / BOXPLOT_FIGURE).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "| z1 time [s] |" in (out / "study.md").read_text()


def test_study_statistics_closed_form():
    """NSGA-II 1…5 against MODE 6…10: U = 0, exact two-sided p = 2 / C(10, 5), medians 3
    and 8, IQR 2 (linear quartiles); lower z1 is better and the paper's single run had
    MODE faster, so the study contradicts it."""
    low, high = [1.0, 2.0, 3.0, 4.0, 5.0], [6.0, 7.0, 8.0, 9.0, 10.0]
    metrics = {"nsga2": {m.key: low for m in METRICS}, "mode": {m.key: high for m in METRICS}}
    rows = {r["metric"]: r for r in study_statistics(metrics)}
    z1 = rows["z1"]
    assert z1["U"] == 0.0
    assert z1["p"] == pytest.approx(2.0 / 252.0)
    assert (z1["nsga2"]["median"], z1["nsga2"]["iqr"]) == (3.0, 2.0)
    assert z1["mode"]["median"] == 8.0
    assert z1["better"] == "nsga2"
    assert z1["verdict"] == "contradicted"
    assert rows["RNI"]["better"] == "mode"  # higher is better
    assert rows["RNI"]["verdict"] == "contradicted"
    assert rows["SSM"]["verdict"] == "confirmed"  # the paper's SSM favoured NSGA-II
    assert rows["T_run"]["verdict"] == "nsga2 better (paper: no comparison)"
    assert rows["N_eval"]["better"] is None  # fixed by the budget, not a quality
    assert rows["N_eval"]["verdict"] == "not a quality measure"


def test_study_report_of_given_values(tmp_path):
    """The report of the closed-form case: every metric a row, the box plots a PNG."""
    low, high = [1.0, 2.0, None], [6.0, 7.0, 8.0]
    metrics = {"nsga2": {m.key: low for m in METRICS}, "mode": {m.key: high for m in METRICS}}
    rows = study_statistics(metrics)
    text = write_study_report(rows, metrics, (1, 2, 3), tmp_path, figure=True)
    assert text.count("| 1.5 [1.25, 1.75] | 7 [6.5, 7.5] |") == len(METRICS)
    assert json.loads((tmp_path / STUDY_FILE).read_text())["runs"] == metrics
    assert (tmp_path / BOXPLOT_FIGURE).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("text", "seeds"), [("1-3", (1, 2, 3)), ("4,1", (4, 1)), ("1-2,7", (1, 2, 7)), ("0", (0,))]
)
def test_parse_seeds(text, seeds):
    assert parse_seeds(text) == seeds


@pytest.mark.parametrize("text", ["", "3-1", "a", "1,1", "-2", "1-20000"])
def test_parse_seeds_refuses(text):
    with pytest.raises(ConfigurationError, match="--seeds"):
        parse_seeds(text)


@pytest.mark.parametrize("name", ["paper", "detour"])
def test_a_shipped_scene_by_name(tmp_path, name):
    """``scene`` names a shipped scene as ``--scene`` does, before any file of that name."""
    (tmp_path / name).write_text("not a scene file")
    path = tmp_path / "cycle.toml"
    path.write_text(THREE_MOVES.replace('"empty.toml"', f'"{name}"'))
    assert read_cycle_file(path).scene == Scene.shipped(name)


#: A Dask worker preload whose teardown keeps the worker process alive for 5 s after it
#: is asked to close (as a loaded machine does: measured 4.5–6.5 s with 12 busy processes
#: on the workers' core), then leaves a mark that it was not killed.
SLOW_EXIT = """\
import os
import time


def dask_teardown(worker):
    time.sleep(5.0)
    with open(os.environ["ADEPT_TRAJ_TEST_MARK"], "a") as f:
        f.write("exited by itself\\n")
"""


@pytest.mark.slow  # a worker process that takes 5 s to exit, and a whole command: ~15 s
def test_the_command_closes_dask_without_killing_a_slow_worker(tmp_path: Path) -> None:
    """``adept-traj cycle`` stops its local cluster cleanly: a worker process that needs
    more than Dask's 4 s to exit is waited for (:data:`~adept_traj.cycle.CLOSE_TIMEOUT`),
    not killed with "Worker process still alive after 4.0 seconds, killing" on stderr
    (the warning the command printed before on a loaded machine)."""
    import subprocess
    import sys

    path = write_cycle(tmp_path, THREE_MOVES)
    preload, mark = tmp_path / "slow_exit.py", tmp_path / "mark.txt"
    preload.write_text(SLOW_EXIT)
    env = {
        **os.environ,
        "DASK_DISTRIBUTED__WORKER__PRELOAD": json.dumps([str(preload)]),
        "ADEPT_TRAJ_TEST_MARK": str(mark),
        "PYTHONPATH": os.pathsep.join(
            [str(Path(__file__).parents[2]), *filter(None, [os.environ.get("PYTHONPATH")])]
        ),
    }
    argv = [sys.executable, "-m", "adept_traj.cli", "cycle", str(path), "--out"]
    argv += [str(tmp_path / "out"), "--workers", "1", "--quiet", "--no-plots", "--no-playback"]
    run = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    assert "still alive" not in run.stderr, run.stderr[-2000:]
    assert "killing" not in run.stderr.lower(), run.stderr[-2000:]
    assert mark.read_text() == "exited by itself\n"  # the teardown ran to its end
