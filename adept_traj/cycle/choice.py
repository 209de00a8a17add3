r"""Which member of a move's front a cycle runs: weights that mean what they say.

A move's ``choose`` (``docs/cycles.md``):

- ``"trade-off"`` (default): the planner's reported solution, the best trade-off (the
  first certified member by the rank sum of f_c and of the unweighted F_avg,
  :func:`~adept_traj.analysis.best_tradeoff`): the weights only shift it.
- ``"fastest"``: the certified member of least travel time T; the weights are not used.
- ``"weighted-sum"``: the certified member of least f_c alone (the weighted sum of the
  normalised objectives with the move's weights, :func:`~adept_traj.analysis.combined_objective`
  on the front's own bounds); ``weights = [1, 0, 0, 0, 0, 0]`` then is the fastest.

A front with no certified member reports the best trade-off (not certified).
"""

from __future__ import annotations

import numpy as np

from adept_traj.analysis import combined_objective
from adept_traj.cycle.cycle_file import CHOICES, MoveSpec
from adept_traj.errors import CycleError
from adept_traj.results import PlanningResult

__all__ = ["chosen_member"]


def chosen_member(result: PlanningResult, move: MoveSpec) -> int:
    """The row of ``result.front`` the cycle runs for ``move`` (its ``choose``; module doc).

    Raises
    ------
    CycleError
        ``move.choose`` is not one of :data:`~adept_traj.cycle.cycle_file.CHOICES`.
    """
    if move.choose not in CHOICES:
        raise CycleError(f"move {move.name!r}: choose must be one of {', '.join(CHOICES)}")
    front = result.front
    ok = np.flatnonzero(np.asarray(front.feasible, dtype=bool))
    if move.choose == "trade-off" or ok.size == 0:
        return int(result.best.index)
    if move.choose == "fastest":
        score = front.objectives[ok, 0]
    else:
        score = combined_objective(front.objectives, move.weights)[ok]
    return int(ok[np.lexsort((ok, score))[0]])
