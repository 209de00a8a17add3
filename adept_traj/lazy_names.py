"""Names a package imports on first use (PEP 562): :func:`lazy_names` makes the package's
``__getattr__``.

``import adept_traj`` loads none of pinocchio, coal, pymoo or scipy before a name that needs
them is used (its public names live in the modules that hold them), and the names that
moved to another subpackage are still found where they were (``adept_traj.analysis``'s
certificate names, ``adept_traj.results``'s audit names): each is imported from the module
that holds it when it is first asked for, then kept in the package's namespace.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["lazy_names"]


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
