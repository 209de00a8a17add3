"""Stored against recomputed values: the mismatch record and the log that collects them
(used by :mod:`~adept_traj.certification.audit`).

Numbers agree within :data:`AUDIT_RTOL` of the larger magnitude; infinite values must be
equal; everything else is compared exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.validation import deep_equal

__all__ = ["AUDIT_RTOL", "Mismatch", "MismatchLog", "close"]

#: Relative tolerance of the comparison of a stored and a recomputed number (module doc).
AUDIT_RTOL = 1e-9


@dataclass(frozen=True)
class Mismatch:
    """A stored value that differs from its recomputation.

    Attributes
    ----------
    field: its path in ``result.json``, e.g. ``front[3].objectives[1]``,
        ``best_trajectory.tau[12][2]`` (for an array: its worst element).
    stored: the stored value.
    recomputed: the recomputed value.
    note: what else the reader should know (how many values of the field differ, …).
    """

    field: str
    stored: Any
    recomputed: Any
    note: str = ""

    def __str__(self) -> str:
        text = f"{self.field}: stored {_show(self.stored)}, recomputed {_show(self.recomputed)}"
        return f"{text} ({self.note})" if self.note else text


class MismatchLog:
    """Collects :class:`Mismatch` records and counts the fields and values compared."""

    def __init__(self) -> None:
        self.mismatches: list[Mismatch] = []
        self.n_fields = self.n_values = 0

    # ------------------------------------------------------------------ comparisons
    def numbers(self, path: str, stored: Any, recomputed: Any, rows: bool = False) -> None:
        """Compare two arrays of numbers (module doc); ``rows``: one field per row, named
        ``path.format(row)``."""
        s, c = np.asarray(stored, dtype=float), np.asarray(recomputed, dtype=float)
        if s.shape != c.shape:
            self.count(1, 1)
            self.add(path.format("*"), f"shape {s.shape}", f"shape {c.shape}")
            return
        finite = np.isfinite(s) & np.isfinite(c)
        mag = np.where(finite, np.maximum(np.abs(s), np.abs(c)), 0.0)
        scale = mag.max(axis=0) if s.ndim == 2 and s.size else (mag.max() if s.size else 0.0)
        gap = np.abs(np.subtract(s, c, out=np.full(s.shape, np.inf), where=finite))
        bad = (s != c) & (gap > AUDIT_RTOL * scale)
        if rows:
            blocks = [(path.format(i), s[i], c[i], bad[i], gap[i]) for i in range(len(s))]
        else:
            blocks = [(path, s, c, bad, gap)]
        self.count(len(blocks), s.size)
        for name, sv, cv, bv, gv in blocks:
            if bv.any():
                worst = np.unravel_index(int(np.argmax(np.where(bv, gv, -1.0))), bv.shape)
                n_bad = int(bv.sum())
                note = f"{n_bad} of {bv.size} values differ" if n_bad > 1 else ""
                self.add(name + _index(worst), sv[worst], cv[worst], note)

    def value(self, path: str, stored: Any, recomputed: Any, note: str = "") -> None:
        """Compare two values of any other kind (exactly, :func:`deep_equal`)."""
        self.count(1, 1)
        if not deep_equal(stored, recomputed):
            self.add(path, stored, recomputed, note)

    def optional(self, path: str, stored: float | None, recomputed: float | None) -> None:
        """Compare two numbers either of which may be ``None`` (not computed)."""
        if stored is None or recomputed is None:
            self.value(path, stored, recomputed)
        else:
            self.numbers(path, stored, recomputed)

    def fields(self, path: str, stored: Any, recomputed: Any, *groups: tuple[str, ...]) -> None:
        """Compare attributes of two records, in the order given: each group is a kind —
        ``"value"``, ``"numbers"`` or ``"optional"``, the method that compares — then the
        attribute names it compares, each field named ``path.name``."""
        for kind, *names in groups:
            compare = getattr(self, kind)
            for name in names:
                compare(f"{path}.{name}", getattr(stored, name), getattr(recomputed, name))

    def tree(self, path: str, stored: Any, recomputed: Any) -> None:
        """Compare two parsed documents (dicts, lists, leaves) leaf by leaf."""
        if isinstance(stored, dict) and isinstance(recomputed, dict):
            for key in sorted(set(stored) | set(recomputed), key=str):
                missing = "(absent)"
                self.tree(f"{path}.{key}", stored.get(key, missing), recomputed.get(key, missing))
        elif isinstance(stored, list) and isinstance(recomputed, list):
            if len(stored) != len(recomputed):
                self.count(1, 1)
                self.add(path, len(stored), len(recomputed), "number of items")
                return
            for i, (a, b) in enumerate(zip(stored, recomputed, strict=True)):
                self.tree(f"{path}[{i}]", a, b)
        else:
            self.value(path, stored, recomputed)

    def count(self, fields: int, values: int) -> None:
        self.n_fields += fields
        self.n_values += values

    def add(self, path: str, stored: Any, recomputed: Any, note: str = "") -> None:
        self.mismatches.append(Mismatch(path, stored, recomputed, note))

    # ------------------------------------------------------------------ the audit


def _show(value: Any) -> str:
    """A value as printed in a mismatch: floats in shortest round-trip form."""
    if isinstance(value, (float, np.floating)):
        return repr(float(value))
    if isinstance(value, (np.integer, np.bool_)):
        return repr(value.item())
    return repr(value) if isinstance(value, str) else str(value)


def _index(idx: tuple[int, ...]) -> str:
    return "".join(f"[{int(i)}]" for i in idx)


def close(a: float, b: float) -> bool:
    """``a`` and ``b`` agree within :data:`AUDIT_RTOL` of the larger magnitude."""
    return a == b or abs(a - b) <= AUDIT_RTOL * max(abs(a), abs(b))
