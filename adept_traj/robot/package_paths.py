"""Where the ``package://`` files of a URDF are: the folders searched and the ones used.

A URDF names its meshes ``package://<package>/<path>``; ROS finds ``<package>`` in the
folders of ``ROS_PACKAGE_PATH``. :func:`package_search_dirs` lists, in this order:

1. the folders given by the caller (``Robot.from_urdf(..., package_dirs=[...])``);
2. the folders of the ``ROS_PACKAGE_PATH`` environment variable;
3. the ``share`` folders of installed robot-data packages: every ``cmeel.prefix/share``
   under the Python path (where ``pip install example-robot-data`` puts
   ``example-robot-data/robots/...``).

:func:`resolve_package_uris` finds every ``package://`` file of a URDF in them, refuses a
missing one (naming the folders searched), and returns the folders actually used, which a
saved result records so that ``verify`` and ``show`` find the meshes again in a new shell.
"""

from __future__ import annotations

import os
import sys
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from pathlib import Path

from adept_traj.errors import RobotModelError

__all__ = [
    "installed_data_dirs",
    "package_search_dirs",
    "resolve_package_file",
    "resolve_package_uris",
]

_SCHEME = "package://"


def installed_data_dirs() -> tuple[Path, ...]:
    """The ``cmeel.prefix/share`` folders under the entries of ``sys.path`` (installed
    robot-data packages such as ``example-robot-data``), without repeats."""
    out: list[Path] = []
    for entry in sys.path:
        candidate = Path(entry or ".") / "cmeel.prefix" / "share"
        if candidate.is_dir() and candidate.resolve() not in out:
            out.append(candidate.resolve())
    return tuple(out)


def package_search_dirs(package_dirs: Iterable[str | Path] = ()) -> tuple[Path, ...]:
    """The folders searched for ``package://`` files, in order: ``package_dirs``, then
    ``ROS_PACKAGE_PATH``, then :func:`installed_data_dirs` (absolute, without repeats)."""
    given = [Path(p) for p in package_dirs]
    ros = [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
    out: list[Path] = []
    for folder in (*given, *ros, *installed_data_dirs()):
        folder = folder.resolve()
        if folder not in out:
            out.append(folder)
    return tuple(out)


def package_uris(root: ET.Element) -> tuple[str, ...]:
    """The ``package://`` file names of a URDF's ``<mesh>`` elements, in document order."""
    names = (m.get("filename", "") for m in root.iter("mesh"))
    return tuple(dict.fromkeys(n for n in names if n.startswith(_SCHEME)))


def resolve_package_file(uri: str, package_dirs: Iterable[str | Path] = ()) -> Path:
    """The file a ``package://pkg/rest`` URI names (the first searched folder holding it,
    see :func:`resolve_package_uris`); a URI without the scheme is returned as a path.

    Raises :class:`~adept_traj.errors.RobotModelError` when no searched folder holds it."""
    if not uri.startswith(_SCHEME):
        return Path(uri)
    search = package_search_dirs(package_dirs)
    package, _, rest = uri[len(_SCHEME) :].partition("/")
    for d in search:
        for candidate in (d / package / rest, d / rest if d.name == package else None):
            if candidate is not None and candidate.is_file():
                return candidate
    raise RobotModelError(
        f"'{uri}' not found in the package folders {[str(d) for d in search]}; give its "
        "package's parent folder with package_dirs (command line: --package-dir), set "
        "ROS_PACKAGE_PATH, or install the package that ships it"
    )


def resolve_package_uris(
    root: ET.Element, urdf: Path, package_dirs: Iterable[str | Path] = ()
) -> tuple[Path, ...]:
    """The folders (in search order) holding the ``package://`` files of the URDF whose
    parsed root is ``root`` (``urdf`` names it in messages).

    A URI ``package://pkg/rest`` is found in folder ``D`` when ``D/pkg/rest`` is a file
    (``D`` contains the package) or when ``D`` is the package itself (its name is ``pkg``
    and ``D/rest`` is a file).

    Raises
    ------
    RobotModelError
        A ``package://`` file found in no searched folder (the message names the folders
        and how to add one).
    """
    search = package_search_dirs(package_dirs)
    used: list[Path] = []
    for uri in package_uris(root):
        package, _, rest = uri[len(_SCHEME) :].partition("/")
        found = next(
            (
                d
                for d in search
                if (d / package / rest).is_file() or (d.name == package and (d / rest).is_file())
            ),
            None,
        )
        if found is None:
            raise RobotModelError(
                f"{urdf}: mesh '{uri}' not found in the package folders "
                f"{[str(d) for d in search]}; give its package's parent folder with "
                "Robot.from_urdf(..., package_dirs=[...]) (command line: --package-dir), set "
                "ROS_PACKAGE_PATH, or install the package that ships it"
            )
        if found not in used:
            used.append(found)
    return tuple(d for d in search if d in used)
