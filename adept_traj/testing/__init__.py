"""Test helpers shipped with the package: hand-made paper moves and the per-sample
reference evaluator, used by the tests and the benchmarks (no ``sys.path`` tricks)."""
