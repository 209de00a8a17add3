"""The collector around heavy imports (:func:`adept_traj.frozen_imports.frozen_imports`),
checked in a fresh interpreter (a freeze would stay in the test process); ``main`` called
in-process freezes nothing."""

from __future__ import annotations

import gc
import json
import subprocess
import sys

from adept_traj.cli import main

_PROBE = """
import gc, json
from adept_traj.frozen_imports import frozen_imports
seen = {}
before = gc.get_freeze_count()
with frozen_imports():
    seen["on_inside"] = gc.isenabled()
    import fractions  # not imported yet: its objects are made in the block
seen["frozen"] = gc.get_freeze_count() - before
seen["on_after"] = gc.isenabled()
gc.disable()
try:
    with frozen_imports():
        raise KeyError("in the block")
except KeyError:
    seen["raised"] = True
seen["off_stays_off"] = not gc.isenabled()
gc.enable()
try:
    with frozen_imports():
        raise KeyError("in the block")
except KeyError:
    pass
seen["on_after_error"] = gc.isenabled()
print(json.dumps(seen))
"""


def test_imports_uncollected_then_frozen_and_the_collector_restored() -> None:
    done = subprocess.run(
        [sys.executable, "-c", _PROBE], capture_output=True, text=True, check=True, timeout=120
    )
    seen = json.loads(done.stdout)
    assert seen["on_inside"] is False
    assert seen["frozen"] > 100  # the module's objects and everything alive before
    assert seen["on_after"] is True
    assert seen["raised"] is True
    assert seen["off_stays_off"] is True
    assert seen["on_after_error"] is True


def test_main_called_in_process_freezes_nothing(tmp_path) -> None:
    before, enabled = gc.get_freeze_count(), gc.isenabled()
    assert main(["verify", str(tmp_path / "no-such-folder")]) == 2
    assert gc.get_freeze_count() == before
    assert gc.isenabled() is enabled
