"""meshcat, imported in one place for every module of :mod:`adept_traj.viz`.

The viewer modules take the parts of meshcat they use from here: its geometry, commands,
animation and paths, its message packer ``umsgpack``, and :class:`Recorder`, which draws
into a list of commands the way ``meshcat.Visualizer`` draws into a window. None of these
needs meshcat's viewer (``meshcat.visualizer``, ``meshcat.servers``), whose import
takes IPython, pyzmq and Pillow with it, several times the cost of the rest: a static
page (``playback.html``) is written without it. The live viewer (:mod:`adept_traj.viz.server`)
asks for it with :func:`viewer_modules`.

How: when this module is first imported and meshcat is not yet, the ``meshcat`` package
is registered without running its ``__init__`` (the one that imports the viewer), and its
parts above are imported from it. The first use of any other name of the package
(``meshcat.Visualizer``, ``from meshcat import Visualizer``, :func:`viewer_modules`) runs
that ``__init__`` then, in place: the package is then the one ``import meshcat`` gives, for
the caller's code as for ours. A meshcat imported before is used as it is.

meshcat 0.3.2 imports pyzmq's deprecated ``zmq.eventloop.ioloop``; its deprecation warning
is silenced here, once.
"""

from __future__ import annotations

import contextlib
import importlib.util
import sys
import warnings
from collections.abc import Iterator
from types import ModuleType
from typing import Any

import numpy as np

from adept_traj.errors import MeshcatServerError

__all__ = [
    "Animation",
    "AnimationFrameVisualizer",
    "MeshcatPath",
    "Recorder",
    "meshcat",
    "mg",
    "umsgpack",
    "viewer_modules",
]


@contextlib.contextmanager
def _quiet() -> Iterator[None]:
    """A context in which meshcat's import of ``zmq.eventloop.ioloop`` does not warn."""
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", "zmq.eventloop.ioloop is deprecated", DeprecationWarning)
        yield


def _package_without_viewer() -> ModuleType:
    """The ``meshcat`` package, registered in :data:`sys.modules` without its ``__init__``
    run (that is left to the first use of a name it defines); meshcat as it is if imported
    already."""
    if "meshcat" in sys.modules:
        return sys.modules["meshcat"]
    spec = importlib.util.find_spec("meshcat")
    if spec is None or spec.loader is None:
        raise ModuleNotFoundError("No module named 'meshcat'", name="meshcat")
    package = importlib.util.module_from_spec(spec)

    def rest_of_meshcat(name: str) -> Any:
        """The package's ``__getattr__`` until its ``__init__`` has run: a submodule not
        imported yet is imported (as ``from . import name`` inside meshcat asks), a probe
        such as ``__wrapped__`` is not found; any other name runs the ``__init__``, then
        is given."""
        if name.startswith("__"):
            raise AttributeError(f"module 'meshcat' has no attribute {name!r}")
        if name != "visualizer" and importlib.util.find_spec(f"meshcat.{name}") is not None:
            return importlib.import_module(f"meshcat.{name}")
        del package.__getattr__
        with _quiet():
            spec.loader.exec_module(package)
        return getattr(package, name)

    package.__getattr__ = rest_of_meshcat  # type: ignore[attr-defined]
    sys.modules["meshcat"] = package
    return package


def viewer_modules() -> tuple[ModuleType, type]:
    """meshcat as ``import meshcat`` gives it (its viewer imported), and its
    ``meshcat.visualizer.ViewerWindow``: for the live viewer."""
    with _quiet():
        import meshcat.visualizer as visualizer

        meshcat.Visualizer  # noqa: B018  (runs the package's __init__ if not yet)
    return meshcat, visualizer.ViewerWindow


meshcat = _package_without_viewer()
with _quiet():
    import meshcat.commands as commands
    import meshcat.geometry as mg
    import umsgpack
    from meshcat.animation import Animation, AnimationFrameVisualizer
    from meshcat.path import Path as MeshcatPath


class Recorder:
    """The part of ``meshcat.Visualizer`` that :func:`~adept_traj.viz.meshcat_scene.draw`
    uses, sending to a window that records (``window.send(command)``), with no viewer:
    ``recorder[path]`` (a recorder one level down), ``path``, and the same commands as
    meshcat's ``set_object``, ``set_transform``, ``set_property``, ``set_animation`` and
    ``delete`` build."""

    __slots__ = ("path", "window")

    def __init__(self, window: Any, path: MeshcatPath | None = None) -> None:
        if not callable(getattr(window, "send", None)):
            raise MeshcatServerError(f"a Recorder needs a window with send(); got {window!r}")
        self.window = window
        self.path = MeshcatPath(("meshcat",)) if path is None else path

    def __getitem__(self, path: str) -> Recorder:
        return Recorder(self.window, self.path.append(path))

    def set_object(self, geometry: Any, material: Any = None) -> None:
        self.window.send(commands.SetObject(geometry, material, self.path))

    def set_transform(self, matrix: np.ndarray | None = None) -> None:
        matrix = np.eye(4) if matrix is None else matrix
        self.window.send(commands.SetTransform(matrix, self.path))

    def set_property(self, key: str, value: Any) -> None:
        self.window.send(commands.SetProperty(key, value, self.path))

    def set_animation(
        self, animation: Animation, play: bool = True, repetitions: float = 1
    ) -> None:
        self.window.send(commands.SetAnimation(animation, play=play, repetitions=repetitions))

    def delete(self) -> None:
        self.window.send(commands.Delete(self.path))
