"""lazy_names: a package's names imported on first use from the module that holds them,
then kept in its namespace; a name not served is an AttributeError."""

from __future__ import annotations

import subprocess
import sys
import types

import pytest

from adept_traj.lazy_names import lazy_names


@pytest.fixture
def package(monkeypatch: pytest.MonkeyPatch) -> types.ModuleType:
    """An empty package registered under a name of its own."""
    module = types.ModuleType("lazy_names_probe")
    monkeypatch.setitem(sys.modules, module.__name__, module)
    return module


def test_a_mapped_name_is_imported_once_and_kept(package) -> None:
    import json.decoder

    package.__getattr__ = lazy_names(package.__name__, {"JSONDecoder": "json.decoder"})
    assert "JSONDecoder" not in vars(package)
    assert package.JSONDecoder is json.decoder.JSONDecoder
    assert vars(package)["JSONDecoder"] is json.decoder.JSONDecoder  # no second look-up
    with pytest.raises(AttributeError, match="module 'lazy_names_probe' has no attribute 'x'"):
        package.x  # noqa: B018


def test_a_module_serves_the_names_of_its_all_only(package) -> None:
    import shutil

    assert "copyfile" in shutil.__all__
    assert "os" not in shutil.__all__
    package.__getattr__ = lazy_names(package.__name__, "shutil")
    assert package.copyfile is shutil.copyfile
    with pytest.raises(AttributeError, match="no attribute 'os'"):
        package.os  # noqa: B018


def test_the_moved_names_are_found_where_they_were() -> None:
    import adept_traj.analysis
    import adept_traj.certification
    import adept_traj.certification.audit
    import adept_traj.certification.mismatches
    import adept_traj.results

    assert adept_traj.analysis.certify is adept_traj.certification.certify
    assert adept_traj.results.audit is adept_traj.certification.audit.audit
    assert adept_traj.results.AUDIT_RTOL == adept_traj.certification.mismatches.AUDIT_RTOL
    with pytest.raises(AttributeError):
        adept_traj.results.certify  # noqa: B018  (moved to certification, not from results)


def _fresh_python(code: str) -> list[str]:
    """The lines ``code`` prints in a new interpreter (nothing imported before it)."""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


def test_every_name_of_optimise_resolves_and_the_time_optimal_names_import_no_search() -> None:
    code = (
        "import sys\n"
        "from adept_traj.optimise import ALGORITHMS, POLISH_MODES, TIME_OPTIMAL, RunState\n"
        "heavy = ('moocore', 'pymoo.algorithms', 'pymoo.util.nds',"
        " 'adept_traj.optimise.search.loop')\n"
        "print(sorted(m for m in sys.modules if m.startswith(heavy)))\n"
        "import adept_traj.optimise as o\n"
        "missing = [n for n in o.__all__ if getattr(o, n, None) is None]\n"
        "print(len(o.__all__), missing)\n"
    )
    light, resolved = _fresh_python(code)
    assert light == "[]"
    count, missing = resolved.split(" ", 1)
    assert int(count) > 90
    assert missing == "[]"


def test_public_names_reads_a_modules_all_without_importing_it() -> None:
    import importlib

    from adept_traj.lazy_names import public_names

    code = (
        "import sys\n"
        "from adept_traj.lazy_names import public_names\n"
        "print(public_names('adept_traj.optimise.search.checkpoint'))\n"
        "print('adept_traj.optimise.search.checkpoint' in sys.modules)\n"
    )
    names, imported = _fresh_python(code)
    checkpoint = importlib.import_module("adept_traj.optimise.search.checkpoint")
    assert names == repr(list(checkpoint.__all__))
    assert imported == "False"
    assert public_names("json.decoder") == list(importlib.import_module("json.decoder").__all__)


def test_optimise_serves_every_name_of_its_whole_modules() -> None:
    import importlib

    import adept_traj.optimise as optimise

    for module in (
        "adept_traj.optimise.local.polish_modes",
        "adept_traj.optimise.local.weighted_move",
        "adept_traj.optimise.search.checkpoint",
        "adept_traj.optimise.operators.tournament",
    ):
        holder = importlib.import_module(module)
        for name in holder.__all__:
            assert name in optimise.__all__, (module, name)
            assert getattr(optimise, name) is getattr(holder, name), (module, name)


def test_public_names_refuses_a_module_without_a_literal_all(tmp_path, monkeypatch) -> None:
    from adept_traj.lazy_names import public_names

    (tmp_path / "computed_all_probe.py").write_text("__all__ = sorted(['a', 'b'])\n")
    (tmp_path / "no_all_probe.py").write_text("x = 1\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    for name in ("computed_all_probe", "no_all_probe"):
        with pytest.raises(ImportError, match=f"module '{name}' has no literal __all__"):
            public_names(name)
    with pytest.raises(ImportError, match="no Python source file for module 'no_such_probe'"):
        public_names("no_such_probe")
