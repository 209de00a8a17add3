"""What the figures share: objective labels, colours and markers, legend names, the
checks of the results and paths, and a figure on its own Agg canvas.

matplotlib is imported inside :func:`new_figure` only (``pip install 'adept-traj[plot]'``).
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from adept_traj.errors import InvalidInputError
from adept_traj.problem import OBJECTIVES
from adept_traj.results import PlanningResult
from adept_traj.viz.inputs import as_result
from adept_traj.viz.plots._png import write_png

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "COLOURS",
    "DPI",
    "MARKERS",
    "OBJECTIVE_LABELS",
    "PNG_COMPRESSION",
    "as_results",
    "display_name",
    "file_suffix",
    "front_rows",
    "legend_labels",
    "load_matplotlib",
    "new_figure",
    "padded",
    "png_path",
    "save_figure",
    "status",
    "violations_line",
]

#: Axis labels of z1…z6 with their units, from the objective table (z4 marked "(max)").
OBJECTIVE_LABELS = tuple(objective.label for objective in OBJECTIVES)
#: Colour and marker of each result in a figure, in order (at most six results).
COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")
MARKERS = ("o", "s", "^", "D", "v", "P")
#: Resolution of the PNG files [dots per inch].
DPI = 110
#: zlib compression level of the PNG files (1: fastest; matplotlib's default is 6).
PNG_COMPRESSION = 1
_DISPLAY_NAMES = {
    "nsga2": "NSGA-II",
    "mode": "MODE",
    "nsga3": "NSGA-III",
    "unsga3": "U-NSGA-III",
    "smsemoa": "SMS-EMOA",
    "moead": "MOEA/D",
    "rvea": "RVEA",
}


# ============================================================================ inputs
def as_results(results: Any) -> dict[str, PlanningResult]:
    """``{name: result}`` from a mapping (or one result, named by its algorithm); at most
    ``len(COLOURS)`` results, keys non-empty strings."""
    if isinstance(results, PlanningResult):
        return {results.algorithm: results}
    if not isinstance(results, Mapping):
        raise InvalidInputError(
            "results must be a mapping {name: PlanningResult} (or one PlanningResult); got "
            f"{type(results).__name__}"
        )
    if not results:
        raise InvalidInputError("results must hold at least one PlanningResult")
    out: dict[str, PlanningResult] = {}
    for key, value in results.items():
        if not isinstance(key, str) or not key:
            raise InvalidInputError(f"results keys must be non-empty strings; got {key!r}")
        out[key] = as_result(value, f"results[{key!r}]")
    if len(out) > len(COLOURS):
        raise InvalidInputError(f"at most {len(COLOURS)} results per figure; got {len(out)}")
    return out


def png_path(path: Any) -> Path:
    """``path`` as a :class:`~pathlib.Path` naming a ``.png`` file (its folder created)."""
    try:
        out = Path(os.fspath(path))
    except TypeError:
        raise InvalidInputError(f"path must be a file path; got {type(path).__name__}") from None
    if out.suffix.lower() != ".png":
        raise InvalidInputError(f"path must name a .png file; got {str(out)!r}")
    out.parent.mkdir(parents=True, exist_ok=True)
    return out


def file_suffix(key: str) -> str:
    """A result's name made safe for a file name (other characters than letters, digits,
    ``_ . -`` replaced by ``_``; ``"result"`` if nothing is left)."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", key).strip("._") or "result"


# ============================================================================ labels
def display_name(algorithm: str) -> str:
    """The usual spelling of an algorithm's name (``"nsga2"`` → ``"NSGA-II"``)."""
    return _DISPLAY_NAMES.get(algorithm.lower(), algorithm)


def legend_labels(results: Mapping[str, PlanningResult]) -> dict[str, str]:
    """Legend label per key: the algorithm's name when unique, else key and name."""
    names = [display_name(r.algorithm) for r in results.values()]
    if len(set(names)) == len(names):
        return dict(zip(results, names))
    return {k: f"{k} ({name})" for k, name in zip(results, names)}


def status(result: PlanningResult) -> str:
    """The certificate's verdict in words."""
    return "verified feasible" if result.feasible else "NOT feasible"


def violations_line(result: PlanningResult, at_most: int = 2) -> str:
    """A second title line listing the certificate's first violations (or nothing)."""
    v = result.certificate.violations
    if not v:
        return ""
    more = f"; {len(v) - at_most} more" if len(v) > at_most else ""
    return "\n" + "; ".join(v[:at_most]) + more


# ============================================================================ data, axes
def front_rows(result: PlanningResult) -> np.ndarray:
    """(n, 6) objectives of the feasible front, or of the whole front if nothing is
    feasible."""
    feas = result.front.feasible
    return result.front.objectives[feas] if feas.any() else result.front.objectives


def padded(lo: float, hi: float, frac: float = 0.06) -> tuple[float, float]:
    """Axis limits around [lo, hi], widened by ``frac`` of the span on each side; a
    single value v gets ±5 % of :math:`|v|` (±0.05 for 0)."""
    span = hi - lo
    if span <= 1e-12 * max(abs(lo), abs(hi)) or span == 0.0:
        pad = 0.05 * abs(lo) if lo != 0.0 else 0.05
        return lo - pad, hi + pad
    return lo - frac * span, hi + frac * span


# ============================================================================ matplotlib
def load_matplotlib() -> tuple[type, type]:
    """matplotlib's ``Figure`` and ``FigureCanvasAgg`` classes, imported on first call
    (an :class:`ImportError` naming the ``plot`` extra when matplotlib is missing)."""
    try:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover - matplotlib is in the test extra
        raise ImportError(
            "adept_traj.viz.plots needs matplotlib: pip install 'adept-traj[plot]'"
        ) from exc
    return Figure, FigureCanvasAgg


def new_figure(width: float, height: float) -> Figure:
    """A new figure of ``width`` × ``height`` [inch] on its own Agg canvas (no pyplot, no
    backend switch, never shown)."""
    figure_class, canvas_class = load_matplotlib()
    fig = figure_class(figsize=(width, height), dpi=DPI)
    canvas_class(fig)
    return fig


def save_figure(fig: Figure, path: Path) -> Path:
    """Write ``fig`` as a PNG at its own resolution (:data:`DPI` for every figure of
    :func:`new_figure`) atomically (no half-written figure is left by a crash or Ctrl-C);
    return ``path``.

    The pixels are those ``savefig`` gives at that resolution; the file is encoded by
    ``adept_traj.viz.plots._png.write_png`` (rows unfiltered, RGB, zlib level
    :data:`PNG_COMPRESSION`: faster than Pillow, whose encoder tries five filters per
    row, and smaller files). No text
    chunks (no matplotlib version): the same figure gives the same bytes with any
    matplotlib release.
    """
    return write_png(fig, path, PNG_COMPRESSION)
