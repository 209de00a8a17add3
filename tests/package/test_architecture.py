"""The package's layout rules, read from the source: data flows one way between the
subpackages (docs/architecture.md), private names stay inside their module, and every
exception class lives in errors.py."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[2] / "adept_traj"

#: Rank of each subpackage in the data flow; a module may import its own subpackage and any
#: of lower rank. Equal ranks are siblings that must not import each other.
RANK = {
    "errors": 0, "data": 0, "urdf": 0, "lazy_names": 0, "frozen_imports": 0,
    "process_tree": 0.5,  # a process tree's threads and priority, for process_pool
    "validation": 1, "files": 1, "memory": 1, "process_pool": 1,
    "process_helper": 1.5,
    "work_ahead": 1.6,  # a Helper computing a value ahead at nice 19
    "transforms": 2, "schema": 2,
    "robot": 3,
    "scene": 4,
    "collision": 5,
    "problem": 6,
    "certification": 6.5,
    "analysis": 7,
    "results": 8,
    "certification.audit": 8.2,  # the audit behind verify reads a PlanningResult
    "export": 8.5,  # fixed-step exports of a result's members; used by viz's explorer
    "optimise": 9,
    "viz": 9,
    "testing": 10,
    "cycle": 10,
    "cli": 11,
}  # fmt: skip


def _modules() -> list[Path]:
    return sorted(p for p in PACKAGE.rglob("*.py") if "urdf" not in p.parts)


def _owner(path: Path) -> str:
    """The unit of :data:`RANK` a module belongs to: its subpackage (or top-level module),
    or ``"subpackage.module"`` where RANK names that module apart."""
    rel = path.relative_to(PACKAGE).with_suffix("")
    dotted = ".".join(rel.parts[:2])
    return dotted if dotted in RANK else rel.parts[0]


def _target(module: str) -> str | None:
    """The unit of :data:`RANK` that ``import adept_traj.a.b...`` imports (None for the
    package itself)."""
    parts = module.split(".")
    if len(parts) < 2:
        return None
    dotted = ".".join(parts[1:3])
    return dotted if dotted in RANK else parts[1]


def _imports(path: Path) -> list[tuple[str, list[str], int]]:
    """(module, imported names, line) of every ``adept_traj`` import, relative ones resolved."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    here = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = here[: len(here) - node.level]
                module = ".".join([*base, *(node.module.split(".") if node.module else [])])
            else:
                module = node.module or ""
            if module.split(".")[0] == "adept_traj":
                found.append((module, [a.name for a in node.names], node.lineno))
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "adept_traj":
                    found.append((alias.name, [], node.lineno))
    return found


def test_every_top_level_name_has_a_rank():
    names = {p.name.removesuffix(".py") for p in PACKAGE.iterdir() if not p.name.startswith("_")}
    names -= {"__pycache__"}
    assert names <= set(RANK), sorted(names - set(RANK))


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_imports_flow_one_way(path: Path):
    owner = _owner(path)
    if owner == "__init__":
        return  # the top-level package re-exports the public API
    for module, names, line in _imports(path):
        target = _target(module)
        # "from adept_traj import X": X is a subpackage or module
        targets = names if target is None else [target]
        for t in targets:
            if t == owner or t == "__version__":
                continue
            assert t in RANK, f"{path.name}:{line} imports unknown adept_traj.{t}"
            assert RANK[t] < RANK[owner], (
                f"{path.relative_to(PACKAGE)}:{line} imports adept_traj.{t} "
                f"(rank {RANK[t]}) from {owner} (rank {RANK[owner]}): data flows one way"
            )


#: The parts of optimise/, in the same one-way order: a module of optimise/ imports its own
#: part and parts of lower rank only (pymoo's operators know nothing of the search, the
#: search nothing of the local solver, neither of the worker processes beside plan()).
OPTIMISE_RANK = {
    "operators": 0, "search": 1, "local": 2, "parallel": 3, "planner": 4, "__init__": 5,
}  # fmt: skip


def _optimise_part(dotted: str) -> str:
    return dotted.split(".")[2].removesuffix(".py")


@pytest.mark.parametrize(
    "path",
    sorted((PACKAGE / "optimise").rglob("*.py")),
    ids=lambda p: str(p.relative_to(PACKAGE)),
)
def test_optimise_parts_flow_one_way(path: Path):
    """Every module of optimise/ sits in one of its parts (a new module goes into the part
    that says what it holds), and imports only from its part and lower ones."""
    rel = path.relative_to(PACKAGE / "optimise")
    part = rel.parts[0].removesuffix(".py")
    assert part in OPTIMISE_RANK, f"optimise/{rel} is in none of {sorted(OPTIMISE_RANK)}"
    for module, _, line in _imports(path):
        if not module.startswith("adept_traj.optimise.") or len(module.split(".")) < 3:
            continue
        target = _optimise_part(module)
        assert target in OPTIMISE_RANK, f"optimise/{rel}:{line} imports {module}"
        if part != "__init__" and target != part:
            assert OPTIMISE_RANK[target] < OPTIMISE_RANK[part], (
                f"optimise/{rel}:{line} imports {module} ({target}, rank "
                f"{OPTIMISE_RANK[target]}) from {part} (rank {OPTIMISE_RANK[part]})"
            )


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_private_names_stay_in_their_subpackage(path: Path):
    owner = path.relative_to(PACKAGE).parts[0].removesuffix(".py")
    for module, names, line in _imports(path):
        parts = module.split(".")
        target = parts[1] if len(parts) > 1 else owner
        private = [n for n in names if n.startswith("_") and n != "__version__"]
        private_module = any(p.startswith("_") for p in parts[1:])
        if target != owner:
            where = f"{path.relative_to(PACKAGE)}:{line}"
            assert not private, f"{where} imports private names {private} from {module}"
            assert not private_module, f"{where} imports the private module {module}"


def _is_private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def private_names_used(path: Path, package: Path) -> list[str]:
    """Every private name (``_x``, not a dunder) that the module at ``path`` takes from
    another module of ``package``: ``from M import _x`` (also relative), and ``m._x`` on a
    name ``m`` bound to a module of the package (``import a.b as m``, ``from a import b``).
    A private *module* of the importer's own subpackage may be imported (``from . import
    _heap``): it is that subpackage's."""
    root = package.parent
    here = list(path.relative_to(root).with_suffix("").parts)
    me = ".".join(here).removesuffix(".__init__")

    def is_module(dotted: str) -> bool:
        base = root.joinpath(*dotted.split("."))
        return base.with_suffix(".py").is_file() or (base / "__init__.py").is_file()

    def subpackage(dotted: str) -> str:
        parts = dotted.split(".")
        return parts[1] if len(parts) > 2 else ""  # "" for the top-level modules

    tree = ast.parse(path.read_text(encoding="utf-8"))
    modules: dict[str, str] = {}  # local name → module it is bound to
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = here[: len(here) - node.level]
                module = ".".join([*base, *(node.module.split(".") if node.module else [])])
            else:
                module = node.module or ""
            if module.split(".")[0] != package.name:
                continue
            for alias in node.names:
                target = f"{module}.{alias.name}"
                if is_module(target):
                    modules[alias.asname or alias.name] = target
                    own = subpackage(target) == subpackage(me) and subpackage(me)
                    if _is_private(alias.name) and not own:
                        found.append(f"{node.lineno}: from {module} import {alias.name}")
                elif _is_private(alias.name) and module != me:
                    found.append(f"{node.lineno}: from {module} import {alias.name}")
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == package.name and alias.asname:
                    modules[alias.asname] = alias.name
    for node in ast.walk(tree):
        if (
            isinstance(node, ast.Attribute)
            and isinstance(node.value, ast.Name)
            and node.value.id in modules
            and _is_private(node.attr)
            and modules[node.value.id] != me
        ):
            found.append(f"{node.lineno}: {node.value.id}.{node.attr} ({modules[node.value.id]})")
    return found


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_no_private_name_is_taken_from_another_module(path: Path):
    """What another module needs is public in its subpackage (documented), or the two are
    one module."""
    rel = str(path.relative_to(PACKAGE))
    found = private_names_used(path, PACKAGE)
    assert not found, f"{rel} takes private names of other modules: {found}"


def test_the_private_name_check_finds_each_form(tmp_path: Path):
    """The check above on a made-up package: each form of a private name taken across
    modules is found, and what is allowed is not."""
    pkg = tmp_path / "adept_traj"
    (pkg / "sub").mkdir(parents=True)
    for name in ("__init__.py", "sub/__init__.py", "sub/_hidden.py", "sub/other.py", "top.py"):
        (pkg / name).write_text("", encoding="utf-8")
    (pkg / "sub" / "mine.py").write_text(
        "from adept_traj.sub.other import _a, public\n"  # found
        "from .other import _b\n"  # found
        "import adept_traj.sub.other as other_module\n"
        "from adept_traj.sub import other\n"
        "from . import _hidden\n"  # allowed: a private module of its own subpackage
        "from adept_traj.sub.other import __version__\n"  # allowed: a dunder
        "x = other_module._c + other._d + other.e + _hidden.f\n"  # _c, _d found
        "def _own():\n    return _own\n",  # allowed: its own private name
        encoding="utf-8",
    )
    (pkg / "top.py").write_text("from adept_traj.sub import _hidden\n", encoding="utf-8")
    found = private_names_used(pkg / "sub" / "mine.py", pkg)
    assert [f.split(": ", 1)[1] for f in found] == [
        "from adept_traj.sub.other import _a",
        "from adept_traj.sub.other import _b",
        "other_module._c (adept_traj.sub.other)",
        "other._d (adept_traj.sub.other)",
    ]
    # a private module of another subpackage (here: of sub, from the top level) is found
    assert private_names_used(pkg / "top.py", pkg) == ["1: from adept_traj.sub import _hidden"]


#: Private names of pymoo's operator and algorithm protocol: adept_traj's subclasses
#: override them and call them on pymoo's objects (checked to exist on pymoo's classes).
PYMOO_PROTOCOL = {
    "_do": "pymoo.core.operator.Operator",
    "_initialize": "pymoo.core.algorithm.Algorithm",
    "_set_optimum": "pymoo.core.algorithm.Algorithm",
}


def _defined_names(tree: ast.AST) -> set[str]:
    """Names a module defines: functions, classes, assigned names and attributes (``x._a =
    ...``, ``setattr(x, "_a", ...)``, ``object.__setattr__(x, "_a", ...)``)."""
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.arg):
            names.add(node.arg)
        elif isinstance(node, ast.Call) and len(node.args) >= 2:
            func = node.func
            setter = (isinstance(func, ast.Name) and func.id == "setattr") or (
                isinstance(func, ast.Attribute) and func.attr == "__setattr__"
            )
            name = node.args[1]
            if setter and isinstance(name, ast.Constant) and isinstance(name.value, str):
                names.add(name.value)
    return names


def private_attributes_used(paths: list[Path]) -> list[str]:
    """Every ``obj._name`` (not on ``self`` or ``cls``) in one of ``paths`` where ``_name``
    is not defined in that module but is defined in another one: a private method or
    attribute used across modules. pymoo's protocol names (:data:`PYMOO_PROTOCOL`) aside."""
    trees = {path: ast.parse(path.read_text(encoding="utf-8")) for path in paths}
    defined = {path: _defined_names(tree) for path, tree in trees.items()}
    found = []
    for path, tree in trees.items():
        for node in ast.walk(tree):
            if not (isinstance(node, ast.Attribute) and _is_private(node.attr)):
                continue
            if isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"):
                continue
            if node.attr in defined[path] or node.attr in PYMOO_PROTOCOL:
                continue
            owners = sorted(p.name for p, names in defined.items() if node.attr in names)
            if owners:
                found.append(f"{path.name}:{node.lineno}: {ast.unparse(node)} ({owners})")
    return found


def test_no_private_method_or_attribute_is_used_from_another_module():
    """``checker._narrow(...)`` in another module: what another module calls is public
    (documented), or the caller moves into the module."""
    found = private_attributes_used(_modules())
    assert not found, found


def test_pymoo_protocol_names_are_pymoo_s():
    import importlib

    for name, owner in PYMOO_PROTOCOL.items():
        module, _, cls = owner.rpartition(".")
        assert hasattr(getattr(importlib.import_module(module), cls), name), (name, owner)


def test_the_private_attribute_check_finds_each_form(tmp_path: Path):
    """The check above on made-up modules: another module's private method or attribute is
    found, on any object but ``self``; a module's own, stdlib's and pymoo's are not."""
    (tmp_path / "checker.py").write_text(
        "class Checker:\n"
        "    def __init__(self):\n        self._broad = 1\n"
        "        object.__setattr__(self, '_rates', 2)\n"
        "    def _narrow(self):\n        return self._broad\n",
        encoding="utf-8",
    )
    (tmp_path / "user.py").write_text(
        "import os\n"
        "def f(checker, op):\n"
        "    a = checker._narrow()\n"  # found
        "    b = checker._broad + checker._rates\n"  # both found
        "    op._do(None)\n"  # pymoo's protocol: allowed
        "    os._exit(0)\n"  # not the package's: allowed
        "    return a, b\n",
        encoding="utf-8",
    )
    found = private_attributes_used([tmp_path / "checker.py", tmp_path / "user.py"])
    assert [f.split(": ", 1)[1] for f in found] == [
        "checker._narrow (['checker.py'])",
        "checker._broad (['checker.py'])",
        "checker._rates (['checker.py'])",
    ]


def test_every_exception_class_is_in_errors_py():
    elsewhere = []
    for path in _modules():
        if path.name == "errors.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ClassDef) and any(
                (isinstance(b, ast.Name) and (b.id.endswith(("Error", "Exception", "Interrupted"))))
                or (isinstance(b, ast.Attribute) and b.attr.endswith(("Error", "Exception")))
                for b in node.bases
            ):
                elsewhere.append(f"{path.relative_to(PACKAGE)}:{node.lineno} {node.name}")
    assert not elsewhere, elsewhere


def test_every_subpackage_ships_in_the_wheel():
    """pyproject.toml lists every package folder (a missing one is left out of the wheel:
    `pip install .` then fails where an editable install works)."""
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib

    pyproject = tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text(encoding="utf-8"))
    listed = set(pyproject["tool"]["setuptools"]["packages"])
    folders = {
        ".".join(p.parent.relative_to(PACKAGE.parent).parts) for p in PACKAGE.rglob("__init__.py")
    }
    assert folders <= listed, sorted(folders - listed)


def test_every_exception_class_is_defined_in_errors_py():
    """Imported, not read: any class of the package deriving from BaseException or Warning
    (directly or not) is defined in adept_traj.errors."""
    import importlib
    import inspect

    elsewhere = []
    for path in _modules():
        if path.name == "__main__.py":  # runs the command when imported
            continue
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        name = ".".join(rel.parts).removesuffix(".__init__")
        module = importlib.import_module(name)
        for obj in vars(module).values():
            if (
                inspect.isclass(obj)
                and issubclass(obj, (BaseException, Warning))
                and obj.__module__.startswith("adept_traj")
                and obj.__module__ != "adept_traj.errors"
            ):
                elsewhere.append(f"{obj.__module__}.{obj.__qualname__}")
    assert not elsewhere, sorted(set(elsewhere))


#: Modules allowed past the 400-line target, with the reason (a split would cut a concept).
LONG_MODULES = {
    "problem/bspline.py": "BSplineTrajectory's public methods, half of it docstrings and math",
    "schema.py": "the one reader of three file formats (Node and its typed accessors)",
    "collision/broad_phase.py": "the conservative bounds of every shape pair, one algorithm",
    "collision/checker.py": "CollisionChecker, the one face of the distances over every "
    "obstacle kind (broad phase, views, clouds, coal), half of it docstrings",
    "optimise/planner.py": "plan(): the one pipeline from the search to the certified result "
    "(its checkpoint fingerprint, history and front), half of it docstrings",
    "scene/scene_file.py": "the reader and writer of every scene-file table (its mesh, cloud, "
    "motion and robot entries are in machine_entries)",
    "scene/motion_laws.py": "the MotionLaw contract (pose, speed bound, jumps) and the paper's "
    "pendulum, half of it docstrings",
    "certification/certificate.py": "certify, its Certificate record and the certificate of dense "
    "states already computed (member certificates share it), half of it docstrings",
    "problem/spline_segments.py": "the per-segment arithmetic behind BSplineTrajectory (basis, "
    "samples, exact extrema and integrals), half of it docstrings and math",
    "results/json_codec.py": "the one encoder and decoder of result.json (its certificates in "
    "certificate_codec, JSON values in json_values)",
    "robot/robot.py": "Robot: construction, its frozen copy (replace) and the batched dynamics, "
    "kinematics and manipulability, half of it docstrings",
    "process_pool.py": "the one process mechanism: the caller's side (Worker) and the "
    "worker's (its start, Channel, parent death, error transport), half of it docstrings",
}


def test_modules_are_small():
    """One concept per module: ≲ 400 lines, except the few listed with their reason, and
    none past 460. A numpy section's underline (a line of dashes) is layout, not content:
    it is not counted (issue #27 made every docstring numpy)."""
    long = {}
    for path in _modules():
        lines = path.read_text(encoding="utf-8").splitlines()
        n = sum(1 for line in lines if not re.fullmatch(r"\s*-{3,}\s*", line))
        rel = str(path.relative_to(PACKAGE))
        if n > 460 or (n > 400 and rel not in LONG_MODULES):
            long[rel] = n
    assert not long, long


def test_tests_are_grouped_by_subsystem():
    """Every test file sits in a folder of tests/ named after a subsystem (none at the top),
    and every such folder is a package, so that two test files may share a name."""
    tests = PACKAGE.parent / "tests"
    assert sorted(p.name for p in tests.glob("test_*.py")) == []
    folders = {p.parent for p in tests.rglob("test_*.py")}
    assert all((folder / "__init__.py").is_file() for folder in folders | {tests}), sorted(
        str(f.relative_to(tests)) for f in folders if not (f / "__init__.py").is_file()
    )
