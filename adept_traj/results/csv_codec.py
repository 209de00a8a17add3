"""The two CSV files of a result folder and their agreement with ``result.json``.

- ``front.csv``: header ``z1,…,z6,feasible,x0,…,x{n_var−1}``; one row per solution of the
  front, ``feasible`` as ``1``/``0``.
- ``best_trajectory.csv``: the best trade-off at a fixed step of 0.001 s, exactly from its
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
from typing import TYPE_CHECKING

import numpy as np

from adept_traj.errors import ResultFormatError
from adept_traj.files import write_text_atomic
from adept_traj.problem import OBJECTIVE_NAMES
from adept_traj.results.reader import read_text
from adept_traj.robot.limits import LIMITS

if TYPE_CHECKING:  # the record imports this module
    from adept_traj.results.fixed_step import FixedStepTrajectory
    from adept_traj.results.record import PlanningResult

__all__ = [
    "check_front_csv",
    "check_trajectory_csv",
    "csv_text",
    "trajectory_header",
    "write_front_csv",
    "write_trajectory_csv",
]

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


def write_front_csv(r: PlanningResult, path: Path) -> Path:
    """Write ``front.csv`` of a result (atomically).

    Parameters
    ----------
    r:
        The :class:`~adept_traj.results.PlanningResult`.
    path:
        The file.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    text = csv_text(_front_header(r.front.x.shape[1]), _front_table(r), [len(OBJECTIVE_NAMES)])
    return write_text_atomic(path, text)


def check_front_csv(r: PlanningResult, path: Path) -> None:
    """Check that ``front.csv`` agrees with a result read from ``result.json``.

    Parameters
    ----------
    r, path:
        As :func:`write_front_csv`.

    Raises
    ------
    ResultFormatError
        Another header, row count or value (naming the row and column).
    """
    _check_csv(path, _front_header(r.front.x.shape[1]), _front_table(r))


# ============================================================================ best_trajectory.csv
def _best_fixed_step(r: PlanningResult) -> FixedStepTrajectory:
    """What ``best_trajectory.csv`` holds: the best trade-off, certified or not, at the
    fixed step :func:`~adept_traj.results.fixed_step.file_step` (0.001 s)."""
    from adept_traj.results import fixed_step  # it needs the record, which imports this

    return fixed_step.sample_member(
        r, dt=fixed_step.file_step(float(r.best_x[0])), allow_uncertified=True
    )


def trajectory_header(names: Sequence[str]) -> list[str]:
    """The header of a ``best_trajectory.csv`` before issue #29 (the certificate's grid),
    still read by :func:`check_trajectory_csv` and written by the ROS-free grid exports.

    Parameters
    ----------
    names:
        The joint names.

    Returns
    -------
    list of str
        ``t``, ``q_<joint>`` … ``tau_<joint>``, ``min_distance``.
    """
    return ["t", *(f"{p}_{n}" for p in _JOINT_PREFIXES for n in names), "min_distance"]


def _legacy_trajectory_table(r: PlanningResult) -> np.ndarray:
    """(n, 2 + 5·nq) the rows of a ``best_trajectory.csv`` before issue #29."""
    d = r.certificate.dense
    return np.column_stack([d.t, d.q, d.qd, d.qdd, d.qddd, d.tau, d.min_distance])


def write_trajectory_csv(r: PlanningResult, path: Path) -> Path:
    """Write ``best_trajectory.csv`` of a result (atomically): the best trade-off at the
    fixed step of 0.001 s (:mod:`~adept_traj.results.fixed_step`).

    Parameters
    ----------
    r, path:
        As :func:`write_front_csv`.

    Returns
    -------
    pathlib.Path
        ``path``.
    """
    from adept_traj.results import fixed_step  # it needs the record, which imports this

    return write_text_atomic(path, fixed_step.csv_text(_best_fixed_step(r)))


def check_trajectory_csv(r: PlanningResult, path: Path) -> None:
    """Check that ``best_trajectory.csv`` agrees with a result read from ``result.json``:
    the fixed-step file with the best trade-off's spline (to :data:`_SAMPLE_RTOL`); a file
    of an earlier version (the certificate's grid) with ``result.json``'s dense samples,
    exactly. Its arguments and errors are those of :func:`check_front_csv`.
    """
    legacy = trajectory_header(r.robot.joint_names)
    text = read_text(path)
    if text.split("\n", 1)[0].rstrip("\r") == ",".join(legacy):
        _check_csv(path, legacy, _legacy_trajectory_table(r), text=text)
        return
    from adept_traj.results import fixed_step  # it needs the record, which imports this

    tr = _best_fixed_step(r)
    header = fixed_step.csv_header(tr.joint_names, tr.units)
    table = np.column_stack([tr.t, tr.q, tr.qd, tr.qdd])
    _check_csv(path, header, table, text=text, rtol=_SAMPLE_RTOL, source="the best move's spline")


# ============================================================================ both
def csv_text(header: list[str], rows: np.ndarray, int_columns: Sequence[int] = ()) -> str:
    """CSV text of a table, floats in their shortest round-trip form.

    Parameters
    ----------
    header:
        Column names.
    rows:
        (n, len(header)) values.
    int_columns:
        Columns written as integers.

    Returns
    -------
    str
        Header and rows, newline line ends.
    """
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
    rows = list(csv.reader(io.StringIO(read_text(path) if text is None else text)))
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
