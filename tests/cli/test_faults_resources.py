"""Hostile sizes are refused before the work, with the library's error naming the option,
the value, the estimate and the limit (issue 13, "bounded resources"); the sampler and the
repair work in blocks. Nothing here allocates the amounts it refuses."""

from __future__ import annotations

import os
import time
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from adept_traj import memory
from adept_traj.certification import certificate_bytes, certify
from adept_traj.cli.app import main
from adept_traj.cli.robot import samples_bytes
from adept_traj.errors import (
    InvalidInputError,
    ResourceLimitError,
    ResultFormatError,
    SceneError,
)
from adept_traj.files import (
    MAX_FILE_BYTES,
    MAX_NESTING,
    check_nesting,
    parse_json,
    parse_toml,
    read_bytes_bounded,
    read_toml,
)
from adept_traj.optimise import (
    KinematicTimeRepair,
    RampSampling,
    check_population_memory,
    kinematic_time,
    plan,
    population_bytes,
)
from adept_traj.optimise.operators import repair as repair_module
from adept_traj.optimise.search import sampling as sampling_module
from adept_traj.robot import Robot
from adept_traj.scene import MAX_OBSTACLES, Obstacle, Scene, Sphere

RESULT_V1 = Path(__file__).parents[1] / "data" / "result_v1"
GiB = 2**30


# ============================================================================ the budget
def test_budget_is_the_ceiling_or_the_available_memory(monkeypatch: pytest.MonkeyPatch) -> None:
    assert memory.available_memory() > 0
    assert memory.memory_budget() <= memory.MAX_MEMORY_BYTES
    monkeypatch.setattr(memory, "available_memory", lambda: 1 * GiB)
    assert memory.memory_budget() == 1 * GiB
    pattern = r"--pop = 15000 .*1\.3 GiB.*available on this machine, 1\.0 GiB"
    with pytest.raises(ResourceLimitError, match=pattern):
        check_population_memory(15000, options=("--pop", "--gens"))  # ≈ 1.3 GiB


def test_check_memory_names_option_value_estimate_and_limit() -> None:
    with pytest.raises(ResourceLimitError) as info:
        memory.check_memory(3 * GiB, "--opt", 42, budget=2 * GiB)
    assert "--opt = 42" in str(info.value)
    assert "3.0 GiB" in str(info.value)
    assert "2.0 GiB" in str(info.value)
    assert isinstance(info.value, InvalidInputError)
    assert memory.check_memory(GiB, "--opt", 1, budget=2 * GiB) == GiB


# ============================================================================ population
def test_population_estimate_formula() -> None:
    # 170 MiB + 20 kB·N + 4 B·N² + 300 B·N·G, written out independently.
    assert population_bytes(1000, 10) == 178257920 + 20_000_000 + 4_000_000 + 3_000_000
    assert population_bytes(100_000) > memory.MAX_MEMORY_BYTES  # 39 GiB


def test_plan_refuses_a_huge_population_before_sampling(problem) -> None:
    t0 = time.perf_counter()
    with pytest.raises(ResourceLimitError, match=r"pop_size = 100000 would need about"):
        plan(problem, "nsga2", seed=1, pop_size=100_000, n_gen=1)
    assert time.perf_counter() - t0 < 5.0


#: Oversized options of compare and what the refusal names (plan has one --pop).
OVERSIZED = [
    (["--pop-nsga2", "100000"], "--pop-nsga2 = 100000"),
    (["--pop-mode", "100000"], "--pop-mode = 100000"),
    (["--gens", "1000000000000"], "--gens = 1000000000000"),
    (["--rate", "1e9"], "--rate = 1e+09 Hz"),
]


@pytest.mark.parametrize(("argv", "option"), OVERSIZED)
def test_plan_refuses_before_running(argv, option, tmp_path, capsys) -> None:
    """The same limits for plan (--pop for its one population), before run.json is written."""
    argv = ["--pop" if a.startswith("--pop-") else a for a in argv]
    option = option.replace("--pop-nsga2", "--pop").replace("--pop-mode", "--pop")
    out = tmp_path / "run"
    assert main(["plan", *argv, "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert option in err
    assert "would need about" in err
    assert not out.exists()


@pytest.mark.parametrize(("argv", "option"), OVERSIZED)
def test_compare_refuses_before_running(argv, option, tmp_path, capsys) -> None:
    out = tmp_path / "cmp"
    assert main(["compare", *argv, "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert option in err
    assert "would need about" in err
    assert "ResourceLimit" not in err
    assert not out.exists()  # nothing was run, nothing written


# ============================================================================ certificate
def test_certify_refuses_a_rate_beyond_the_budget(problem) -> None:
    x = problem.trajectory.straight_line(1.0)
    t0 = time.perf_counter()
    with pytest.raises(ResourceLimitError, match=r"rate_hz = 1e\+09 Hz \(T = 1 s\)"):
        certify(problem, x, rate_hz=1e9)
    assert time.perf_counter() - t0 < 2.0


@pytest.mark.slow  # default-tier time (≤ 3 min): the slow tier runs it in CI (.ci/run)
def test_certificate_estimate_bounds_the_measured_peak(problem) -> None:
    x = problem.trajectory.straight_line(1.0)
    certify(problem, x, rate_hz=200.0)  # warm caches outside the measurement
    tracemalloc.start()
    try:
        certify(problem, x, rate_hz=3000.0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    estimate = certificate_bytes(problem, 1.0, 3000.0)
    assert peak <= estimate <= 3 * peak


def test_verify_refuses_a_huge_rate(capsys) -> None:
    assert main(["verify", str(RESULT_V1), "--rate", "1e9"]) == 2
    err = capsys.readouterr().err
    assert "--rate = 1e+09 Hz" in err
    assert "would need about" in err


# ============================================================================ robot demo
def test_robot_refuses_a_huge_number_of_samples(capsys) -> None:
    assert main(["robot", "--samples", "1000000000"]) == 2
    err = capsys.readouterr().err
    assert "--samples = 1000000000 would need about" in err


def test_robot_samples_estimate_bounds_the_measured_peak() -> None:
    robot = Robot.adept_one_xl()
    n = 20_000
    q = np.zeros((n, robot.nq))
    tracemalloc.start()
    try:
        robot.inverse_dynamics(q, q, q)
        robot.manipulability(q)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak <= samples_bytes(n, robot.nq)


# ============================================================================ blocks
def test_sampler_in_blocks_is_bit_identical_and_bounded(problem, monkeypatch) -> None:
    whole = RampSampling()._do(problem, 37, random_state=np.random.default_rng(5))
    monkeypatch.setattr(sampling_module, "_BLOCK_CURVES", 4)  # one individual per block
    monkeypatch.setattr(repair_module, "_BLOCK_ROWS", 3)
    blocked = RampSampling()._do(problem, 37, random_state=np.random.default_rng(5))
    assert np.array_equal(whole, blocked)
    monkeypatch.undo()
    tracemalloc.start()
    try:
        RampSampling()._do(problem, 1000, random_state=np.random.default_rng(0))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 80 * 2**20  # 306 MB unblocked: (1000, 4, 2001) arrays


def test_repair_in_blocks_is_bit_identical_and_bounded(problem, monkeypatch) -> None:
    x = RampSampling()._do(problem, 41, random_state=np.random.default_rng(6))
    whole = kinematic_time(problem, x)
    monkeypatch.setattr(repair_module, "_BLOCK_ROWS", 4)
    assert np.array_equal(kinematic_time(problem, x), whole)
    repaired = KinematicTimeRepair(snap=0.0)._do(problem, x)
    monkeypatch.undo()
    assert np.array_equal(KinematicTimeRepair(snap=0.0)._do(problem, x), repaired)
    big = np.repeat(x, 100, axis=0)  # 4 100 candidates
    tracemalloc.start()
    try:
        kinematic_time(problem, big)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 40 * 2**20  # about 80 MB unblocked


# ============================================================================ files
def test_dev_zero_is_refused_quickly() -> None:
    t0 = time.perf_counter()
    pattern = r"/dev/zero: scene file larger than the limit of 67108864"
    with pytest.raises(SceneError, match=pattern):
        read_bytes_bounded("/dev/zero", SceneError, what="scene file")
    assert time.perf_counter() - t0 < 5.0


def test_a_huge_file_is_refused_before_reading(tmp_path: Path) -> None:
    huge = tmp_path / "huge.toml"
    with open(huge, "wb") as f:
        f.truncate(10 * GiB)  # sparse: no disk space used
    t0 = time.perf_counter()
    with pytest.raises(SceneError, match="larger than the limit"):
        Scene.from_file(huge)
    assert time.perf_counter() - t0 < 1.0
    small = tmp_path / "small.bin"
    small.write_bytes(b"x" * 100)
    with pytest.raises(SceneError, match="larger than the limit of 99 bytes"):
        read_bytes_bounded(small, SceneError, limit=99)
    assert read_bytes_bounded(small, SceneError, limit=100) == b"x" * 100


def test_limits_are_documented_values() -> None:
    assert MAX_FILE_BYTES == 64 * 2**20
    assert MAX_NESTING == 64
    assert MAX_OBSTACLES == 10_000


@pytest.mark.parametrize("depth", [65, 100_000])
def test_deep_json_is_refused_without_recursion_error(depth: int) -> None:
    raw = b"[" * depth + b"]" * depth
    with pytest.raises(ResultFormatError, match=rf"nested {depth} levels deep.*limit of 64"):
        parse_json(raw, "result.json", lambda m: ResultFormatError("result.json", None, m))


def test_json_nesting_counts_structure_only() -> None:
    text = '{"a": [1, {"b": "[[[[{{{{\\"[[["}], "c": []}'
    assert check_nesting(text, "s", SceneError) == 3
    deep = "[" * 64 + "]" * 64
    assert parse_json(deep.encode(), "s", SceneError) == eval(deep)


@pytest.mark.parametrize("text", ['{"a": 1e400}', '{"a": -1e999}', '{"a": NaN}', "[Infinity]"])
def test_non_finite_json_numbers_are_refused(text: str) -> None:
    with pytest.raises(SceneError, match=r"not finite|not a JSON number"):
        parse_json(text.encode(), "f.json", SceneError)


def test_invalid_json_names_the_source() -> None:
    with pytest.raises(SceneError, match=r"f\.json: not valid JSON"):
        parse_json(b"{", "f.json", SceneError)
    with pytest.raises(SceneError, match=r"f\.json: not UTF-8"):
        parse_json(b'"\xff"', "f.json", SceneError)


@pytest.mark.parametrize(
    "text",
    [
        "a = " + "[" * 100_000 + "]" * 100_000,
        "a = " + "{b = " * 1000 + "1" + "}" * 1000,
        "a" + ".a" * 100 + " = 1",
        "[" + ".".join(["t"] * 100) + "]\nx = 1",
    ],
    ids=["arrays", "inline-tables", "dotted-keys", "table-header"],
)
def test_deep_toml_is_refused_without_recursion_error(text: str, tmp_path: Path) -> None:
    path = tmp_path / "deep.toml"
    path.write_text(text)
    with pytest.raises(SceneError, match=r"levels deep|MAX_NESTING"):
        read_toml(path, SceneError)
    with pytest.raises(SceneError, match=r"levels deep|MAX_NESTING"):
        Scene.from_file(path)


def test_toml_nesting_ignores_strings_and_comments() -> None:
    text = (
        'a = [[1], "[[[["]  # [[[[\n[t]\nb = \'\'\'[[[\'\'\'\nc = """[[[\n\\"""[["""\nd = \'[[\'\n'
    )
    assert check_nesting(text, "s", SceneError, kind="toml") == 2
    data = parse_toml(text.encode(), "s", SceneError)
    assert data["a"] == [[1], "[[[["]
    assert data["t"]["c"] == '[[[\n"""[['


@pytest.mark.parametrize(
    ("content", "says"),
    [
        (b"[" * 100_000 + b"]" * 100_000, "nested 100000 levels deep, more than the limit of 64"),
        (b'{"pop": NaN}', "NaN is not a JSON number"),
        (b'{"pop": 1e400}', "the number 1e400 is not finite"),
        (b"\xff", "not UTF-8 text"),
    ],
    ids=["deep", "nan", "overflow", "binary"],
)
def test_resume_refuses_a_hostile_run_file_in_one_line(
    content: bytes, says: str, tmp_path: Path, capsys
) -> None:
    (tmp_path / "run.json").write_bytes(content)
    assert main(["plan", "--resume", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert f"{tmp_path / 'run.json'}: {says}" in err
    assert "Traceback" not in err


def test_resume_refuses_a_run_file_beyond_the_size_limit(tmp_path: Path, capsys) -> None:
    with (tmp_path / "run.json").open("wb") as fh:  # sparse: no 64 MiB written
        fh.truncate(MAX_FILE_BYTES + 1)
    assert main(["plan", "--resume", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "run.json: run arguments larger than the limit" in err


# ============================================================================ obstacles
def _sphere_entries(n: int) -> dict:
    return {
        "obstacle": [
            {"name": f"s{i}", "shape": "sphere", "radius": 0.01, "xyz": [2.0, 2.0, 2.0 + i]}
            for i in range(n)
        ]
    }


def test_scene_with_too_many_obstacles_is_refused_before_building(monkeypatch) -> None:
    built = []
    monkeypatch.setattr(Obstacle, "__post_init__", lambda self: built.append(self))
    with pytest.raises(ResourceLimitError, match=r"10001 obstacles, more than the limit"):
        Scene.from_dict(_sphere_entries(MAX_OBSTACLES + 1), "big.toml")
    assert built == []
    pendulums = {"pendulum": [{}] * (MAX_OBSTACLES // 2 + 1)}  # two obstacles each
    with pytest.raises(ResourceLimitError, match=r"big\.toml: 10002 obstacles"):
        Scene.from_dict(pendulums, "big.toml")


def test_scene_object_with_too_many_obstacles_is_refused() -> None:
    ball = Obstacle("b", Sphere(0.01))
    many = [ball] * (MAX_OBSTACLES + 1)  # the count is checked before the names
    with pytest.raises(ResourceLimitError, match="scene 'scene': 10001 obstacles"):
        Scene(many)


def test_scene_at_the_limit_is_accepted_by_the_count_check() -> None:
    from adept_traj.scene import check_obstacle_count

    assert check_obstacle_count(MAX_OBSTACLES) == MAX_OBSTACLES


def test_checks_are_os_independent_of_the_caller_folder(tmp_path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SceneError, match="not found"):
        read_toml("missing.toml", SceneError, what="scene file")
    os.mkdir("folder.toml")
    with pytest.raises(SceneError, match="is a folder"):
        read_toml("folder.toml", SceneError)


@pytest.mark.slow
@pytest.mark.parametrize("algorithm", ["nsga2", "mode"])
def test_peak_rss_of_a_large_run_stays_below_its_estimate(algorithm: str, tmp_path) -> None:
    """The estimate that guards --pop bounds the peak RSS of a real run (pop 4 000)."""
    import subprocess
    import sys

    cmd = [
        "-m", "adept_traj.cli", "plan", "--algorithm", algorithm, "--pop", "4000", "--gens",
        "2", "--quiet", "--no-plots", "--no-html", "--out", str(tmp_path),
    ]  # fmt: skip
    # A fresh parent, so that ru_maxrss is this run's alone (not an earlier child's).
    measure = (
        "import resource, subprocess, sys; "
        f"subprocess.run([sys.executable, *{cmd!r}], check=True); "
        "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)"
    )
    out = subprocess.run([sys.executable, "-c", measure], check=True, capture_output=True)
    peak = int(out.stdout.split()[-1]) * 1024  # ru_maxrss is in KiB on Linux
    assert peak <= population_bytes(4000, 2)
