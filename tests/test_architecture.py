"""The package's layout rules, read from the source: data flows one way between the
subpackages (docs/architecture.md), private names stay inside their subpackage, and every
exception class lives in errors.py."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "adept_traj"

#: Rank of each subpackage in the data flow; a module may import its own subpackage and any
#: of lower rank. Equal ranks are siblings that must not import each other.
RANK = {
    "errors": 0, "data": 0, "urdf": 0,
    "validation": 1, "files": 1, "memory": 1, "process_pool": 1,
    "transforms": 2, "schema": 2,
    "robot": 3,
    "scene": 4,
    "collision": 5,
    "problem": 6,
    "analysis": 7,
    "results": 8,
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
    rel = path.relative_to(PACKAGE)
    return rel.parts[0].removesuffix(".py")


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
        parts = module.split(".")
        target = parts[1] if len(parts) > 1 else None
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


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE)))
def test_private_names_stay_in_their_subpackage(path: Path):
    owner = _owner(path)
    for module, names, line in _imports(path):
        parts = module.split(".")
        target = parts[1] if len(parts) > 1 else owner
        private = [n for n in names if n.startswith("_") and n != "__version__"]
        private_module = any(p.startswith("_") for p in parts[1:])
        if target != owner:
            where = f"{path.relative_to(PACKAGE)}:{line}"
            assert not private, f"{where} imports private names {private} from {module}"
            assert not private_module, f"{where} imports the private module {module}"


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
    "scene/scene_file.py": "the reader and writer of every scene-file table (its mesh, cloud, "
    "motion and robot entries are in machine_entries)",
    "scene/motion_laws.py": "the MotionLaw contract (pose, speed bound, jumps) and the paper's "
    "pendulum, half of it docstrings",
    "process_pool.py": "the one process mechanism: the caller's side (Worker) and the "
    "worker's (its start, Channel, parent death, error transport), half of it docstrings",
}


def test_modules_are_small():
    """One concept per module: ≲ 400 lines, except the few listed with their reason, and
    none past 460."""
    long = {}
    for path in _modules():
        n = len(path.read_text(encoding="utf-8").splitlines())
        rel = str(path.relative_to(PACKAGE))
        if n > 460 or (n > 400 and rel not in LONG_MODULES):
            long[rel] = n
    assert not long, long
