"""Many panels on ONE hidden matplotlib ``Axes``: its cells, their tick values and labels.

A matplotlib ``Axes`` is costly to make and draw (its axis objects, ticks and
spines), so the figures with many panels (the Pareto matrix: 36, the joint motion: 20)
draw every panel as a cell of one ``Axes`` with its own scale, each kind of line as one
collection over all the cells, and only the tick labels that are seen as text. The texts
are made by :func:`panel_texts` (as ``Axes.text`` makes them, their unused clip path shared),
their offset transforms shared (:func:`shifter`).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["hidden_axes", "panel_texts", "shifted", "shifter", "tick_labels"]

_SUPERSCRIPT = str.maketrans("-−0123456789", "⁻⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def hidden_axes(fig: Any, box: tuple[float, float, float, float], width: float,
                height: float) -> Any:  # fmt: skip
    """An ``Axes`` without axis, ticks or frame over ``box`` (left, bottom, right, top,
    figure fractions), data coordinates [0, ``width``] × [0, ``height``] (cell units)."""
    left, bottom, right, top = box
    ax = fig.add_axes((left, bottom, right - left, top - bottom))
    ax.set_axis_off()
    ax.set(xlim=(0.0, width), ylim=(0.0, height))
    return ax


def shifted(ax: Any, dx: float, dy: float) -> Any:
    """``ax``'s data coordinates moved by (``dx``, ``dy``) [points] (for text beside a
    cell)."""
    from matplotlib.transforms import offset_copy

    return offset_copy(ax.transData, fig=ax.figure, x=dx, y=dy, units="points")


def shifter(ax: Any) -> Callable[[float, float], Any]:
    """:func:`shifted` for ``ax``, each offset (``dx``, ``dy``) [points] made once: the texts
    at one offset share its transform."""
    made: dict[tuple[float, float], Any] = {}

    def shift(dx: float, dy: float) -> Any:
        if (dx, dy) not in made:
            made[dx, dy] = shifted(ax, dx, dy)
        return made[dx, dy]

    return shift


def panel_texts(ax: Any) -> Callable[..., Any]:
    """``Axes.text`` for ``ax``, made cheaper: ``text(x, y, s, **kwargs)`` adds a text at
    (``x``, ``y``) in ``ax``'s data coordinates (or ``transform=``) with ``Axes.text``'s
    defaults (left, baseline, not clipped) and returns it. ``Axes.text`` gives every text
    the axes' patch as clip path, whose transform is costly to make, and unused (the text
    is not clipped): these texts share one, made once."""
    from matplotlib.text import Text
    from matplotlib.transforms import TransformedPatchPath

    clip = TransformedPatchPath(ax.patch)

    def text(x: float, y: float, s: str, **kwargs: Any) -> Any:
        t = Text(x, y, s, **{"transform": ax.transData, "clip_on": False, **kwargs})
        t.set_clip_path(clip)
        return ax.add_artist(t)

    return text


def tick_labels(
    lo: float,
    hi: float,
    n_ticks: int,
    *,
    power_of_ten: bool = False,
    power_limits: tuple[int, int] | None = None,
) -> tuple[np.ndarray, list[str], str]:
    """Ticks of a scale [``lo``, ``hi``] as an axis of matplotlib would place and label
    them: ``MaxNLocator(n_ticks)`` values within the range, the labels and the offset or
    factor text (``""`` if none) of a ``ScalarFormatter``.

    ``power_of_ten``: a factor written ``×10³`` (Unicode, as ``useMathText`` shows it but
    without mathtext, whose parser is slow on a figure's first use) instead of
    ``1e3``. ``power_limits``: the exponents (low, high) outside which a factor is used
    (``ScalarFormatter.set_powerlimits``; default matplotlib's, −5 and 6).

    Returns
    -------
    (k,) tick values in [lo, hi], their k labels, and the scale's offset text.
    """
    from matplotlib.ticker import MaxNLocator, ScalarFormatter

    locs = MaxNLocator(n_ticks).tick_values(lo, hi)
    span = 1e-10 * (hi - lo)
    locs = locs[(locs >= lo - span) & (locs <= hi + span)]
    fmt = ScalarFormatter()
    if power_limits is not None:
        fmt.set_powerlimits(power_limits)
    fmt.create_dummy_axis()
    fmt.axis.set_view_interval(lo, hi)
    fmt.axis.set_data_interval(lo, hi)
    labels, offset = fmt.format_ticks(locs), fmt.get_offset()
    factor = re.fullmatch("1e([-−]?[0-9]+)", offset)  # a factor alone, no offset
    if power_of_ten and factor:
        return locs, labels, "×10" + factor.group(1).translate(_SUPERSCRIPT)
    return locs, labels, offset
