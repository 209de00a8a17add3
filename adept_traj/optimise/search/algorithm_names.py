"""The names of the multi-objective algorithms :func:`~adept_traj.optimise.make_algorithm`
builds, and the paper's settings of its two (:mod:`adept_traj.optimise.search.algorithms`
describes them). Plain data, apart from the algorithms so that naming them (the command
line's choices) imports no pymoo.
"""

from __future__ import annotations

from typing import Any

__all__ = ["ALGORITHMS", "OTHER_ALGORITHMS", "PAPER_SETTINGS"]

#: The paper's settings per algorithm (population, generations, operator parameters).
PAPER_SETTINGS: dict[str, dict[str, Any]] = {
    "nsga2": {
        "pop_size": 100,
        "n_gen": 100,
        "crossover_prob": 0.7,
        "crossover_eta": 10.0,
        "mutation_prob_var": 0.01,
        "mutation_eta": 100.0,
    },
    "mode": {"pop_size": 500, "n_gen": 100, "CR": 0.9, "F": 0.5},
}
#: The other pymoo algorithms offered (their defaults, pymoo's).
OTHER_ALGORITHMS: tuple[str, ...] = ("nsga3", "unsga3", "smsemoa", "rvea")

#: Names accepted by :func:`~adept_traj.optimise.make_algorithm`.
ALGORITHMS: tuple[str, ...] = (*PAPER_SETTINGS, *OTHER_ALGORITHMS)
