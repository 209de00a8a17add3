"""The two CSV files of a result folder and their agreement with ``result.json``.

- ``front.csv``: header ``z1,…,z6,feasible,x0,…,x{n_var−1}``; one row per solution of the
  front, ``feasible`` as ``1``/``0``.
- ``best_trajectory.csv``: the best trade-off at a fixed step of 1 ms, exactly from its
  spline, the file ``adept-traj export DIR --format csv`` writes
  (:mod:`~adept_traj.results.fixed_step`): header ``t [s], q_<joint> [rad|m]…,
  qd_<joint> [rad/s|m/s]…, qdd_<joint> [rad/s^2|m/s^2]…``, rows t = 0, 0.001, …, the last
  at T. (Before issue #29 it held the certificate's grid, ⌈T·rate⌉ + 1 samples, with
  ``qddd``, ``tau`` and ``min_distance``: those stay in ``result.json``'s
  ``best_trajectory``, and such files of earlier versions still load.)

Floats are written in Python's shortest round-trip form (``inf`` for an infinite distance),
so they read back exactly. On load, both files must have the expected header, row count and
values: ``front.csv`` those of ``result.json``, exactly; ``best_trajectory.csv`` the best
trade-off's spline sampled again (to 1e-12 relative); otherwise
:class:`~adept_traj.errors.ResultFormatError` names the file and the field (``header``,
``row 2, column z2``). The schema is in ``docs/results.md``;
:meth:`~adept_traj.results.PlanningResult.save`,
:meth:`~adept_traj.results.PlanningResult.load` and
:func:`~adept_traj.results.to_csv` are the public entry points.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from adept_traj.errors import ResultFormatError
from adept_traj.files import write_text_atomic
from adept_traj.problem import OBJECTIVE_NAMES
from adept_traj.results.fixed_step import (
    FixedStepTrajectory,
    csv_header,
    csv_text,
    file_step,
    sample_member,
)
from adept_traj.results.reader import _read_text
from adept_traj.results.record import PlanningResult
from adept_traj.robot.limits import LIMITS

__all__: list[str] = []

#: Derivative prefixes of the joint columns of a ``best_trajectory.csv`` before issue #29.
_JOINT_PREFIXES = tuple(kind.quantity for kind in LIMITS)
#: Relative tolerance of the fixed-step file against its spline sampled again on load (the
#: same code on the same numbers: equal but for a machine's rounding of the matrix products).
_SAMPLE_RTOL = 1e-12


# ============================================================================ front.csv
def _front_header(n_var: int) -> list[str]:
    return [*OBJECTIVE_NAMES, "feasible", *(f"x{i}" for i in range(n_var))]


def _front_table(r: PlanningResult) -> np.ndarray:
    """(n, 7 + n_var) the rows of ``front.csv`` (feasible as 1.0 / 0.0)."""
    fr = r.front
    return np.column_stack([fr.objectives, fr.feasible.astype(float), fr.x])


def _write_front_csv(r: PlanningResult, path: Path) -> Path:
    text = _csv_text(_front_header(r.front.x.shape[1]), _front_table(r), [len(OBJECTIVE_NAMES)])
    return write_text_atomic(path, text)


def _check_front_csv(r: PlanningResult, path: Path) -> None:
    _check_csv(path, _front_header(r.front.x.shape[1]), _front_table(r))


# ============================================================================ best_trajectory.csv
def _best_fixed_step(r: PlanningResult) -> FixedStepTrajectory:
    """What ``best_trajectory.csv`` holds: the best trade-off, certified or not, at the
    fixed step :func:`~adept_traj.results.fixed_step.file_step` (1 ms)."""
    return sample_member(r, dt=file_step(float(r.best_x[0])), allow_uncertified=True)


def _write_trajectory_csv(r: PlanningResult, path: Path) -> Path:
    return write_text_atomic(path, csv_text(_best_fixed_step(r)))


def _legacy_trajectory_header(names: Sequence[str]) -> list[str]:
    """The header of ``best_trajectory.csv`` before issue #29: the certificate's grid."""
    return ["t", *(f"{p}_{n}" for p in _JOINT_PREFIXES for n in names), "min_distance"]


def _legacy_trajectory_table(r: PlanningResult) -> np.ndarray:
    """(n, 2 + 5·nq) the rows of a ``best_trajectory.csv`` before issue #29."""
    d = r.certificate.dense
    return np.column_stack([d.t, d.q, d.qd, d.qdd, d.qddd, d.tau, d.min_distance])


def _check_trajectory_csv(r: PlanningResult, path: Path) -> None:
    """The fixed-step file agrees with the best trade-off's spline (to
    :data:`_SAMPLE_RTOL`); a file of an earlier version (the certificate's grid) with
    ``result.json``'s dense samples, exactly."""
    legacy = _legacy_trajectory_header(r.robot.joint_names)
    text = _read_text(path)
    if text.split("\n", 1)[0].rstrip("\r") == ",".join(legacy):
        _check_csv(path, legacy, _legacy_trajectory_table(r), text=text)
        return
    tr = _best_fixed_step(r)
    header, table = (
        csv_header(tr.joint_names, tr.units),
        np.column_stack([tr.t, tr.q, tr.qd, tr.qdd]),
    )
    _check_csv(path, header, table, text=text, rtol=_SAMPLE_RTOL, source="the best move's spline")


# ============================================================================ both
def _csv_text(header: list[str], rows: np.ndarray, int_columns: Sequence[int] = ()) -> str:
    """The CSV text: ``header``, then ``rows`` as shortest round-trip floats (the
    ``int_columns`` as integers); ``\\n`` line ends."""
    lines = [",".join(header)]
    for row in rows.tolist():
        cells = [repr(float(v)) for v in row]
        for j in int_columns:
            cells[j] = str(int(row[j]))
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"


def _check_csv(
    path: Path,
    header: list[str],
    expected: np.ndarray,
    *,
    text: str | None = None,
    rtol: float = 0.0,
    source: str = "result.json",
) -> None:
    """Check that the CSV file at ``path`` (its ``text`` when already read) has ``header``
    and the values of ``expected`` (n, m): exactly (``rtol = 0``), else each within
    ``rtol · (1 + |expected|)``; raise :class:`ResultFormatError` naming the first bad row
    and column and ``source``, where the expected values come from."""
    rows = list(csv.reader(io.StringIO(_read_text(path) if text is None else text)))
    if not rows or rows[0] != header:
        got = rows[0] if rows else "nothing"
        raise ResultFormatError(path, "header", f"expected {','.join(header)}; got {got}")
    body = [row for row in rows[1:] if row]
    if len(body) != expected.shape[0]:
        raise ResultFormatError(
            path, None, f"expected {expected.shape[0]} data rows as in {source}; got {len(body)}"
        )
    widths = np.fromiter(map(len, body), dtype=int, count=len(body))
    short = np.flatnonzero(widths != len(header))
    if short.size:
        raise ResultFormatError(path, f"row {short[0] + 1}", f"expected {len(header)} columns")
    cells = np.array(body, dtype=str).reshape(expected.shape)
    try:
        values = cells.astype(float)
    except ValueError:  # a cell numpy does not read: read each as Python does (NaN if bad)
        values = np.vectorize(_number, otypes=[float])(cells)
    bad = np.isnan(values) | ~(np.abs(values - expected) <= rtol * (1.0 + np.abs(expected)))
    bad &= values != expected  # the same infinities
    if bad.any():
        i, j = (int(k) for k in np.argwhere(bad)[0])
        raise ResultFormatError(
            path,
            f"row {i + 1}, column {header[j]}",
            f"{body[i][j]!r} is not the number in {source} ({float(expected[i, j])!r})",
        )


def _number(cell: str) -> float:
    """``float(cell)``, or NaN when the cell is not a number."""
    try:
        return float(cell)
    except ValueError:
        return math.nan
