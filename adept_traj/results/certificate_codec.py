"""The certificates in ``result.json``: the best solution's full
:class:`~adept_traj.analysis.Certificate` (with its dense trajectory,
``best_trajectory``) and each front member's
:class:`~adept_traj.analysis.MemberCertificate` (``front[i].certificate``, version 2).
Used by :mod:`adept_traj.results.json_codec`; the schema is in ``docs/results.md``.
"""

from __future__ import annotations

import math
from typing import Any

from adept_traj.certification import SelfDistance
from adept_traj.certification.certificate import Certificate, DenseTrajectory, LimitCheck
from adept_traj.certification.member_certificate import MemberCertificate
from adept_traj.results.json_values import json_float, json_floats
from adept_traj.results.parts import Front
from adept_traj.robot.limits import LIMIT_KINDS, LIMITS
from adept_traj.schema import Node

__all__ = [
    "DENSE_FIELDS",
    "decode_certificate",
    "decode_dense",
    "decode_member_certificate",
    "encode_certificate",
    "encode_member_certificate",
]

#: The series of the dense trajectory stored as ``best_trajectory``.
DENSE_FIELDS = ("t", *(kind.quantity for kind in LIMITS), "min_distance")


def encode_member_certificate(front: Front, i: int) -> dict[str, Any]:
    """The certificate entry of a front member in ``result.json``.

    Parameters
    ----------
    front:
        The result's :class:`~adept_traj.results.Front`.
    i:
        The member's index.

    Returns
    -------
    dict
        ``{"certificate": ...}`` (version 2: the member's certificate or ``None``), or
        ``{}`` when the front has no certificates (version 1).
    """
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
        "min_distance": json_float(m.min_distance),
        "min_distance_exact": m.min_distance_exact,
        "t_min_distance": m.t_min_distance,
        "closest_pair": None if m.closest_pair is None else list(m.closest_pair),
        "violations": list(m.violations),
    }
    if m.distance_bound is not None:
        out["distance_bound"] = json_float(m.distance_bound)  # null: +inf (no obstacle)
    if m.self_distance is not None:  # optional key (self-collision on)
        out["self_distance"] = _encode_self_distance(m.self_distance)
    return {"certificate": out}


def _encode_self_distance(d: SelfDistance) -> dict[str, Any]:
    out: dict[str, Any] = {
        "min_distance": json_float(d.min_distance),  # null: +inf (no checked pair)
        "exact": d.exact,
        "t_min_distance": d.t_min_distance,
        "pair": None if d.pair is None else list(d.pair),
        "guarantee": d.guarantee,
    }
    if d.distance_bound is not None:
        out["distance_bound"] = json_float(d.distance_bound)
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


def encode_certificate(c: Certificate) -> dict[str, Any]:
    """The ``certificate`` object of ``result.json``.

    Parameters
    ----------
    c:
        The best move's :class:`~adept_traj.analysis.Certificate`.

    Returns
    -------
    dict
        Its fields as JSON values, the dense samples left out (they are stored as
        ``best_trajectory``, :func:`decode_dense`).
    """
    out: dict[str, Any] = {
        "feasible": c.feasible,
        "rate_hz": c.rate_hz,
        "n_samples": c.n_samples,
        "margin": c.margin,
        "min_distance": json_float(c.min_distance),
        "t_min_distance": c.t_min_distance,
        "closest_pair": None if c.closest_pair is None else list(c.closest_pair),
        "violations": list(c.violations),
        "x": json_floats(c.x),
    }
    if c.guarantee is not None:  # optional keys (absent in files of older versions)
        out["guarantee"] = c.guarantee
    if c.distance_bound is not None:
        out["distance_bound"] = json_float(c.distance_bound)  # null: +inf (no obstacle)
    if c.torque_guarantee is not None:
        out["torque_guarantee"] = c.torque_guarantee
    if c.self_distance is not None:
        out["self_distance"] = _encode_self_distance(c.self_distance)
    for check in c.checks:
        out[check.kind] = {
            "limit": check.symbol,
            "worst": json_floats(check.worst),
            "within": [bool(b) for b in check.within],
            "dense": json_floats(check.dense),
            "exact": None if check.exact is None else json_floats(check.exact),
            "t_worst": json_floats(check.t_worst),
            "tolerance": check.tolerance,
        }
    return out


def decode_member_certificate(node: Node) -> MemberCertificate | None:
    """A front member's certificate read from ``result.json`` (version 2).

    Parameters
    ----------
    node:
        The member's ``certificate`` node.

    Returns
    -------
    MemberCertificate or None
        ``None`` for a member that was not certified (``null``).

    Raises
    ------
    ResultFormatError
        The node is missing or a field is malformed.
    """
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


def decode_dense(node: Node, nq: int) -> DenseTrajectory:
    """The dense samples of the best move read from ``result.json``.

    Parameters
    ----------
    node:
        The ``best_trajectory`` node (fields :data:`DENSE_FIELDS`).
    nq:
        Joint count.

    Returns
    -------
    DenseTrajectory
        ``t`` (n,) [s], ``q`` … ``tau`` (n, nq), ``min_distance`` (n,) [m] (``null`` as +inf).

    Raises
    ------
    ResultFormatError
        A field missing or of the wrong shape.
    """
    t = node["t"].array((None,))
    arrays = {name: node[name].array((t.size, nq)) for name in DENSE_FIELDS[1:-1]}
    distance = node["min_distance"].array((t.size,), null=math.inf)
    return node.build(DenseTrajectory, t=t, **arrays, min_distance=distance)


def decode_certificate(node: Node, dense: DenseTrajectory) -> Certificate:
    """The best move's certificate read from ``result.json``.

    Parameters
    ----------
    node:
        The ``certificate`` node.
    dense:
        Its dense samples (:func:`decode_dense`).

    Returns
    -------
    Certificate

    Raises
    ------
    ResultFormatError
        A field missing or malformed.
    """
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
