r"""What a result's certificate did not check, said once: :func:`unchecked`.

A URDF gives position, velocity and effort limits, often not acceleration or jerk limits,
and some joints (a mimic finger, a joint without ``<limit>``) have none at all. A limit that
is not known is ``inf`` in :class:`~adept_traj.robot.JointLimits`; its constraint is then
0 − 1 < 0 at every sample (always met), so the search ignores it and the certificate
cannot say anything about it. Likewise a robot whose links are not checked against each
other. :func:`unchecked` lists these statements; ``result.json`` stores them under
``unchecked`` (absent: everything was checked), the ``plan`` summary and ``verify``
print them, and the motion figure draws no limit line for them (a panel says
``no limit``).

Without a jerk limit the jerk objective z5 (:math:`\sum_i \int_0^T \dddot q_i^2\,dt`,
not relative to any limit) is still computed and minimised: the B-spline's jerk is finite
and z5 measures its smoothness. The kinematic lower bound of ``T``
(:func:`~adept_traj.problem.kinematic_lower_bound`) takes the limits that are known: the
trapezoidal-velocity bound without a jerk limit, ``h / v`` with a velocity limit only.
"""

from __future__ import annotations

import numpy as np

from adept_traj.problem import ProblemSettings
from adept_traj.robot.limits import LIMITS, JointLimits

__all__ = ["unchecked", "unchecked_of"]


def unchecked(limits: JointLimits, settings: ProblemSettings) -> tuple[str, ...]:
    """Statements of what the certificate of a problem with ``limits`` and ``settings``
    does not check: one per limit kind with joints without a limit (an infinite bound),
    and one when self-collision is off; ``()`` when everything is checked.

    Example: ``"jerk (JC): no limit for panda_joint1, panda_joint2: not constrained, not
    certified"``.
    """
    out = []
    for kind in LIMITS:
        if kind.name == "position":
            missing = ~(np.isfinite(limits.lower) & np.isfinite(limits.upper))
        else:
            missing = ~np.isfinite(limits.bound(kind.name))
        if missing.any():
            names = ", ".join(n for n, m in zip(limits.names, missing) if m)
            out.append(
                f"{kind.name} ({kind.symbol}): no limit for {names}: not constrained, not certified"
            )
    if not settings.self_collision:
        out.append("self-collision: off: the robot's links were not checked against each other")
    return tuple(out)


def unchecked_of(result: object) -> tuple[str, ...]:
    """The statements of :func:`unchecked` a :class:`~adept_traj.results.PlanningResult`
    records (``result.unchecked``), or, for a result without them (made directly, or saved
    before the field), those its limits and settings give."""
    stored = getattr(result, "unchecked", None)
    if stored is not None:
        return tuple(stored)
    return unchecked(result.limits, result.problem_settings)  # type: ignore[attr-defined]
