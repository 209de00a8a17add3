"""adept_traj.viz.plots: every figure is written, is a real PNG and is not blank; inputs are
validated; matplotlib is imported lazily and pyplot's state is left alone."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import matplotlib  # the [test] extra: a missing matplotlib fails here, it is not skipped
import numpy as np
import pytest

import adept_traj as at
from adept_traj.errors import InvalidInputError
from adept_traj.results import GenerationRecord, PlanningResult, Replay, RobotInfo
from adept_traj.viz import plots
from adept_traj.viz.plots import all_figures, wireframes
from adept_traj.viz.plots.common import file_suffix
from adept_traj.viz.plots.history import _records_hypervolume


@pytest.fixture(scope="module")
def results() -> dict[str, PlanningResult]:
    """Two tiny runs (a few seconds): nothing feasible yet, so the fronts are the
    least-infeasible solutions (hollow markers, 'NOT feasible' titles)."""
    scene = at.Scene.paper()
    problem = at.TrajectoryProblem(at.Robot.adept_one_xl(), scene, scene.start, scene.goal)
    try:
        return {
            name: at.plan(problem, name, seed=1, pop_size=12, n_gen=3, rate_hz=250.0, polish=False)
            for name in ("nsga2", "mode")
        }
    finally:
        problem.close()


@pytest.fixture(scope="module")
def with_hypervolume(results: dict[str, PlanningResult]) -> PlanningResult:
    """A result whose history records hypervolumes (one generation without)."""
    history = [
        GenerationRecord(1, 12, 0, None),
        GenerationRecord(2, 24, 3, 0.21),
        GenerationRecord(3, 36, 5, 0.35),
    ]
    return dataclasses.replace(results["nsga2"], history=history)


def assert_picture(path: Path, min_width: int = 600, min_height: int = 400) -> None:
    """A PNG of a sensible size that is not blank."""
    from matplotlib.image import imread

    assert path.is_file()
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    img = imread(path)
    h, w = img.shape[:2]
    assert w >= min_width
    assert h >= min_height
    grey = img[..., :3].mean(axis=-1)
    assert grey.std() > 0.03  # not a uniform picture
    assert (grey < 0.9).mean() > 0.01  # some ink
    assert (grey > 0.95).mean() > 0.2  # not a filled mess either


FIGURES = [
    "pareto_matrix.png",
    "best_tradeoffs.png",
    "hypervolume_history.png",
    "joint_motion_nsga2.png",
    "tool_path_nsga2.png",
    "joint_motion_mode.png",
    "tool_path_mode.png",
]


@pytest.fixture(scope="module")
def figures(
    results: dict[str, PlanningResult], tmp_path_factory: pytest.TempPathFactory
) -> dict[str, Path]:
    """Every figure, drawn once by save_all; the backend and pyplot's figure list are
    checked around the call (pyplot is imported first, so a figure made through it would
    register)."""
    import matplotlib.pyplot as plt

    backend = matplotlib.get_backend()
    before = plt.get_fignums()
    folder = tmp_path_factory.mktemp("figures") / "figs"
    written = plots.save_all(results, folder)
    assert matplotlib.get_backend() == backend  # the caller's backend is left alone
    assert plt.get_fignums() == before  # no pyplot figure made or left open
    assert all(p.parent == folder for p in written)
    return {p.name: p for p in written}


def test_save_all_writes_every_figure(figures: dict[str, Path]) -> None:
    assert list(figures) == FIGURES


@pytest.mark.parametrize("name", FIGURES)
def test_figure_is_a_picture(figures: dict[str, Path], name: str) -> None:
    big = {"pareto_matrix.png": (1200, 1200), "joint_motion_nsga2.png": (1200, 1200)}
    big |= {"joint_motion_mode.png": (1200, 1200), "tool_path_nsga2.png": (1200, 800)}
    assert_picture(figures[name], *big.get(name, (600, 400)))


def test_one_result_and_the_returned_path(
    results: dict[str, PlanningResult], tmp_path: Path
) -> None:
    target = tmp_path / "sub" / "dir" / "pareto.png"
    out = plots.pareto_matrix(results["mode"], target)  # a bare result is accepted
    assert out == target
    assert_picture(out, 1200, 1200)


def test_history_with_hypervolume(
    results: dict[str, PlanningResult], with_hypervolume: PlanningResult, tmp_path: Path
) -> None:
    assert _records_hypervolume([with_hypervolume.history])
    both = {"with": with_hypervolume, "without": results["mode"]}
    assert_picture(plots.hypervolume_history(both, tmp_path / "hv.png"))
    assert_picture(plots.hypervolume_history(with_hypervolume, tmp_path / "hv1.png"))


def test_history_without_hypervolume(results: dict[str, PlanningResult], tmp_path: Path) -> None:
    none = [dataclasses.replace(rec, hypervolume=None) for rec in results["mode"].history]
    bare = dataclasses.replace(results["mode"], history=none)
    assert not _records_hypervolume([bare.history])
    assert_picture(plots.hypervolume_history({"a": bare}, tmp_path / "feasible.png"))


def test_history_missing(
    results: dict[str, PlanningResult], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    bare = dataclasses.replace(results["nsga2"], history=None)
    with pytest.raises(InvalidInputError, match="history"):
        plots.hypervolume_history(bare, tmp_path / "hv.png")
    for name in ("pareto_matrix", "best_tradeoffs", "joint_motion", "tool_path_3d"):
        monkeypatch.setattr(all_figures, name, lambda _r, path, **_: Path(path))  # no drawing
    written = plots.save_all({"bare": bare}, tmp_path / "all")
    assert [p.name for p in written] == [
        "pareto_matrix.png",
        "best_tradeoffs.png",
        "joint_motion_bare.png",
        "tool_path_bare.png",
    ]  # no hypervolume_history.png


def _one_move(result: PlanningResult) -> PlanningResult:
    """``result`` with its best trade-off as the only front member."""
    keep = np.arange(len(result.front)) == result.best.index
    best = dataclasses.replace(result.best, index=0)
    return dataclasses.replace(result, front=result.front.subset(keep), best=best)


def test_a_one_move_front_has_no_front_figures(
    results: dict[str, PlanningResult], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """One front member in all (one time-optimal move) has no trade-off to show: no
    pareto matrix, no best trade-offs; two one-move results (compared) have them."""
    one = _one_move(dataclasses.replace(results["nsga2"], history=None))
    assert len(one.front) == 1
    drawn: list[str] = []
    for name in ("pareto_matrix", "best_tradeoffs", "joint_motion", "tool_path_3d"):
        monkeypatch.setattr(
            all_figures, name, lambda _r, path, _n=name, **_: drawn.append(_n) or Path(path)
        )
    written = plots.save_all({"to": one}, tmp_path / "one", processes=1)
    assert [p.name for p in written] == ["joint_motion_to.png", "tool_path_to.png"]
    assert sorted(drawn) == ["joint_motion", "tool_path_3d"]
    assert not all_figures.has_front_figures({"to": one})
    assert all_figures.has_front_figures({"a": one, "b": one})
    assert all_figures.has_front_figures({"nsga2": results["nsga2"]})
    two = plots.save_all({"a": one, "b": one}, tmp_path / "two")
    assert [p.name for p in two][:2] == ["pareto_matrix.png", "best_tradeoffs.png"]


def test_tool_path_with_a_replay_loads_nothing(
    results: dict[str, PlanningResult], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The robot files are loaded once per figure without a replay, never with one."""
    result = results["mode"]
    replay = Replay.of(result)
    loads = []
    load = RobotInfo.load
    monkeypatch.setattr(RobotInfo, "load", lambda info: loads.append(1) or load(info))
    assert_picture(plots.tool_path_3d(result, tmp_path / "a.png", replay=replay), 1200, 800)
    assert loads == []
    assert_picture(plots.tool_path_3d(result, tmp_path / "b.png"), 1200, 800)
    assert loads == [1]
    for name in ("pareto_matrix", "best_tradeoffs", "joint_motion"):
        monkeypatch.setattr(all_figures, name, lambda _r, path, **_: Path(path))  # no drawing
    drawn = []
    monkeypatch.setattr(
        all_figures, "tool_path_3d", lambda _r, path, replay: drawn.append(replay) or path
    )
    plots.save_all(
        {"m": result, "n": results["nsga2"]}, tmp_path / "all", replays={"m": replay}, processes=1
    )
    assert drawn == [replay, None]


@pytest.mark.parametrize(
    ("make", "match"),
    [
        (lambda res: [], "replays must be of type Mapping"),
        (lambda res: {"other": None}, "names no result"),
        (lambda res: {"mode": "replay"}, "replay must be of type Replay"),
        (lambda res: {"mode": Replay.of(res["nsga2"])}, "best_x"),  # another result's
    ],
    ids=["list", "unknown-name", "not-a-replay", "other-result"],
)
def test_bad_replays(
    results: dict[str, PlanningResult], tmp_path: Path, make: object, match: str
) -> None:
    with pytest.raises(InvalidInputError, match=match):
        plots.save_all(results, tmp_path / "figs", replays=make(results))  # type: ignore[operator]
    assert not (tmp_path / "figs").exists()  # checked before anything is drawn


def test_file_names_are_sanitised(results: dict[str, PlanningResult], tmp_path: Path) -> None:
    assert file_suffix("run 1/a") == "run_1_a"
    assert file_suffix("NSGA-II") == "NSGA-II"
    assert file_suffix("../..") == "result"
    with pytest.raises(InvalidInputError, match="clashing"):
        plots.save_all({"a b": results["mode"], "a/b": results["nsga2"]}, tmp_path)
    assert not any(tmp_path.iterdir())  # checked before anything is drawn


@pytest.mark.parametrize(
    "bad",
    [{}, [], None, "nsga2", {"x": 1}, {1: None}, {"": None}],
    ids=["empty", "list", "none", "str", "not-a-result", "int-key", "empty-key"],
)
def test_bad_results(bad: object, tmp_path: Path) -> None:
    for fn in (plots.pareto_matrix, plots.best_tradeoffs, plots.hypervolume_history):
        with pytest.raises(InvalidInputError):
            fn(bad, tmp_path / "x.png")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError):
        plots.save_all(bad, tmp_path)  # type: ignore[arg-type]


@pytest.mark.parametrize("fn", [plots.joint_motion, plots.tool_path_3d])
def test_bad_single_result(fn, tmp_path: Path) -> None:
    with pytest.raises(InvalidInputError, match="PlanningResult"):
        fn({"a": 1}, tmp_path / "x.png")


@pytest.mark.parametrize("path", ["figure.jpg", "figure", 3])
def test_bad_path(results: dict[str, PlanningResult], tmp_path: Path, path: object) -> None:
    target = tmp_path / path if isinstance(path, str) else path
    with pytest.raises(InvalidInputError):
        plots.best_tradeoffs(results, target)  # type: ignore[arg-type]
    assert not any(tmp_path.iterdir())


def test_too_many_results(results: dict[str, PlanningResult], tmp_path: Path) -> None:
    many = {f"r{i}": results["mode"] for i in range(7)}
    with pytest.raises(InvalidInputError, match="at most"):
        plots.pareto_matrix(many, tmp_path / "x.png")


def test_objective_labels_have_units() -> None:
    assert len(plots.OBJECTIVE_LABELS) == 6
    assert all("[" in label and "]" in label for label in plots.OBJECTIVE_LABELS)
    assert set(plots.__all__) >= {
        "pareto_matrix",
        "best_tradeoffs",
        "joint_motion",
        "tool_path_3d",
        "hypervolume_history",
        "save_all",
    }


def test_matplotlib_is_imported_lazily() -> None:
    code = (
        "import sys, adept_traj.viz.plots, adept_traj.results.ros_export\n"
        "assert 'matplotlib' not in sys.modules, 'matplotlib imported eagerly'\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_wireframes_outline_the_solids() -> None:
    pose = np.eye(4)
    pose[:3, 3] = (1.0, 2.0, 3.0)
    box = wireframes.wireframe("box", (0.5, 1.0, 1.5), pose)
    assert len(box) == 12
    pts = np.vstack(box)
    np.testing.assert_allclose(pts.min(axis=0), (0.5, 1.0, 1.5))
    np.testing.assert_allclose(pts.max(axis=0), (1.5, 3.0, 4.5))
    sphere = np.vstack(wireframes.wireframe("sphere", (0.2,), pose))
    np.testing.assert_allclose(np.linalg.norm(sphere - pose[:3, 3], axis=1), 0.2)
    cyl = np.vstack(wireframes.wireframe("cylinder", (0.1, 0.3), pose))
    np.testing.assert_allclose(cyl[:, 2].min(), 2.7)
    np.testing.assert_allclose(cyl[:, 2].max(), 3.3)
    assert wireframes.wireframe("mesh", (), pose) == []


def test_figures_are_the_same_bytes_every_time(
    results: dict[str, PlanningResult], figures: dict[str, Path], tmp_path: Path
) -> None:
    """Drawn again in this process (save_all drew them on two), the same bytes; no
    matplotlib version in the file (a Software entry would change with each release)."""
    again = {
        "pareto_matrix.png": plots.pareto_matrix(results, tmp_path / "p.png"),
        "joint_motion_nsga2.png": plots.joint_motion(results["nsga2"], tmp_path / "j.png"),
    }
    for name, path in again.items():
        data = path.read_bytes()
        assert data == figures[name].read_bytes(), name
        assert b"Software" not in data
        assert b"atplotlib" not in data


def _drawn(monkeypatch: pytest.MonkeyPatch, module: object, draw) -> object:
    """The matplotlib figure ``draw()`` builds in ``module`` (not rendered)."""
    made = []

    def keep(fig, path):
        made.append(fig)
        return path

    monkeypatch.setattr(module, "save_figure", keep)
    draw()
    (fig,) = made
    return fig


def test_the_figures_draw_every_sample(
    results: dict[str, PlanningResult], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """What the figures hold, independent of how fast they are drawn: every 1 kHz sample
    of the joint motion and of the tool path (nothing thinned), every front member in all
    30 scatter panels, the extremes of each series where the panel puts them."""
    from matplotlib.collections import LineCollection, PathCollection

    from adept_traj.viz.plots import fronts, motion, tool_path

    r = results["nsga2"]
    dense, nq = r.best_trajectory, r.best_trajectory.nq
    fig = _drawn(monkeypatch, motion, lambda: plots.joint_motion(r, tmp_path / "j.png"))
    (ax,) = fig.axes
    curves = [c for c in ax.collections if isinstance(c, LineCollection)][1].get_segments()
    assert len(curves) == 5 * nq  # q, q̇, q̈, q⃛, τ of every joint
    assert {len(c) for c in curves} == {len(dense.t)}
    for curve, values in zip(curves[:nq], dense.q.T):  # positions: extremes kept, in place
        lo, hi = curve[:, 1].min(), curve[:, 1].max()
        scaled = (values - values.min()) / np.ptp(values) * (hi - lo) + lo
        np.testing.assert_allclose(curve[:, 1], scaled, atol=1e-9)

    fig = _drawn(monkeypatch, tool_path, lambda: plots.tool_path_3d(r, tmp_path / "t.png"))
    assert len(fig.axes) == 4  # 3-D, top view, side view, colour bar
    for view in fig.axes[1:3]:
        coloured = [c for c in view.collections if c.get_array() is not None]
        assert [len(c.get_segments()) for c in coloured] == [len(dense.t) - 1]

    fig = _drawn(monkeypatch, fronts, lambda: plots.pareto_matrix(r, tmp_path / "p.png"))
    (ax,) = fig.axes
    scatters = [c for c in ax.collections if isinstance(c, PathCollection)]
    assert sum(len(c.get_offsets()) for c in scatters) == 30 * (len(r.front) + 1)  # + best
