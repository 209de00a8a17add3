"""``adept-traj front DIR``: list the members of a saved front, to pick one.

One row per member of ``result.front``: its index (the ``N`` of ``show --member N`` and
of :func:`~adept_traj.results.to_ros_joint_trajectory`'s ``member=N``), the travel time
``T`` [s], the objectives z2…z6 (units in the header, see
:mod:`adept_traj.problem.objectives`), the combined objective ``f_c`` (lower is better)
and the average fitness ``F_avg`` (higher is better) of
:func:`~adept_traj.analysis.best_tradeoff` with ``--weights`` (default: the paper's),
whether the member is certified, and its minimum clearance [m] from its certificate
(``result.json`` version 2 stores one per certified member; ``-``: not certified, or a
version-1 file, which holds the best trade-off's only). A clearance shown as ``≥ d`` is a
lower bound: the member stays farther than ``margin + 0.01 m`` from everything, where its
certificate keeps the broad phase's bounds (:mod:`adept_traj.certification.member_certificate`).
The best trade-off (``result.best.index``) is marked ``*``; its clearance is always exact.
The last two columns are the member's gaps: ``T`` over the kinematic lower bound
(``result.lower_bound.T_min``) and over T_best (``result.metrics.t_best``, the best T the
local solver reached in the run; ``-``: not computed).

``certified`` is ``front.feasible`` when :func:`~adept_traj.plan` certified every member
(``front.n_certified`` set). A result saved before that (``n_certified`` absent, e.g.
``result.json`` v1) only certified its best trade-off: the other members show ``no`` and
a note says that their ``feasible`` flag was the optimiser's verdict at its samples.

Rows are sorted by the best trade-off first (default, ``--sort tradeoff``): the result's
best trade-off, then the certified members in the order of
:func:`~adept_traj.analysis.best_tradeoff` with ``--weights``, then the uncertified ones in
that order; or by ``--sort COLUMN``, ascending unless ``--descending``; ties keep the index
order. A reader that stops early (``adept-traj front DIR | head``) ends the listing
quietly (exit status 0). Reads ``result.json`` only: nothing is
recomputed, no robot file is loaded.
"""

from __future__ import annotations

import argparse
import os
import sys

import numpy as np

from adept_traj.analysis import PAPER_WEIGHTS, best_tradeoff
from adept_traj.cli import status
from adept_traj.cli.arguments import floats
from adept_traj.cli.result_options import add_result_folder
from adept_traj.errors import InvalidInputError
from adept_traj.results import PlanningResult, certified_members

__all__ = ["COLUMNS", "TRADEOFF", "add_parser", "front_table", "run"]

#: The sort key of the default listing: the best trade-off first (module docstring).
TRADEOFF = "tradeoff"

#: The columns of the listing, in order, with their units (``-``: dimensionless; ``""``:
#: no unit shown, ``index`` and ``certified``, which is ``yes`` or ``no``).
COLUMNS: dict[str, str] = {
    "index": "",
    "T": "s",
    "z2": "N²·m²·s",
    "z3": "-",
    "z4": "m²",
    "z5": "rad²/s⁵",
    "z6": "rad²/s³",
    "f_c": "-",
    "F_avg": "-",
    "certified": "",
    "clearance": "m",
    "T/T_lb": "-",
    "T/T_best": "-",
}


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``front`` and its options."""
    p = sub.add_parser("front", help="list the members of a saved front (to pick one)")
    add_result_folder(p)
    p.add_argument(
        "--sort",
        default=TRADEOFF,
        choices=[TRADEOFF, *COLUMNS],
        help="column to sort by (default: tradeoff, the best trade-off first)",
    )
    p.add_argument("--descending", action="store_true", help="sort in descending order")
    p.add_argument(
        "--weights",
        type=floats,
        default=list(PAPER_WEIGHTS),
        help="w1,...,w6 for f_c and F_avg (default: the paper's)",
    )
    return p


def _columns(result: PlanningResult, weights: list[float]) -> dict[str, np.ndarray]:
    """Every column of the listing, each (n,) (``clearance``: NaN when not stored), and
    ``clearance_exact`` (n,) bool: whether the clearance is exact, not a lower bound."""
    front = result.front
    n = len(front)
    choice = best_tradeoff(front.objectives, weights)
    certified = certified_members(result)
    clearance, exact = np.full(n, np.nan), np.ones(n, dtype=bool)
    for k, member in enumerate(front.certificates or ()):
        if member is not None:
            clearance[k], exact[k] = member.min_distance, member.min_distance_exact
    clearance[result.best.index] = result.certificate.min_distance  # exact distances
    cols = {"index": np.arange(n), "T": front.x[:, 0]}
    cols.update({f"z{i + 1}": front.objectives[:, i] for i in range(1, 6)})
    cols.update(f_c=choice.f_c, F_avg=choice.F_avg, certified=certified, clearance=clearance)
    exact[result.best.index] = True
    cols["clearance_exact"] = exact
    rank = np.empty(n)
    rank[choice.order] = np.arange(n)
    rank += np.where(certified, 0.0, n)  # certified members first
    rank[result.best.index] = -1.0
    cols[TRADEOFF] = rank
    t_lb, t_best = float(result.lower_bound.T_min), result.metrics.t_best
    cols["T/T_lb"] = front.x[:, 0] / t_lb if t_lb > 0 else np.full(n, np.nan)
    cols["T/T_best"] = front.x[:, 0] / t_best if t_best else np.full(n, np.nan)
    return cols


def _cell(name: str, value: float | bool, exact: bool = True) -> str:
    if name == "index":
        return str(int(value))
    if name == "certified":
        return "yes" if value else "no"
    if name in ("clearance", "T/T_lb", "T/T_best") and np.isnan(value):
        return "-"
    if name == "clearance" and not exact:
        return f"≥{float(value):.6g}"
    return f"{float(value):.6g}"


def front_table(
    result: PlanningResult,
    *,
    sort: str = TRADEOFF,
    descending: bool = False,
    weights: list[float] | tuple[float, ...] = PAPER_WEIGHTS,
) -> str:
    """The listing printed by ``adept-traj front``: a header line with units, then one row
    per member, the best trade-off marked ``*``.

    Parameters
    ----------
    result: the planning result.
    sort: :data:`TRADEOFF` (the best trade-off first) or a key of :data:`COLUMNS`.
    descending: sort in descending order (ties keep the index order).
    weights: (6,) w1…w6 for ``f_c`` and ``F_avg`` (:func:`~adept_traj.analysis.best_tradeoff`).

    Raises
    ------
    InvalidInputError: ``sort`` is not a column, or bad ``weights``.
    """
    if sort != TRADEOFF and sort not in COLUMNS:
        raise InvalidInputError(
            f"sort must be one of {TRADEOFF}, {', '.join(COLUMNS)}; got {sort!r}"
        )
    cols = _columns(result, list(weights))
    key = np.asarray(cols[sort], dtype=float)
    key = np.where(np.isnan(key), -np.inf if descending else np.inf, key)  # '-' last
    order = np.argsort(-key if descending else key, kind="stable")
    header = [f"{name} [{unit}]" if unit else name for name, unit in COLUMNS.items()]
    exact = cols["clearance_exact"]
    rows = [[_cell(name, cols[name][k], exact[k]) for name in COLUMNS] for k in order]
    width = [max(len(h), *(len(r[j]) for r in rows)) for j, h in enumerate(header)]
    best = result.best.index
    lines = ["  " + "  ".join(h.rjust(w) for h, w in zip(header, width, strict=True))]
    for k, row in zip(order, rows, strict=True):
        mark = "* " if k == best else "  "
        lines.append(mark + "  ".join(c.rjust(w) for c, w in zip(row, width, strict=True)))
    front = result.front
    count = int(cols["certified"].sum())
    lines.append(f"* best trade-off (member {best}); {count} of {len(front)} members certified")
    if front.n_certified is None:
        lines.append(
            "note: saved before every member was certified: only the best trade-off has a "
            "certificate; the others' 'feasible' flag was the optimiser's verdict at its samples"
        )
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    """Print the listing; exit status 0 (also when the reader stops early)."""
    result = PlanningResult.load(args.folder)
    text = front_table(result, sort=args.sort, descending=args.descending, weights=args.weights)
    try:
        print(text, flush=True)
    except BrokenPipeError:  # e.g. | head: the reader has what it wanted
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no error at exit
    return status.OK
