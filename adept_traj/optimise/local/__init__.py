"""The local solver and its starts: one SLSQP minimum-time solve, the certified
refinement in trust boxes, basins, via points and the multi-start time-optimal mode,
the ε-constraint and weighted-sum moves of front members, and the polish modes of
plan()."""
