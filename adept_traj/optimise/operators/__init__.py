"""pymoo's operators on arrays: crossover (SBX), mutation (PM), the binary tournament,
the mating rounds, the survival (rank and crowding), duplicate elimination, MODE's DE
variant, a population's arrays, and the kinematic-time repair they apply. Each takes
pymoo's decisions with pymoo's draws, bit for bit (names as pymoo names them)."""
