"""Issue #15: the import of ``adept-traj plan`` and a run's generations load neither scipy
(``scipy.spatial`` through pymoo's NSGA-II and crowding modules and the duplicate
elimination, ``numpy.f2py`` through scipy's array API) nor ``xml.sax.saxutils`` (which
imports urllib, http, email and ssl); the pieces that replaced them give the same bits."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from xml.sax.saxutils import quoteattr

import numpy as np
import pytest
from pymoo.operators.survival.rank_and_crowding.metrics import get_crowding_function

from adept_traj.errors import InputShapeError
from adept_traj.optimise import crowding_distance

#: Modules that neither the plan command's import nor a run's generations may load.
_AVOIDED = (
    "scipy",
    "scipy.spatial",
    "scipy.sparse",
    "numpy.f2py",
    "xml.sax.saxutils",
    "pymoo.algorithms.moo.nsga2",
    "pymoo.operators.survival.rank_and_crowding",
)

_RUN = """
import sys
import adept_traj.cli.plan
loaded = [sorted(m for m in {avoided!r} if m in sys.modules)]
from adept_traj import Robot, Scene
from adept_traj.optimise import make_algorithm, optimise
from adept_traj.problem import TrajectoryProblem
scene = Scene.paper()
problem = TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)
for name in ("nsga2", "mode"):
    algorithm, _ = make_algorithm(name, pop_size=12)
    optimise(problem, algorithm, 3, seed=1)
loaded.append(sorted(m for m in {avoided!r} if m in sys.modules))
print(loaded)
"""


def test_the_plan_command_and_its_generations_load_no_scipy_nor_urllib_via_xml() -> None:
    code = _RUN.format(avoided=_AVOIDED)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    after_import, after_run = ast.literal_eval(out.stdout.strip().splitlines()[-1])
    assert after_import == []
    assert after_run == []


@pytest.mark.parametrize("n", [1, 2, 3, 7, 40])
@pytest.mark.parametrize("seed", [0, 1])
def test_crowding_distance_is_pymoos_bit_for_bit(n: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    F = rng.integers(0, 4, size=(n, 6)).astype(float)  # ties and duplicate rows
    F[:, 2] = 1.5  # a constant objective (pymoo's NaN norm)
    if n > 3:
        F[0, 1] = np.inf
        F[1] = rng.uniform(size=6)
    with np.errstate(invalid="ignore"):  # inf - inf, as in pymoo
        ours = crowding_distance(F)
        theirs = get_crowding_function("cd").do(F, n_remove=0)
    assert ours.dtype == theirs.dtype
    assert ours.shape == (n,)
    np.testing.assert_array_equal(ours, theirs)
    assert ours.tobytes() == theirs.tobytes()


@pytest.mark.parametrize(
    "name", ["arm", 'say "hi"', "it's", "'both\" & <tags>'", "tab\tnew\nline\rcr", ""]
)
def test_names_are_quoted_as_the_standard_library_quotes_them(name: str) -> None:
    # (tests/robot/test_urdf_builder.py compares the whole URDF with the committed file)
    from adept_traj.robot.urdf_builder import _quoteattr

    assert _quoteattr(name) == quoteattr(name)


_BLAS_THREADS = """
import sys
from types import SimpleNamespace
import numpy as np
from threadpoolctl import threadpool_info
from adept_traj.optimise.local import epsilon_constraint as member_polish
from adept_traj.optimise.local import minimum_time as polish

assert "scipy" not in sys.modules  # as in a run: scipy is first imported by the polish
seen = []

def record(*args, **kwargs):
    seen.append(sorted({{(i["filepath"], i["num_threads"]) for i in threadpool_info()
                         if i["user_api"] == "blas"}}))

problem = SimpleNamespace(n_var=3, xl=np.zeros(3), xu=np.ones(3))  # what is checked first
x0 = np.full(3, 0.5)
if {which!r} == "polish":
    polish._minimum_time = record
    polish.minimum_time(problem, x0)
else:
    member_polish._solve = record
    member_polish.epsilon_solve(problem, x0)
print(seen)
"""


@pytest.mark.parametrize("which", ["polish", pytest.param("member_polish", marks=pytest.mark.slow)])
def test_the_polish_limits_scipys_blas_too_when_scipy_is_imported_late(which: str) -> None:
    # scipy (and its own OpenBLAS) is no longer imported when the run starts: the polish
    # imports it inside its one-BLAS-thread section, whose limit covers only the BLAS
    # libraries loaded before it (a multi-threaded BLAS changed the polished move's bits).
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "2", "OMP_NUM_THREADS": "2"}
    out = subprocess.run(
        [sys.executable, "-c", _BLAS_THREADS.format(which=which)],
        capture_output=True,
        text=True,
        check=True,
        env=env,
    )
    (libraries,) = ast.literal_eval(out.stdout.strip().splitlines()[-1])
    assert len(libraries) >= 2  # numpy's OpenBLAS and scipy's
    assert all(threads == 1 for _, threads in libraries), libraries


@pytest.mark.parametrize("F", [np.ones(3), np.ones((3, 0))])
def test_crowding_distance_refuses_what_is_not_a_front(F) -> None:
    with pytest.raises(InputShapeError, match=r"F must have shape \(n, m\)"):
        crowding_distance(F)
