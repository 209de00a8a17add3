"""Names a package imports on first use (PEP 562): :func:`lazy_names` makes the package's
``__getattr__``.

``import adept_traj`` loads none of pinocchio, coal, pymoo or scipy before a name that needs
them is used (its public names live in the modules that hold them), and the names that
moved to another subpackage are still found where they were (``adept_traj.analysis``'s
certificate names, ``adept_traj.results``'s audit names): each is imported from the module
that holds it when it is first asked for, then kept in the package's namespace.

Where a package serves every public name of a module, :func:`public_names` reads them from
the module's own ``__all__`` (its source, not imported): the module is their one list.
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import re
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

__all__ = ["lazy_names", "public_names"]


def lazy_names(package: str, where: Mapping[str, str] | str) -> Callable[[str], Any]:
    """The ``__getattr__`` of ``package`` that imports a name on first use.

    Parameters
    ----------
    package:
        The package's ``__name__``.
    where:
        Each name served and the module that holds it; or one module, all of whose
        ``__all__`` names are served.

    Returns
    -------
    Callable
        ``__getattr__(name)``: the name's value, imported and then kept in the package's
        namespace; :class:`AttributeError` for a name not served.
    """

    def __getattr__(name: str) -> Any:
        module = where if isinstance(where, str) else where.get(name)
        if module is not None:
            holder = importlib.import_module(module)
            if not isinstance(where, str) or name in holder.__all__:
                value = getattr(holder, name)
                setattr(sys.modules[package], name, value)
                return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__


def public_names(module: str) -> list[str]:
    """The names of ``module``'s ``__all__``, read from its source file without importing
    the module (its parent packages are imported, as by any import of it).

    Parameters
    ----------
    module:
        The module's full name; its ``__all__`` must be assigned at the top level as a
        literal list or tuple of strings (``__all__ = [...]``).

    Returns
    -------
    list of str
        The names, in the order of the source.

    Raises
    ------
    ImportError
        No such module, no source file, or no literal ``__all__`` in it.
    """
    parent, _, leaf = module.rpartition(".")
    folders = getattr(importlib.import_module(parent), "__path__", []) if parent else sys.path
    files = [Path(folder, f"{leaf}.py") for folder in folders]
    found = next((file for file in files if file.is_file()), None)
    if found is None:  # e.g. a module without source: its spec says where it is
        spec = importlib.util.find_spec(module)
        if spec is None or spec.origin is None or not spec.origin.endswith(".py"):
            raise ImportError(f"no Python source file for module {module!r}")
        found = Path(spec.origin)
    source = found.read_text(encoding="utf-8")
    start = re.search(r"^__all__ = ([\[(])", source, re.MULTILINE)
    closer = None if start is None else {"[": "]", "(": ")"}[start.group(1)]
    end = -1 if closer is None else source.find(closer, start.end())  # names hold neither
    try:
        names = ast.literal_eval(source[start.start(1) : end + 1]) if end >= 0 else None
    except (ValueError, SyntaxError):
        names = None
    if not isinstance(names, list | tuple) or not all(isinstance(n, str) for n in names):
        raise ImportError(f"module {module!r} has no literal __all__ = [...] at the top level")
    return list(names)
