"""The certificates in ``result.json``: the best solution's full
:class:`~adept_traj.analysis.Certificate` (with its dense trajectory,
``best_trajectory``) and each front member's
:class:`~adept_traj.analysis.MemberCertificate` (``front[i].certificate``, version 2).
Used by :mod:`adept_traj.results.json_codec`; the schema is in ``docs/results.md``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from adept_traj.analysis import SelfDistance
from adept_traj.analysis.certificate import Certificate, DenseTrajectory, LimitCheck
from adept_traj.analysis.member_certificate import MemberCertificate
from adept_traj.errors import InvalidInputError
from adept_traj.results.parts import Front
from adept_traj.robot.limits import LIMIT_KINDS, LIMITS
from adept_traj.schema import Node

__all__: list[str] = []

#: The series of the dense trajectory stored as ``best_trajectory``.
_DENSE_FIELDS = ("t", *(kind.quantity for kind in LIMITS), "min_distance")


def _member_certificate(front: Front, i: int) -> dict[str, Any]:
    """``{"certificate": ...}`` of member ``i`` (version 2), or nothing (version 1)."""
    if front.certificates is None:
        return {}
    m = front.certificates[i]
    if m is None:
        return {"certificate": None}
    out: dict[str, Any] = {
        "feasible": m.feasible,
        "guarantee": m.guarantee,
        "torque_guarantee": m.torque_guarantee,
        "worst": dict(zip(LIMIT_KINDS, m.worst, strict=True)),
        "worst_joint": dict(zip(LIMIT_KINDS, m.worst_joint, strict=True)),
        "t_worst": dict(zip(LIMIT_KINDS, m.t_worst, strict=True)),
        "min_distance": _float(m.min_distance),
        "min_distance_exact": m.min_distance_exact,
        "t_min_distance": m.t_min_distance,
        "closest_pair": None if m.closest_pair is None else list(m.closest_pair),
        "violations": list(m.violations),
    }
    if m.distance_bound is not None:
        out["distance_bound"] = _float(m.distance_bound)  # null: +inf (no obstacle)
    if m.self_distance is not None:  # optional key (self-collision on)
        out["self_distance"] = _encode_self_distance(m.self_distance)
    return {"certificate": out}


def _encode_self_distance(d: SelfDistance) -> dict[str, Any]:
    out: dict[str, Any] = {
        "min_distance": _float(d.min_distance),  # null: +inf (no checked pair)
        "exact": d.exact,
        "t_min_distance": d.t_min_distance,
        "pair": None if d.pair is None else list(d.pair),
        "guarantee": d.guarantee,
    }
    if d.distance_bound is not None:
        out["distance_bound"] = _float(d.distance_bound)
    return out


def _decode_self_distance(node: Node) -> SelfDistance | None:
    """The ``self_distance`` object (absent: self-collision off, or a file written before)."""
    if not node.present:
        return None
    pair, bound = node["pair"], node["distance_bound"]
    return node.build(
        SelfDistance,
        min_distance=node["min_distance"].number(null=math.inf),
        exact=node["exact"].boolean(),
        t_min_distance=node["t_min_distance"].number(null=None),
        pair=None if pair.value is None else pair.strings(),
        guarantee=node["guarantee"].string(nonempty=True),
        distance_bound=bound.number(null=math.inf) if bound.present else None,
    )


def _encode_certificate(c: Certificate) -> dict[str, Any]:
    out: dict[str, Any] = {
        "feasible": c.feasible,
        "rate_hz": c.rate_hz,
        "n_samples": c.n_samples,
        "margin": c.margin,
        "min_distance": _float(c.min_distance),
        "t_min_distance": c.t_min_distance,
        "closest_pair": None if c.closest_pair is None else list(c.closest_pair),
        "violations": list(c.violations),
        "x": _floats(c.x),
    }
    if c.guarantee is not None:  # optional keys (absent in files of older versions)
        out["guarantee"] = c.guarantee
    if c.distance_bound is not None:
        out["distance_bound"] = _float(c.distance_bound)  # null: +inf (no obstacle)
    if c.torque_guarantee is not None:
        out["torque_guarantee"] = c.torque_guarantee
    if c.self_distance is not None:
        out["self_distance"] = _encode_self_distance(c.self_distance)
    for check in c.checks:
        out[check.kind] = {
            "limit": check.symbol,
            "worst": _floats(check.worst),
            "within": [bool(b) for b in check.within],
            "dense": _floats(check.dense),
            "exact": None if check.exact is None else _floats(check.exact),
            "t_worst": _floats(check.t_worst),
            "tolerance": check.tolerance,
        }
    return out


def _float(value: float) -> float | None:
    """A finite float as is; ±inf as ``None``; NaN refused."""
    v = float(value)
    if math.isnan(v):
        raise InvalidInputError("NaN cannot be saved")
    return v if math.isfinite(v) else None


def _floats(arr: Any) -> Any:
    """Nested lists of floats (±inf → ``None``) from an array; NaN refused."""
    a = np.asarray(arr, dtype=float)
    if np.isnan(a).any():
        raise InvalidInputError("NaN cannot be saved")
    return np.where(np.isinf(a), None, a).tolist() if np.isinf(a).any() else a.tolist()


def _decode_member_certificate(node: Node) -> MemberCertificate | None:
    if not node.present:
        raise node.error("is required in a result of version 2 (an object, or null)")
    if node.value is None:
        return None

    def per_kind(key: str, read: Any) -> tuple[Any, ...]:
        table = node[key].check_keys(LIMIT_KINDS)
        return tuple(read(table[kind]) for kind in LIMIT_KINDS)

    pair = node["closest_pair"]
    return node.build(
        MemberCertificate,
        feasible=node["feasible"].boolean(),
        guarantee=node["guarantee"].string(nonempty=True),
        torque_guarantee=node["torque_guarantee"].string(nonempty=True, null=None),
        worst=per_kind("worst", lambda n: n.number()),
        worst_joint=per_kind("worst_joint", lambda n: n.integer(minimum=0)),
        t_worst=per_kind("t_worst", lambda n: n.number()),
        min_distance=node["min_distance"].number(null=math.inf),
        min_distance_exact=node["min_distance_exact"].boolean(),
        t_min_distance=node["t_min_distance"].number(null=None),
        closest_pair=None if pair.value is None else pair.strings(),
        distance_bound=(
            node["distance_bound"].number(null=math.inf) if node["distance_bound"].present else None
        ),
        violations=node["violations"].strings(),
        self_distance=_decode_self_distance(node["self_distance"]),
    )


def _decode_dense(node: Node, nq: int) -> DenseTrajectory:
    t = node["t"].array((None,))
    arrays = {name: node[name].array((t.size, nq)) for name in _DENSE_FIELDS[1:-1]}
    distance = node["min_distance"].array((t.size,), null=math.inf)
    return node.build(DenseTrajectory, t=t, **arrays, min_distance=distance)


def _decode_certificate(node: Node, dense: DenseTrajectory) -> Certificate:
    nq, checks = dense.nq, {}
    for kind in LIMIT_KINDS:
        cd = node[kind]
        checks[kind] = cd.build(
            LimitCheck,
            kind=kind,
            dense=cd["dense"].array((nq,)),
            exact=cd["exact"].array((nq,), nullable=True),
            t_worst=cd["t_worst"].array((nq,)),
            tolerance=cd["tolerance"].number(),
        )
    pair = node["closest_pair"]
    return node.build(
        Certificate,
        x=node["x"].array((None,)),
        rate_hz=node["rate_hz"].number(),
        margin=node["margin"].number(),
        min_distance=node["min_distance"].number(null=math.inf),
        t_min_distance=node["t_min_distance"].number(null=None),
        closest_pair=None if pair.value is None else pair.strings(),
        violations=node["violations"].strings(),
        dense=dense,
        guarantee=node["guarantee"].string(nonempty=True, default=None),
        distance_bound=(
            node["distance_bound"].number(null=math.inf) if node["distance_bound"].present else None
        ),
        torque_guarantee=node["torque_guarantee"].string(nonempty=True, default=None),
        self_distance=_decode_self_distance(node["self_distance"]),
        **checks,
    )
