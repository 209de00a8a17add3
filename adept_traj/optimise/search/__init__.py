"""The evolutionary search: the algorithms (NSGA-II, MODE, any pymoo one), the initial
sampling, the fast-end local search inside the mating, the generation loop and its
checkpoints."""
