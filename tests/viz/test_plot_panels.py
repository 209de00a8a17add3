"""adept_traj.viz.plots._panels: the ticks of a panel drawn on a shared hidden Axes are those
a matplotlib axis of the same range places and labels (the reference: a real Axes)."""

from __future__ import annotations

import re

import matplotlib  # the [test] extra
import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator, ScalarFormatter

from adept_traj.viz.plots._panels import hidden_axes, tick_labels

assert matplotlib  # imported for its presence

RANGES = [(0.0, 1.0), (-2.7, 3.1), (1.2e-3, 4.4e-3), (950.0, 5200.0), (0.031, 0.0392), (-60.0, 0.5)]


def _axis_ticks(lo: float, hi: float, n: int, limits: tuple[int, int] | None, math: bool):
    """Tick values, labels and offset text of a real x axis on [lo, hi] (drawn)."""
    fig = Figure()
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.set_xlim(lo, hi)
    ax.xaxis.set_major_locator(MaxNLocator(n))
    fmt = ScalarFormatter(useMathText=math)
    if limits is not None:
        fmt.set_powerlimits(limits)
    ax.xaxis.set_major_formatter(fmt)
    fig.canvas.draw()
    ticks = [t for t in ax.xaxis.get_major_ticks() if lo <= t.get_loc() <= hi]
    locs = np.array([t.get_loc() for t in ticks])
    labels = [t.label1.get_text() for t in ticks]
    return locs, labels, ax.xaxis.get_offset_text().get_text()


@pytest.mark.parametrize(("lo", "hi"), RANGES)
@pytest.mark.parametrize("n", [3, 4, 5])
def test_plain_ticks_are_an_axis_ticks(lo: float, hi: float, n: int) -> None:
    locs, labels, offset = tick_labels(lo, hi, n)
    ref_locs, ref_labels, ref_offset = _axis_ticks(lo, hi, n, None, False)
    np.testing.assert_allclose(locs, ref_locs)
    assert labels == ref_labels
    assert offset == ref_offset


@pytest.mark.parametrize(("lo", "hi"), RANGES)
def test_power_of_ten_factor(lo: float, hi: float) -> None:
    locs, labels, offset = tick_labels(lo, hi, 3, power_of_ten=True, power_limits=(-2, 3))
    ref_locs, ref_labels, ref_offset = _axis_ticks(lo, hi, 3, (-2, 3), True)
    np.testing.assert_allclose(locs, ref_locs)
    assert [f"$\\mathdefault{{{s}}}$" for s in labels] == ref_labels
    power = re.search(r"10\^\{([-−]?\d+)\}", ref_offset)  # mathtext: \times 10^{3}
    expected = {None: "", "3": "×10³", "−3": "×10⁻³", "−2": "×10⁻²"}
    assert offset == expected[power.group(1) if power else None]


def test_hidden_axes_spans_its_box() -> None:
    fig = Figure(figsize=(10.0, 5.0))
    FigureCanvasAgg(fig)
    ax = hidden_axes(fig, (0.1, 0.2, 0.9, 0.8), 6.0, 3.0)
    assert not ax.axison
    np.testing.assert_allclose(ax.get_position().bounds, (0.1, 0.2, 0.8, 0.6))
    assert ax.get_xlim() == (0.0, 6.0)
    assert ax.get_ylim() == (0.0, 3.0)
