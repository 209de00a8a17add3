"""The two CSV files of a result folder and their agreement with ``result.json``.

- ``front.csv``: header ``z1,…,z6,feasible,x0,…,x{n_var−1}``; one row per solution of the
  front, ``feasible`` as ``1``/``0``.
- ``best_trajectory.csv``: header ``t, q_<joint>…, qd_<joint>…, qdd_<joint>…,
  qddd_<joint>…, tau_<joint>…, min_distance``; one row per dense sample of the certificate
  (units: s; rad | m; rad/s | m/s; rad/s² | m/s²; rad/s³ | m/s³; N·m | N; m).

Floats are written in Python's shortest round-trip form (``inf`` for an infinite distance),
so they read back exactly. On load, both files must have the expected header, row count and
values, the same as in ``result.json``; otherwise
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
    from adept_traj.results.record import PlanningResult

__all__ = [
    "check_front_csv",
    "check_trajectory_csv",
    "csv_text",
    "trajectory_header",
    "write_front_csv",
    "write_trajectory_csv",
]

#: Derivative prefixes of the joint columns of ``best_trajectory.csv``, in order.
_JOINT_PREFIXES = tuple(kind.quantity for kind in LIMITS)


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
    r:
        The :class:`~adept_traj.results.PlanningResult`.
    path:
        The file.

    Raises
    ------
    ResultFormatError
        Another header, row count or value (naming the row and column).
    """
    _check_csv(path, _front_header(r.front.x.shape[1]), _front_table(r))


# ============================================================================ best_trajectory.csv
def trajectory_header(names: Sequence[str]) -> list[str]:
    """The header of ``best_trajectory.csv``.

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


def _trajectory_table(r: PlanningResult) -> np.ndarray:
    """(n, 2 + 5·nq) the rows of ``best_trajectory.csv``."""
    d = r.certificate.dense
    return np.column_stack([d.t, d.q, d.qd, d.qdd, d.qddd, d.tau, d.min_distance])


def write_trajectory_csv(r: PlanningResult, path: Path) -> Path:
    """Write ``best_trajectory.csv`` of a result (atomically).

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
    text = csv_text(trajectory_header(r.robot.joint_names), _trajectory_table(r))
    return write_text_atomic(path, text)


def check_trajectory_csv(r: PlanningResult, path: Path) -> None:
    """Check that ``best_trajectory.csv`` agrees with a result read from ``result.json``.

    Parameters
    ----------
    r:
        The :class:`~adept_traj.results.PlanningResult`.
    path:
        The file.

    Raises
    ------
    ResultFormatError
        Another header, row count or value (naming the row and column).
    """
    _check_csv(path, trajectory_header(r.robot.joint_names), _trajectory_table(r))


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


def _check_csv(path: Path, header: list[str], expected: np.ndarray) -> None:
    """Check that the CSV file at ``path`` has ``header`` and the values of ``expected``
    (n, m), exactly; raise :class:`ResultFormatError` naming the first bad row and column."""
    rows = list(csv.reader(io.StringIO(read_text(path))))
    if not rows or rows[0] != header:
        got = rows[0] if rows else "nothing"
        raise ResultFormatError(path, "header", f"expected {','.join(header)}; got {got}")
    body = [row for row in rows[1:] if row]
    if len(body) != expected.shape[0]:
        raise ResultFormatError(
            path, None, f"expected {expected.shape[0]} data rows as in result.json; got {len(body)}"
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
    bad = np.isnan(values) | (values != expected)
    if bad.any():
        i, j = (int(k) for k in np.argwhere(bad)[0])
        raise ResultFormatError(
            path,
            f"row {i + 1}, column {header[j]}",
            f"{body[i][j]!r} is not the number in result.json ({float(expected[i, j])!r})",
        )


def _number(cell: str) -> float:
    """``float(cell)``, or NaN when the cell is not a number."""
    try:
        return float(cell)
    except ValueError:
        return math.nan
