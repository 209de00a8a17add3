"""Figures of planning results (the paper's Figs. 4–9) as PNG files.

Every function takes one :class:`~adept_traj.results.PlanningResult` or a mapping
``{name: PlanningResult}`` (e.g. ``{"nsga2": r1, "mode": r2}``), writes a PNG and returns
its :class:`~pathlib.Path`:

===========================  ================================  ============================
function                     module                            figure
===========================  ================================  ============================
:func:`pareto_matrix`        :mod:`.fronts`                    scatter matrix of z1…z6 of
                                                               the fronts (Figs. 5–6)
:func:`best_tradeoffs`       :mod:`.tradeoffs`                 the best trade-offs side by
                                                               side, scored bars (Fig. 7)
:func:`joint_motion`         :mod:`.motion`                    q, q̇, q̈, q⃛ and τ of every
                                                               joint against time (Figs. 8–9)
:func:`tool_path_3d`         :mod:`.tool_path`                 tool path, obstacles and
                                                               pendulum in the world (Fig. 4)
:func:`hypervolume_history`  :mod:`.history`                   hypervolume (or feasible
                                                               count) per generation
:func:`save_all`             :mod:`.all_figures`               all of the above into a
                                                               folder
:func:`start_save_all`       :mod:`.all_figures`               the same in a forked
                                                               process, the caller goes on
===========================  ================================  ============================

:mod:`.common` holds what they share (labels, colours, checks, the figure canvas),
:mod:`.wireframes` the outlines of solids. matplotlib is imported lazily, inside the
functions (``pip install 'adept-traj[plot]'``). Figures are drawn on the Agg canvas
directly: no pyplot state, no window, nothing is shown, the caller's matplotlib backend is
left alone. Units are SI. Bad arguments raise
:class:`~adept_traj.errors.InvalidInputError`. See ``docs/plots-and-export.md``.
"""

from __future__ import annotations

from adept_traj.viz.plots.all_figures import BackgroundFigures, save_all, start_save_all
from adept_traj.viz.plots.common import OBJECTIVE_LABELS
from adept_traj.viz.plots.fronts import pareto_matrix
from adept_traj.viz.plots.history import hypervolume_history
from adept_traj.viz.plots.motion import joint_motion
from adept_traj.viz.plots.tool_path import tool_path_3d
from adept_traj.viz.plots.tradeoffs import best_tradeoffs

__all__ = [
    "OBJECTIVE_LABELS",
    "BackgroundFigures",
    "best_tradeoffs",
    "hypervolume_history",
    "joint_motion",
    "pareto_matrix",
    "save_all",
    "start_save_all",
    "tool_path_3d",
]
