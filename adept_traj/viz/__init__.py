"""Visualisation of planning results: meshcat playback and plots.

================================  ==========================================================
:mod:`.playback`                  what is drawn and when: frames, poses, closest points
:mod:`.meshcat_scene`             drawing a playback into meshcat; the self-contained page
:mod:`.server`                    the live viewer on a local meshcat server (127.0.0.1)
:mod:`.plots`                     the paper's figures as PNG files (matplotlib)
================================  ==========================================================

The submodules are imported lazily, on first attribute access, so ``import adept_traj.viz``
imports neither meshcat nor matplotlib::

    from adept_traj import viz

    viz.meshcat_scene.static_html(result, "out/playback.html")  # imports meshcat here
    viz.plots.save_all(result, "out/figures")  # imports matplotlib here

"""

from __future__ import annotations

import importlib
from types import ModuleType
from typing import TYPE_CHECKING

__all__ = ["meshcat_scene", "playback", "plots", "server"]

if TYPE_CHECKING:  # pragma: no cover - for type checkers only
    from adept_traj.viz import meshcat_scene, playback, plots, server


def __getattr__(name: str) -> ModuleType:
    if name in __all__:
        module = importlib.import_module(f".{name}", __name__)
        globals()[name] = module
        return module
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
