"""The resource limits of the planning commands, checked before any long work.

:func:`check_run_options` refuses, with a
:class:`~adept_traj.errors.ResourceLimitError` naming the option, its value, the estimated
memory and the limit, a population (``--pop``), a number of generations (``--gens``) or a
verification rate (``--rate``) whose run would need more memory than the budget of
:mod:`adept_traj.memory` (16 GiB, or less when the machine has less available). The
estimates are :func:`~adept_traj.optimise.population_bytes` and
:func:`~adept_traj.analysis.certificate_bytes` (at the longest travel time the problem
allows); the table of limits is in ``docs/cli.md``.
"""

from __future__ import annotations

from adept_traj.certification import check_certificate_memory
from adept_traj.optimise import TIME_OPTIMAL
from adept_traj.problem import TrajectoryProblem

__all__ = ["check_run_options"]


def check_run_options(
    problem: TrajectoryProblem,
    algorithm: str,
    pop: int | None,
    gens: int | None,
    rate_hz: float,
    *,
    pop_option: str = "--pop",
    gens_option: str = "--gens",
) -> int:
    """Check that a run of ``algorithm`` on ``problem`` fits the memory budget; return the
    larger estimate [B].

    ``pop``/``gens`` ``None`` stand for the algorithm's defaults (the paper's); ``rate_hz``
    [Hz] is the dense verification's rate, checked at the problem's longest travel time.

    Raises
    ------
    ConfigurationError
        Unknown algorithm, population < 2 or generations < 1 (from
        :func:`~adept_traj.optimise.make_algorithm`).
    InvalidInputError
        ``rate_hz`` not a finite number > 0.
    ResourceLimitError
        The population (``pop_option``), the generations (``gens_option``) or the rate
        (``--rate``) would need more memory than the budget.
    """
    run = 0
    if algorithm != TIME_OPTIMAL:  # no population
        from adept_traj.optimise import check_population_memory, make_algorithm  # pymoo

        _, settings = make_algorithm(algorithm, pop, gens)
        run = check_population_memory(
            settings.pop_size, settings.n_gen, options=(pop_option, gens_option)
        )
    certificate = check_certificate_memory(problem, rate_hz, option="--rate")
    return max(run, certificate)
