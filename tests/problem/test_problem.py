"""TrajectoryProblem: batched == per-sample reference, the paper scene's obstacles matter."""

from __future__ import annotations

import gc
import os
import signal
import time
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np
import pytest

from adept_traj import Robot, Scene
from adept_traj.collision import CollisionChecker
from adept_traj.errors import (
    AdeptTrajError,
    ConfigurationError,
    InputShapeError,
    InvalidInputError,
    JointLimitError,
    RobotModelError,
)
from adept_traj.problem import Evaluation, ParallelEvaluator, TrajectoryProblem
from adept_traj.process_pool import children
from adept_traj.testing.paper_moves import lift_then_lower
from adept_traj.testing.reference import evaluate_reference


@pytest.fixture(scope="module")
def robot() -> Robot:
    return Robot.adept_one_xl()


@pytest.fixture(scope="module")
def scene() -> Scene:
    return Scene.paper()


def dense_check(problem: TrajectoryProblem, x: np.ndarray, rate: float = 1000.0) -> dict:
    """Independent verification at ``rate`` Hz: every pair by coal, torques by RNEA."""
    T = float(x[0])
    n = int(np.ceil(T * rate)) + 1
    s = np.linspace(0.0, 1.0, n)
    smp = problem.trajectory.sample(x, s)
    checker = CollisionChecker(problem.robot, problem.scene)
    pairs = checker.distances(smp.q[None], smp.t[None], exact=True)
    tau = problem.robot.inverse_dynamics(smp.q, smp.qd, smp.qdd)
    lim = problem.robot.limits
    return {
        "per_obstacle": pairs.per_obstacle[0],
        "torque_ratio": np.abs(tau).max(0) / lim.torque,
        "q_in_limits": bool(np.all((smp.q >= lim.lower - 1e-12) & (smp.q <= lim.upper + 1e-12))),
        "qd_ratio": np.abs(smp.qd).max(0) / lim.velocity,
        "qdd_ratio": np.abs(smp.qdd).max(0) / lim.acceleration,
        "qddd_ratio": np.abs(smp.qddd).max(0) / lim.jerk,
    }


def test_problem_shape(problem: TrajectoryProblem) -> None:
    assert (problem.n_var, problem.n_obj, problem.n_ieq_constr) == (65, 6, 21)
    assert problem.xl[0] == pytest.approx(problem.lower_bound.T_min)
    np.testing.assert_allclose(problem.xl[33:49], 0.0)  # d3 control points: inside the stroke
    np.testing.assert_allclose(problem.xu[33:49], 0.203)
    assert problem.constraint_names[0] == "q[joint1]"
    assert problem.constraint_names[-1] == "distance"
    assert len(problem.constraint_names) == 21


def test_batched_equals_reference(problem: TrajectoryProblem) -> None:
    rng = np.random.default_rng(12)
    x = problem.xl + (problem.xu - problem.xl) * rng.uniform(size=(3, problem.n_var))
    x = np.vstack([x, problem.trajectory.straight_line(1.3), lift_then_lower(problem)])
    batched = problem.evaluate_batch(x)
    reference = evaluate_reference(problem, x)
    np.testing.assert_allclose(batched.objectives, reference.objectives, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(batched.constraints, reference.constraints, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(batched.min_distance, reference.min_distance, rtol=0, atol=1e-9)
    again = problem.evaluate_batch(x)
    np.testing.assert_array_equal(again.objectives, batched.objectives)  # deterministic


@pytest.mark.parametrize("variant", ["paper-sphere", "paper-ellipsoid"])
def test_paper_penalty_variant_equals_reference(robot: Robot, scene: Scene, variant: str) -> None:
    problem = TrajectoryProblem(robot, scene, scene.start, scene.goal, z3=variant)
    x = np.vstack([problem.trajectory.straight_line(1.4), lift_then_lower(problem)])
    batched = problem.evaluate_batch(x)
    reference = evaluate_reference(problem, x)
    np.testing.assert_allclose(batched.objectives, reference.objectives, rtol=1e-9, atol=1e-12)
    assert batched.objectives[0, 2] > 0  # the straight move enters cube 1's sphere


def test_straight_joint_space_move_collides(problem: TrajectoryProblem) -> None:
    for T in (1.1, 1.5, 2.0):
        x = problem.trajectory.straight_line(T)
        ev = problem.evaluate_batch(x)
        assert not ev.feasible
        assert ev.constraints[-1] > 0
        dense = dense_check(problem, x)
        assert dense["per_obstacle"][0] < 0.0  # penetrates cube 1
        assert ev.min_distance[0] == pytest.approx(dense["per_obstacle"][0], abs=2e-3)


def test_a_collision_free_move_exists(problem: TrajectoryProblem) -> None:
    x = lift_then_lower(problem)
    ev = problem.evaluate_batch(x)
    assert ev.feasible, dict(zip(problem.constraint_names, ev.constraints))
    dense = dense_check(problem, x)
    margin = problem.settings.margin
    assert np.all(dense["per_obstacle"] >= margin), dense["per_obstacle"]
    assert dense["q_in_limits"]
    for key in ("torque_ratio", "qd_ratio", "qdd_ratio", "qddd_ratio"):
        assert np.all(dense[key] <= 1.0), (key, dense[key])
    # The pendulum matters: the same path 0.1 s slower hits the rod.
    slower = problem.evaluate_batch(lift_then_lower(problem, T=2.0))
    assert slower.min_distance[2] < margin


def test_search_buffer_tightens_only_the_distance_constraint(
    robot: Robot, scene: Scene, problem: TrajectoryProblem
) -> None:
    """The optimiser asks margin + search_buffer at its samples: a move clearing the margin
    by less than the buffer becomes infeasible; objectives and other constraints stay."""
    x = lift_then_lower(problem)
    unbuffered = TrajectoryProblem(robot, scene, scene.start, scene.goal, search_buffer=0.0)
    plain = unbuffered.evaluate_batch(x)
    clearance = float(plain.min_distance.min()) - problem.settings.margin  # [m] > 0
    buffer = clearance + 1e-3
    buffered = TrajectoryProblem(robot, scene, scene.start, scene.goal, search_buffer=buffer)
    ev = buffered.evaluate_batch(x)
    assert plain.feasible
    assert not ev.feasible
    influence = problem.settings.influence
    # Closed form: g_d = (m + b − min(d_min, δ)) / δ, with d_min from the unbuffered problem.
    assert ev.constraints[-1] == pytest.approx(
        (problem.settings.margin + buffer - min(plain.min_distance.min(), influence)) / influence
    )
    assert ev.constraints[-1] - plain.constraints[-1] == pytest.approx(buffer / influence)
    np.testing.assert_array_equal(ev.constraints[:-1], plain.constraints[:-1])
    np.testing.assert_array_equal(ev.objectives, plain.objectives)
    reference = evaluate_reference(buffered, x)
    np.testing.assert_allclose(ev.constraints, reference.constraints, rtol=1e-9, atol=1e-12)


def test_search_buffer_range(robot: Robot, scene: Scene) -> None:
    for bad in (-1e-3, 0.041):  # margin 0.01, influence 0.05: 0 ≤ buffer ≤ 0.04 m
        with pytest.raises(ConfigurationError, match=r"search_buffer ≤ influence − margin"):
            TrajectoryProblem(robot, scene, scene.start, scene.goal, search_buffer=bad)


def test_pymoo_interface_negates_z4(problem: TrajectoryProblem) -> None:
    x = np.vstack([problem.trajectory.straight_line(1.3), lift_then_lower(problem)])
    out = problem.evaluate(x, return_as_dictionary=True)
    ev = problem.evaluate_batch(x)
    np.testing.assert_allclose(out["F"][:, 3], -ev.objectives[:, 3])
    np.testing.assert_allclose(out["F"][:, [0, 1, 2, 4, 5]], ev.objectives[:, [0, 1, 2, 4, 5]])
    np.testing.assert_allclose(out["G"], ev.constraints)


def test_single_vector_and_objective_values(problem: TrajectoryProblem) -> None:
    x = lift_then_lower(problem)
    ev = problem.evaluate_batch(x)
    assert ev.objectives.shape == (6,)
    assert ev.objectives[0] == pytest.approx(2.1)
    integ = problem.trajectory.integrals(x)
    assert ev.objectives[4] == pytest.approx(float(integ.z5))
    assert ev.objectives[5] == pytest.approx(float(integ.z6))
    assert 0 < ev.objectives[3] <= 0.425 * 0.375  # z4 ≤ a1·a2
    assert ev.objectives[2] >= 0.0


def test_bad_input(robot: Robot, scene: Scene) -> None:
    with pytest.raises(JointLimitError, match=r"start: joint 'joint3' = 0\.3 m"):
        TrajectoryProblem(robot, scene, [0.1, 1.0, 0.3, 0.0], scene.goal)
    with pytest.raises(ConfigurationError, match="z3 must be"):
        TrajectoryProblem(robot, scene, scene.start, scene.goal, z3="spheres")
    with pytest.raises(ConfigurationError, match="margin ≤ influence"):
        TrajectoryProblem(robot, scene, scene.start, scene.goal, margin=0.1, influence=0.05)
    with pytest.raises(ConfigurationError, match="unknown problem setting"):
        TrajectoryProblem(robot, scene, scene.start, scene.goal, knots=12)
    with pytest.raises(ConfigurationError, match="t_bounds must"):
        TrajectoryProblem(robot, scene, scene.start, scene.goal, t_bounds=(1.0,))
    with pytest.raises(ConfigurationError, match="nodes_per_segment must be an integer"):
        TrajectoryProblem(robot, scene, scene.start, scene.goal, nodes_per_segment="x")
    with pytest.raises(ConfigurationError, match="nothing to plan"):
        TrajectoryProblem(robot, scene, scene.start, scene.start)
    bare = Robot.from_urdf(robot.urdf_path)  # no parameter file: no task rows
    with pytest.raises(RobotModelError, match="no task_rows"):
        TrajectoryProblem(bare, scene, scene.start, scene.goal)
    problem = TrajectoryProblem(robot, scene, scene.start, scene.goal)
    with pytest.raises(InputShapeError, match=r"x must have shape \(\.\.\., 65\)"):
        problem.evaluate_batch(np.zeros(64))


def test_parallel_workers_equal_serial(robot: Robot, scene: Scene, problem) -> None:
    parallel = TrajectoryProblem(robot, scene, scene.start, scene.goal, workers=2)
    try:
        rng = np.random.default_rng(30)
        x = problem.xl + (problem.xu - problem.xl) * rng.uniform(size=(40, problem.n_var))
        serial = problem.evaluate_batch(x)
        both = parallel.evaluate_batch(x)
        np.testing.assert_array_equal(both.objectives, serial.objectives)
        np.testing.assert_array_equal(both.constraints, serial.constraints)
        np.testing.assert_array_equal(both.min_distance, serial.min_distance)
        assert both.n_narrow == serial.n_narrow
    finally:
        parallel.close()
    with pytest.raises(ConfigurationError, match=r"workers must be an integer in \[1, ∞\]; got 0"):
        TrajectoryProblem(robot, scene, scene.start, scene.goal, workers=0)


def _new_children(before: set) -> list:
    return [pid for pid in children() if pid not in before]


def _running(pid: int) -> bool:
    """The process exists and has not exited (a zombie has exited), read from /proc: the
    pool's own thread may reap a worker while the test waits, so Process.is_alive can race."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return False
    return stat.rsplit(")", 1)[1].split()[0] not in ("Z", "X")


def _stopped(pids: list, timeout: float = 30.0) -> bool:
    deadline = time.monotonic() + timeout
    while any(_running(pid) for pid in pids):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


def test_problem_owns_and_stops_its_workers(robot: Robot, scene: Scene, problem) -> None:
    """close(), a with block and garbage collection each stop the workers (workers=2: the
    main process and one forked worker); after close() a new one starts and still gives
    the serial results."""
    rng = np.random.default_rng(31)
    x = problem.xl + (problem.xu - problem.xl) * rng.uniform(size=(20, problem.n_var))
    serial = problem.evaluate_batch(x)
    before = set(children())
    with TrajectoryProblem(robot, scene, scene.start, scene.goal, workers=2) as parallel:
        parallel.evaluate_batch(x)
        first = _new_children(before)
        assert len(first) == 1
        parallel.close()
        assert _stopped(first)
        again = parallel.evaluate_batch(x)  # a new pool
        np.testing.assert_array_equal(again.objectives, serial.objectives)
        second = _new_children(before)
        assert len(second) == 1
    assert _stopped(second)  # the with block closed it

    collected = TrajectoryProblem(robot, scene, scene.start, scene.goal, workers=2)
    collected.evaluate_batch(x)
    third = _new_children(before)
    assert len(third) == 1
    del collected
    gc.collect()
    assert _stopped(third)  # garbage collection stopped the pool: nothing kept the problem


def _pid_rows(x: np.ndarray) -> Evaluation:
    """Objectives (k, 2): the row's first variable and the evaluating process id."""
    k = len(x)
    return Evaluation(
        objectives=np.column_stack([x[:, 0], np.full(k, float(os.getpid()))]),
        constraints=np.zeros((k, 1)),
        min_distance=np.zeros((k, 0)),
        n_narrow=k,
    )


def test_parallel_evaluator_hands_the_function_to_forked_workers() -> None:
    """The function reaches the workers once, when they are forked: a closure (which pickle
    refuses) works; rows come back in order, the last chunk computed in the main process
    and each other chunk in its own worker process."""
    offset = 10.0
    evaluate = lambda x: _pid_rows(x + offset)  # noqa: E731 (a closure cannot be pickled)
    x = np.arange(30.0).reshape(10, 3)
    with ParallelEvaluator(evaluate, workers=3, n_var=3) as evaluator:
        ev = evaluator.evaluate(x)
        assert evaluator.running
    assert not evaluator.running
    np.testing.assert_array_equal(ev.objectives[:, 0], x[:, 0] + offset)
    pids = ev.objectives[:, 1]
    chunks = [pids[:4], pids[4:7], pids[7:]]  # np.array_split(10 rows, 3)
    assert [len(set(c)) for c in chunks] == [1, 1, 1]
    assert len({c[0] for c in chunks}) == 3
    assert chunks[2][0] == os.getpid()  # the main process evaluates the last chunk
    assert ev.n_narrow == 10
    with pytest.raises(ConfigurationError, match="closed"):
        evaluator.evaluate(x)
    with pytest.raises(ConfigurationError, match=r"workers must be an integer in \[2, ∞\]"):
        ParallelEvaluator(evaluate, workers=1, n_var=3)
    with ParallelEvaluator(evaluate, workers=2, n_var=3) as evaluator:
        with pytest.raises(InputShapeError, match=r"pop ≥ 1; got \(0, 3\)"):
            evaluator.evaluate(x[:0])
        with pytest.raises(InputShapeError, match=r"\(\.\.\., 3\)"):
            evaluator.evaluate(x[:, :2])


def test_a_population_smaller_than_the_workers_is_cut_into_fewer_chunks() -> None:
    """More workers than rows (``--workers`` defaults to the cores: a many-core machine and
    a small population): one row per process, the last workers idle, the rows in order."""
    x = np.arange(6.0).reshape(3, 2)
    with ParallelEvaluator(_pid_rows, workers=5, n_var=2) as evaluator:
        ev = evaluator.evaluate(x)
        one = evaluator.evaluate(x[:1])
    np.testing.assert_array_equal(ev.objectives[:, 0], x[:, 0])
    assert len(set(ev.objectives[:, 1])) == 3
    assert ev.objectives[-1, 1] == os.getpid()
    np.testing.assert_array_equal(one.objectives[:, 0], x[:1, 0])
    assert one.objectives[0, 1] == os.getpid()


@pytest.mark.slow  # ≥ 5 s (the default tier measured 192 s after the merges)
def test_a_worker_killed_between_populations_is_a_broken_pool() -> None:
    """A worker that died while idle (its pipe broken) is reported as a broken pool, not
    as a bare ``BrokenPipeError``; the next population is evaluated by new workers."""
    x = np.arange(8.0)[:, None] * np.ones((1, 2))
    before = _worker_pids()
    with ParallelEvaluator(_pid_rows, workers=2, n_var=2) as evaluator:
        evaluator.evaluate(x)
        (worker,) = _worker_pids() - before
        os.kill(worker, signal.SIGKILL)
        deadline = time.monotonic() + 5.0
        while worker in _worker_pids() and time.monotonic() < deadline:
            time.sleep(0.01)
        with pytest.raises(BrokenProcessPool, match="ended abruptly"):
            evaluator.evaluate(x)
        np.testing.assert_array_equal(evaluator.evaluate(x).objectives[:, 0], x[:, 0])


def test_workers_stop_although_another_fork_holds_their_pipes() -> None:
    """A process forked from the owner while the workers live (here by ``os.fork``, not as
    a worker) does not keep the workers: ``close`` stops them and returns at once."""
    x = np.arange(8.0)[:, None] * np.ones((1, 2))
    evaluator = ParallelEvaluator(_pid_rows, workers=2, n_var=2)
    evaluator.evaluate(x)
    read, write = os.pipe()
    holder = os.fork()
    if holder == 0:  # holds every inherited descriptor until the test lets it go
        os.close(write)
        os.read(read, 1)
        os._exit(0)
    os.close(read)
    try:
        start = time.monotonic()
        evaluator.close()
        assert time.monotonic() - start < 4.0
    finally:
        os.close(write)
        os.waitpid(holder, 0)


# ParallelEvaluator's failures: a worker's exception, a killed worker, Ctrl-C in the main
# process' own chunk. Each is raised in the main process, the workers are stopped, and the
# next population is evaluated by new workers.

#: First-variable values that make the evaluation function fail, by what they do.
_RAISE, _KILL, _INTERRUPT, _UNPICKLABLE = -1.0, -2.0, -3.0, -4.0


class _Unpicklable(Exception):
    def __init__(self, a: int, b: int) -> None:  # pickle calls __init__ with one argument
        super().__init__(f"{a} and {b}")


def _failing(main_pid: int):
    """An evaluation function whose chunk's first value says how it fails, and in which
    process (worker or main): rows are (x0, the process id)."""

    def evaluate(x: np.ndarray) -> Evaluation:
        in_worker = os.getpid() != main_pid
        if x[0, 0] == _RAISE and in_worker:
            raise InvalidInputError("bad chunk in the worker")
        if x[0, 0] == _UNPICKLABLE and in_worker:
            raise _Unpicklable(1, 2)
        if x[0, 0] == _KILL and in_worker:
            os.kill(os.getpid(), signal.SIGKILL)
        if x[-1, 0] == _INTERRUPT and not in_worker:
            raise KeyboardInterrupt
        return _pid_rows(x)

    return evaluate


def _worker_pids() -> set:
    return set(children())


@pytest.mark.parametrize(
    ("first", "error", "match"),
    [
        (_RAISE, InvalidInputError, "bad chunk in the worker"),
        (_UNPICKLABLE, AdeptTrajError, "_Unpicklable: 1 and 2"),
        (_KILL, BrokenProcessPool, "ended abruptly"),
    ],
)
def test_a_failed_worker_is_raised_here_and_new_workers_follow(first, error, match) -> None:
    x = np.arange(8.0)[:, None] * np.ones((1, 2))
    before = _worker_pids()
    with ParallelEvaluator(_failing(os.getpid()), workers=2, n_var=2) as evaluator:
        good = evaluator.evaluate(x)
        old = _worker_pids() - before
        bad = x.copy()
        bad[0, 0] = first  # the worker's chunk (the main process takes the last one)
        with pytest.raises(error, match=match):
            evaluator.evaluate(bad)
        assert not (old & _worker_pids())  # the old worker is stopped
        again = evaluator.evaluate(x)  # by a new worker
        assert (_worker_pids() - before) - old
    np.testing.assert_array_equal(again.objectives[:, 0], good.objectives[:, 0])
    assert again.objectives[0, 1] != good.objectives[0, 1]


def test_a_worker_exception_carries_the_worker_traceback() -> None:
    x = np.arange(8.0)[:, None] * np.ones((1, 2))
    x[0, 0] = _RAISE
    evaluator = ParallelEvaluator(_failing(os.getpid()), workers=2, n_var=2)
    with evaluator, pytest.raises(InvalidInputError) as raised:
        evaluator.evaluate(x)
    (note,) = raised.value.__notes__
    assert note.startswith("raised in an evaluation worker process:")
    assert 'raise InvalidInputError("bad chunk in the worker")' in note


def test_ctrl_c_in_the_main_process_stops_the_busy_workers() -> None:
    x = np.arange(8.0)[:, None] * np.ones((1, 2))
    before = _worker_pids()
    with ParallelEvaluator(_failing(os.getpid()), workers=3, n_var=2) as evaluator:
        bad = x.copy()
        bad[-1, 0] = _INTERRUPT
        with pytest.raises(KeyboardInterrupt):
            evaluator.evaluate(bad)
        assert _worker_pids() == before  # terminated while they evaluated, and waited for
        np.testing.assert_array_equal(evaluator.evaluate(x).objectives[:, 0], x[:, 0])


def test_a_forked_copy_of_the_owner_evaluates_in_itself() -> None:
    """A process forked from the evaluator's owner after its workers started (e.g. a task
    process certifying front members) must not use the owner's pipes: it evaluates the
    whole population itself, and the owner's workers still serve the owner."""
    x = np.arange(12.0)[:, None] * np.ones((1, 2))
    with ParallelEvaluator(_pid_rows, workers=2, n_var=2) as evaluator:
        evaluator.evaluate(x)  # the owner's worker is running now
        read, write = os.pipe()
        child = os.fork()
        if child == 0:  # the forked copy: report whether every row was its own
            try:
                rows = evaluator.evaluate(x).objectives
                ok = bool(np.all(rows[:, 1] == os.getpid()) and np.all(rows[:, 0] == x[:, 0]))
                os.write(write, b"1" if ok else b"0")
            finally:
                os._exit(0)
        os.close(write)
        answer = os.read(read, 1)
        os.close(read)
        os.waitpid(child, 0)
        again = evaluator.evaluate(x).objectives
    assert answer == b"1"
    np.testing.assert_array_equal(again[:, 0], x[:, 0])
    assert len(set(again[:, 1])) == 2  # the owner's worker and the owner itself
