"""The local Dask cluster of ``adept-traj cycle``: its workers are the command's own
processes and keep their heap as the command does (issue #25: Dask's 64 KiB trim
threshold made them page-fault freed memory back in)."""

from __future__ import annotations

import os

import pytest

from adept_traj.cycle import dask_client
from adept_traj.problem import heap_environment


def _malloc_environment() -> dict[str, str | None]:
    return {k: os.environ.get(k) for k in ("MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_")}


def test_local_workers_keep_their_heap_and_dask_s_other_settings(monkeypatch) -> None:
    """(A user's own ``MALLOC_*_`` variables would win, as Dask's nanny lets them: so would
    those an earlier nanny in this process left, hence they are cleared here.)"""
    pytest.importorskip("distributed")
    for name in heap_environment():
        monkeypatch.delenv(name, raising=False)
    with dask_client(2, None, 2) as client:
        found = client.run(_malloc_environment)
        threads = client.run(lambda: os.environ.get("OPENBLAS_NUM_THREADS"))
    kept = {"MALLOC_MMAP_THRESHOLD_": "33554432", "MALLOC_TRIM_THRESHOLD_": "536870912"}
    assert len(found) == 2
    assert all(env == kept for env in found.values())  # 32 MiB and 512 MiB
    assert heap_environment() == kept
    assert set(threads.values()) == {"1"}  # Dask's one BLAS thread per worker is kept
