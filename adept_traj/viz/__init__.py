"""Visualisation of planning results: meshcat playback (:mod:`.meshcat_view`) and plots
(:mod:`.plots`).

The submodules are imported lazily, on first attribute access, so ``import adept_traj.viz``
imports neither meshcat nor matplotlib::

    from adept_traj import viz

    viz.meshcat_view.static_html(result, "out/playback.html")  # imports meshcat here
"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import TYPE_CHECKING

__all__ = ["meshcat_view", "plots"]

if TYPE_CHECKING:  # pragma: no cover - for type checkers only
    from adept_traj.viz import meshcat_view, plots


def __getattr__(name: str) -> ModuleType:
    if name in __all__:
        module = importlib.import_module(f".{name}", __name__)
        globals()[name] = module
        return module
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
