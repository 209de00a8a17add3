r"""Audit of a saved result: every stored number that can be recomputed is recomputed and
compared (``adept-traj verify``; the list is in ``docs/results.md``).

:func:`audit` rebuilds the problem of a :class:`~adept_traj.results.PlanningResult` from
its robot files and stored scene (:meth:`PlanningResult.problem`) and compares, field by
field of ``result.json``:

- the robot's name, joints, tool frame and limits, and the kinematic lower bound of the
  travel time, against the reloaded robot (:func:`~adept_traj.problem.kinematic_lower_bound`);
- the stored scene against the scene rebuilt from it and against a reference scene (the
  shipped scene of the stored name (``"paper"``, ``"detour"``), or the one given);
- every front member's objectives and constraints against
  :meth:`~adept_traj.problem.TrajectoryProblem.evaluate_batch` of its decision vector, its
  ``feasible`` flag against the recomputed constraints and, for a result whose members
  are all certified (``front.n_certified``), each member's own continuous certificate
  (and, version 2, its stored summary ``front[i].certificate`` field by field);
  when the front has a member feasible at the samples, that every member is and none
  dominates another (how ``plan`` builds it);
- the certificate (dense trajectory t, q, qd, qdd, qddd, tau, min_distance; every limit
  check, the minimum distance, its time and pair, the self-distance when self-collision is
  on, the violations, the verdict) against a
  fresh :func:`~adept_traj.analysis.certify` at the stored rate and tolerance;
- ``best.F_avg`` and ``best.f_c`` against :func:`~adept_traj.analysis.best_tradeoff` of the
  stored front with ``weights`` (not stored: ``plan``'s are the paper's unless changed),
  and ``best.index`` against ``plan``'s rule (the trade-off order; when the choice is not
  the first, the members before it must fail certification: they are certified again);
- for a result of the weighted-sum mode (``algorithm_settings["weighted_sum"]``): its
  stored weights replace ``weights``, ``best.index`` follows the order of increasing
  :math:`f_w` (:meth:`~adept_traj.analysis.WeightedSum.order`), and the stored scales
  against :func:`~adept_traj.analysis.weighted_sum` of the rebuilt problem;
- the metrics SSM, OO, AE, HV and the HV reference point, recomputed as ``plan`` does from
  the stored front and timing; T_best, when stored, as the z1 of the fastest certified
  member, and its source as the algorithm's (``"time-optimal"`` or ``"polish"``).

Numbers agree when equal or within a relative tolerance :data:`AUDIT_RTOL` of the field's
magnitude (per column of a matrix, i.e. per quantity and joint):

.. math::

    |s - r| \le \varepsilon \max_{\text{column}} \max(|s|, |r|), \qquad
    \varepsilon = 10^{-9}

Evaluation is deterministic, but not bit-identical across batch sizes, numpy builds and
processors (a result re-evaluated alone differs from its population's values in the last
bit: 4.5e-13 on an energy of 2 433 J, 7e-15 N·m on torques of 50 N·m); a tampered value
(q shifted by 0.05 rad, a halved objective, zeroed torques) is many orders above it.
Infinite values must be equal. RNI (needs the final population) and the per-generation
hypervolumes (need every generation's front) cannot be recomputed: :attr:`Audit.not_checked`
names them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from adept_traj.analysis import (
    DEFAULT_HV_REFERENCE,
    PAPER_WEIGHTS,
    WeightedSum,
    algorithm_effort,
    best_tradeoff,
    non_dominated,
    normalised_hypervolume,
    objective_bounds,
    objective_weights,
    optimizer_overhead,
    spread,
    weighted_sum,
)
from adept_traj.certification import Certificate, certify, certify_members
from adept_traj.certification.mismatches import Mismatch, MismatchLog, close
from adept_traj.problem import OBJECTIVE_NAMES, TrajectoryProblem
from adept_traj.results.record import PlanningResult
from adept_traj.robot import LIMITS
from adept_traj.scene import SHIPPED_SCENES, Scene
from adept_traj.validation import check_type

__all__ = ["Audit", "audit"]

#: What cannot be recomputed from a result folder.
NOT_RECOMPUTABLE = (
    "metrics.RNI (needs the final population, which is not stored)",
    "history[*].hypervolume (needs every generation's front, which is not stored)",
)


@dataclass(frozen=True, eq=False)
class Audit:
    """What :func:`audit` found.

    Attributes
    ----------
    mismatches: every :class:`Mismatch` (empty: the folder holds what its decision vectors
        give).
    n_fields: fields compared (an array counts once; one per front member and field).
    n_values: numbers and other values compared.
    not_checked: what could not be compared, and why.
    certificate: the fresh :class:`~adept_traj.analysis.Certificate` of the best solution
        at the stored rate.
    """

    mismatches: tuple[Mismatch, ...]
    n_fields: int
    n_values: int
    not_checked: tuple[str, ...]
    certificate: Certificate

    @property
    def ok(self) -> bool:
        """No mismatch."""
        return not self.mismatches


def audit(
    result: PlanningResult,
    *,
    weights: ArrayLike = PAPER_WEIGHTS,
    scene: Scene | None = None,
    problem: TrajectoryProblem | None = None,
) -> Audit:
    """Recompute every stored number of ``result`` that can be and compare (module doc).

    Parameters
    ----------
    result: the loaded result.
    weights: (6,) the weights of f_c given to ``plan`` (default: the paper's; a result of
        the weighted-sum mode uses its stored ones).
    scene: the scene the run was planned on, to compare the stored one with; default: the
        shipped scene of the stored scene's name (``adept_traj.scene.SHIPPED_SCENES``),
        else none.
    problem: ``result.problem()`` if the caller has built it (left open); default: built
        here and closed.

    Returns
    -------
    Audit
        The mismatches, what was compared and the fresh certificate.
    """
    check_type(result, PlanningResult, "result")
    w = objective_weights(weights, len(OBJECTIVE_NAMES))
    weighted = WeightedSum.from_settings(result.algorithm_settings)
    if weighted is not None:
        w = weighted.weights
    if scene is not None:
        check_type(scene, Scene, "scene")
    elif result.scene.get("name") in SHIPPED_SCENES:
        scene = Scene.shipped(result.scene["name"])
    if problem is not None:
        check_type(problem, TrajectoryProblem, "problem")
        return _Auditor(result, problem, w, scene).run()
    with result.problem() as built:
        return _Auditor(result, built, w, scene).run()


class _Auditor(MismatchLog):
    """The comparisons of one audit."""

    def __init__(
        self, result: PlanningResult, problem: TrajectoryProblem, weights: Any, scene: Any
    ) -> None:
        super().__init__()
        self.r, self.p, self.weights, self.scene = result, problem, weights, scene
        self.weighted = WeightedSum.from_settings(result.algorithm_settings)
        self.not_checked = list(NOT_RECOMPUTABLE)

    def run(self) -> Audit:
        self.robot()
        self.scenes()
        self.front()
        certificate = certify(
            self.p,
            self.r.best_x,
            rate_hz=self.r.certificate.rate_hz,
            tolerance=self.r.certificate.position.tolerance,
        )
        self.certificate("certificate", self.r.certificate, certificate)
        self.best(certificate)
        self.weighted_sum()
        self.metrics()
        return Audit(
            tuple(self.mismatches),
            self.n_fields,
            self.n_values,
            tuple(self.not_checked),
            certificate,
        )

    def robot(self) -> None:
        r, robot = self.r, self.p.robot
        self.value("robot.name", r.robot.name, robot.name)
        self.value("robot.joint_names", list(r.robot.joint_names), list(robot.joint_names))
        self.value("robot.tool_frame", r.robot.tool_frame, robot.tool_frame)
        stored, now = r.limits, robot.limits
        self.value("limits.units", list(stored.units), list(now.units))
        self.numbers("limits.q_lower", stored.lower, now.lower)
        self.numbers("limits.q_upper", stored.upper, now.upper)
        for kind in LIMITS[1:]:
            self.numbers(f"limits.{kind.quantity}", stored.bound(kind.name), now.bound(kind.name))
        lb, now_lb = r.lower_bound, self.p.lower_bound
        self.numbers("lower_bound.T_min", lb.T_min, now_lb.T_min)
        self.numbers("lower_bound.per_joint", lb.times, now_lb.times)
        self.numbers("lower_bound.delta", lb.delta, now_lb.delta)
        self.value("lower_bound.limiting_joint", lb.limiting_joint, now_lb.limiting_joint)
        self.value("lower_bound.cases", list(lb.cases), list(now_lb.cases))

    def scenes(self) -> None:
        self.tree("scene", self.r.scene, self.p.scene.to_dict())
        if self.scene is None:
            self.not_checked.append(
                f"scene against its file (the stored scene is named "
                f"{self.r.scene.get('name')!r}; give the file: verify --scene FILE)"
            )
        else:
            self.tree("scene", self.r.scene, self.scene.to_dict())

    def front(self) -> None:
        front = self.r.front
        ev = self.p.evaluate_batch(front.x)
        self.numbers("front[{}].objectives", front.objectives, ev.objectives, rows=True)
        self.numbers("front[{}].constraints", front.constraints, ev.constraints, rows=True)
        feasible = self.certified_members(ev.feasible)
        for i, (stored, now) in enumerate(zip(front.feasible, feasible, strict=True)):
            self.value(f"front[{i}].feasible", bool(stored), bool(now))
        if not ev.feasible.any():
            return  # the least-infeasible members of a population that is not stored
        rule = "plan keeps only the non-dominated members feasible at its samples"
        kept = non_dominated(front.objectives)
        self.count(len(front), len(front))
        for i in np.flatnonzero(~ev.feasible | ~kept):
            member = "infeasible member" if not ev.feasible[i] else "dominated member"
            self.add(f"front[{i}]", member, "not in the front", rule)

    def certified_members(self, sampled: np.ndarray) -> np.ndarray:
        """(n,) the recomputed ``front.feasible``: the optimiser's verdict ``sampled`` (n,)
        for a result of the earlier rule (``front.n_certified`` is None), else that verdict
        and the member's own certificate with the continuous guarantee (as ``plan`` does).
        The stored member certificates (version 2) are compared with the fresh ones."""
        front = self.r.front
        if front.n_certified is None:
            return np.asarray(sampled, dtype=bool)
        stored = front.certificates
        if stored is None:  # n_certified without the certificates: certify what could pass
            rows = [int(i) for i in np.flatnonzero(sampled)]
        else:
            rows = [i for i, c in enumerate(stored) if c is not None]
            skipped = [int(i) for i in np.flatnonzero(sampled) if stored[i] is None]
            if skipped:
                self.not_checked.append(
                    f"front{skipped}: feasible at the samples but not certified by plan "
                    f"(plan(max_certify=...)); stored as not feasible"
                )
        fresh = certify_members(
            self.p,
            front.x,
            rows,
            rate_hz=self.r.certificate.rate_hz,
            tolerance=self.r.certificate.position.tolerance,
        )
        if stored is not None:
            for i in rows:
                self.member_certificate(f"front[{i}].certificate", stored[i], fresh[i])
        return np.array(
            [bool(ok) and c is not None and c.feasible for ok, c in zip(sampled, fresh)],
            dtype=bool,
        )

    def member_certificate(self, path: str, stored: Any, now: Any) -> None:
        """Compare two :class:`~adept_traj.analysis.MemberCertificate` field by field."""
        self.fields(
            path, stored, now,
            ("value", "feasible", "guarantee", "torque_guarantee", "worst_joint",
             "min_distance_exact", "closest_pair", "violations"),
            ("numbers", "worst", "t_worst", "min_distance"),
            ("optional", "t_min_distance", "distance_bound"),
        )  # fmt: skip
        self.self_distance(f"{path}.self_distance", stored.self_distance, now.self_distance)

    def self_distance(self, path: str, stored: Any, now: Any) -> None:
        """Compare two :class:`~adept_traj.analysis.SelfDistance` (or ``None``: off)."""
        if stored is None or now is None:
            self.value(path, stored, now)
            return
        self.fields(
            path, stored, now, ("value", "exact", "pair", "guarantee"),
            ("numbers", "min_distance"), ("optional", "t_min_distance", "distance_bound"),
        )  # fmt: skip

    def certificate(self, path: str, stored: Certificate, now: Certificate) -> None:
        self.fields(
            path, stored, now, ("value", "feasible", "n_samples"),
            ("numbers", "margin", "min_distance"), ("optional", "t_min_distance"),
            ("value", "closest_pair"),
        )  # fmt: skip
        self.value(f"{path}.violations", list(stored.violations), list(now.violations))
        self.self_distance(f"{path}.self_distance", stored.self_distance, now.self_distance)
        for old, new in zip(stored.checks, now.checks, strict=True):
            for name in ("dense", "t_worst"):
                self.numbers(f"{path}.{old.kind}.{name}", getattr(old, name), getattr(new, name))
            if old.exact is None or new.exact is None:
                self.value(f"{path}.{old.kind}.exact", old.exact, new.exact)
            else:
                self.numbers(f"{path}.{old.kind}.exact", old.exact, new.exact)
        for name in ("t", *(kind.quantity for kind in LIMITS), "min_distance"):
            self.numbers(
                f"best_trajectory.{name}", getattr(stored.dense, name), getattr(now.dense, name)
            )

    def best(self, certificate: Certificate) -> None:
        r = self.r
        choice = best_tradeoff(r.front.objectives, self.weights)
        i = r.best.index
        self.optional("best.F_avg", r.best.f_avg, float(choice.F_avg[i]))
        weights = ",".join(f"{w:g}" for w in self.weights)
        self.count(1, 1)
        if r.best.f_c is not None and not close(r.best.f_c, float(choice.f_c[i])):
            self.add("best.f_c", r.best.f_c, float(choice.f_c[i]), f"with weights {weights}")
        order = choice.order if self.weighted is None else self.weighted.order(r.front.objectives)
        expected = self.expected_index(order, certificate)
        self.value("best.index", i, expected, f"plan's rule with weights {weights}")

    def weighted_sum(self) -> None:
        """The stored scales of the weighted-sum mode against the rebuilt problem's."""
        if self.weighted is None:
            return
        now = weighted_sum(self.p, self.weighted.weights)
        self.numbers("algorithm.settings.weighted_sum.scale", self.weighted.scale, now.scale)
        self.value(
            "algorithm.settings.weighted_sum.reference", self.weighted.reference, now.reference
        )

    def expected_index(self, order: np.ndarray, certificate: Certificate) -> int:
        """``plan``'s choice. With every member certified (``front.n_certified`` set): the
        first member of the trade-off order whose stored verdict is certified (checked
        member by member in :meth:`front`), else the first of the order. Before that rule:
        the first of the order, or when its certificate fails, the first member after it
        marked feasible whose certificate passes."""
        r, first = self.r, int(order[0])
        if r.front.n_certified is not None:
            passed = [int(k) for k in order if r.front.feasible[k]]
            return passed[0] if passed else first
        if r.best.index == first:
            return first  # the members after it are not certified again
        rank = int(np.flatnonzero(order == r.best.index)[0])
        tried = [first] + [int(k) for k in order[1:rank] if r.front.feasible[k]]
        rate, tol = r.certificate.rate_hz, r.certificate.position.tolerance
        for k in tried:
            if certify(self.p, r.front.x[k], rate_hz=rate, tolerance=tol).feasible:
                return k
        ok = certificate.feasible and bool(r.front.feasible[r.best.index])
        return r.best.index if ok else first

    def metrics(self) -> None:
        r, m = self.r, self.r.metrics
        F = r.front.objectives
        self.optional("metrics.SSM", m.ssm, spread(F) if len(F) > 1 else None)
        t = r.timing
        timed = 0.0 <= t.evaluation_s <= t.total_s and t.total_s > 0.0  # else undefined
        oo = optimizer_overhead(t.total_s, t.evaluation_s) if timed else None
        self.optional("metrics.OO", m.oo, oo)
        self.optional(
            "metrics.AE", m.ae, algorithm_effort(t.total_s, t.n_evaluations) if timed else None
        )
        feasible = bool(r.front.feasible.any())
        hv = normalised_hypervolume(F, *objective_bounds(F)) if feasible else None
        self.optional("metrics.HV", m.hv, hv)
        ref = np.full(len(OBJECTIVE_NAMES), DEFAULT_HV_REFERENCE) if feasible else None
        if m.hv_reference_point is None or ref is None:
            self.value("metrics.HV_reference_point", m.hv_reference_point, ref)
        else:
            self.numbers("metrics.HV_reference_point", m.hv_reference_point, ref)
        if m.t_best is not None:  # None: not computed (which rows the solver made is not stored)
            ok = r.front.feasible
            self.optional("metrics.T_best", m.t_best, float(F[ok, 0].min()) if ok.any() else None)
            source = "time-optimal" if r.algorithm == "time-optimal" else "polish"
            self.value("metrics.T_best_source", m.t_best_source, source)
