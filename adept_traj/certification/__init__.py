"""The certificate of a move: dense samples, limit checks, the continuous-time distance
bound between samples, self-distances, member certificates, the start and goal
checked at rest, and the audit behind ``adept-traj verify``."""
