"""The CLI's figure step: a missing matplotlib is a note, a broken adept_traj is an error
(it used to print "install the 'plot' extra" when a subpackage was missing from the wheel)."""

from __future__ import annotations

from pathlib import Path

import pytest

from adept_traj.cli import report
from adept_traj.cli.report import finish_figures, save_figures, start_figures
from adept_traj.viz import plots


def _raise(name: str):
    def save_all(*_args, **_kwargs):
        raise ImportError(f"No module named '{name}'", name=name)

    return save_all


def test_missing_matplotlib_is_a_note(monkeypatch, tmp_path: Path, capsys):
    monkeypatch.setattr(plots, "save_all", _raise("matplotlib.pyplot"))
    save_figures({}, tmp_path)
    assert "figures skipped" in capsys.readouterr().err


def test_missing_part_of_adept_traj_is_an_error(monkeypatch, tmp_path: Path):
    monkeypatch.setattr(plots, "save_all", _raise("adept_traj.viz.plots.fronts"))
    with pytest.raises(ImportError, match=r"adept_traj\.viz\.plots\.fronts"):
        save_figures({}, tmp_path)


class _Drawing:
    """A figure drawing under way whose wait raises an ImportError of ``name``."""

    def __init__(self, name: str) -> None:
        self.name = name

    def wait(self):
        raise ImportError(f"No module named '{self.name}'", name=self.name)


def test_background_figures_missing_matplotlib_is_a_note(monkeypatch, tmp_path: Path, capsys):
    finish_figures(_Drawing("matplotlib.figure"), tmp_path, {})
    assert "figures skipped" in capsys.readouterr().err
    with pytest.raises(ImportError, match=r"adept_traj\.viz\.plots\.fronts"):
        finish_figures(_Drawing("adept_traj.viz.plots.fronts"), tmp_path, {})
    monkeypatch.setattr(report.importlib.util, "find_spec", lambda name: None)
    assert start_figures({}, tmp_path) is None  # nothing started, nothing checked
    assert "figures skipped (no module named 'matplotlib')" in capsys.readouterr().err
