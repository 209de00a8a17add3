"""``result.json`` (format ``"adept_traj.result"``, version 2; version 1 read): encode a
:class:`~adept_traj.results.PlanningResult` as JSON text and decode it back.

The schema is in ``docs/results.md``. Floats are written in Python's shortest round-trip
form, so every value reads back exactly. JSON has no NaN or infinity: NaN is refused and an
infinite value is written as ``null`` (``-inf`` in ``limits.q_lower``, ``+inf`` everywhere
else it may occur: infinite joint limits, the distance of a scene without obstacles).

Decoding goes through the package's one schema reader, :class:`~adept_traj.schema.Node`:
a node of the parsed JSON (its value and its dotted path such as ``front[3].x``) with typed
accessors; any missing or malformed field or value raises
:class:`~adept_traj.errors.ResultFormatError` naming the file and the field.
:meth:`PlanningResult.save <adept_traj.results.PlanningResult.save>` and
:meth:`~adept_traj.results.PlanningResult.load` are the public entry points.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from adept_traj.collision import SelfPairs
from adept_traj.files import write_text_atomic
from adept_traj.problem import OBJECTIVE_NAMES, KinematicBound, ProblemSettings
from adept_traj.results import parts
from adept_traj.results.certificate_codec import (
    DENSE_FIELDS,
    decode_certificate,
    decode_dense,
    decode_member_certificate,
    encode_certificate,
    encode_member_certificate,
)
from adept_traj.results.json_values import json_float, json_floats, jsonable
from adept_traj.results.reader import open_json
from adept_traj.results.unchecked import unchecked
from adept_traj.robot.limits import LIMITS, JointLimits
from adept_traj.scene.scene import Scene
from adept_traj.schema import Node
from adept_traj.validation import deep_equal

if TYPE_CHECKING:  # the record imports this module: its class is given to read_json
    from adept_traj.results.record import PlanningResult

__all__ = ["FORMAT", "READ_VERSIONS", "VERSION", "read_json", "write_json"]

#: Value of the ``"format"`` key of ``result.json``.
FORMAT = "adept_traj.result"
#: Newest schema version: written when the front carries its members' certificates
#: (version 1, without them, is still read, and written back for a result read from it).
VERSION = 2
#: Schema versions read.
READ_VERSIONS = (1, 2)

#: JSON key of each metric of :class:`~adept_traj.results.Metrics`.
_JSON_METRICS = dict(zip(parts.METRIC_NAMES, ("SSM", "RNI", "OO", "AE", "HV"), strict=True))


def write_json(r: PlanningResult, path: Path) -> Path:
    """Write result ``r`` (a :class:`~adept_traj.results.PlanningResult`) as JSON to
    ``path`` (atomically: a reader sees the old file or the whole new one); return
    ``path``. The layout is the module's (schema version :data:`VERSION`, or 1 for a
    result read from a version-1 file)."""
    return write_text_atomic(path, _dumps(_encode(r)) + "\n")


def read_json(path: Path, result_type: type[PlanningResult]) -> PlanningResult:
    """The result stored in a ``result.json``.

    Parameters
    ----------
    path:
        The file.
    result_type:
        The class to build, :class:`~adept_traj.results.PlanningResult` (given by its
        ``load``: the record imports this module, not the other way round).

    Returns
    -------
    PlanningResult

    Raises
    ------
    ResultFormatError
        As :meth:`~adept_traj.results.PlanningResult.load`.
    """
    return _decode(open_json(path), result_type)


# ============================================================================ encoding
def _problem_settings(settings: ProblemSettings) -> dict[str, Any]:
    """The settings as stored: a zero ``search_buffer``, ``self_collision`` off, no
    ``disabled_pairs`` and a zero ``start_time`` are left out, so that files written before
    the fields existed are written back unchanged (absent reads back as 0, off, none and
    0)."""
    out = dataclasses.asdict(settings)
    defaults = (
        ("search_buffer", 0.0),
        ("self_collision", False),
        ("disabled_pairs", ()),
        ("start_time", 0.0),
    )
    for key, default in defaults:
        if out[key] == default or out[key] is None:
            del out[key]
    return out


def _encode(r: PlanningResult) -> dict[str, Any]:
    lim, lb, c = r.limits, r.lower_bound, r.certificate
    metrics: dict[str, Any] = {key: getattr(r.metrics, name) for name, key in _JSON_METRICS.items()}
    ref = r.metrics.hv_reference_point
    metrics["HV_reference_point"] = None if ref is None else json_floats(ref)
    if r.metrics.t_best is not None:  # absent: not computed (and in results before it)
        metrics["T_best"], metrics["T_best_source"] = r.metrics.t_best, r.metrics.t_best_source
    history = None if r.history is None else [dataclasses.asdict(rec) for rec in r.history]
    out: dict[str, Any] = {
        "format": FORMAT,
        "version": _version(r),
        "warning": r.warning,
        "robot": r.robot.as_json(),
        "start": json_floats(r.start),
        "goal": json_floats(r.goal),
        "seed": r.seed,
        "algorithm": {"name": r.algorithm, "settings": r.algorithm_settings},
        "problem_settings": jsonable(_problem_settings(r.problem_settings)),
        "scene": r.scene,
        "limits": {
            "joint_names": list(lim.names),
            "units": list(lim.units),
            "q_lower": json_floats(lim.lower),
            "q_upper": json_floats(lim.upper),
            # the other bounds under their quantity's name: qd, qdd, qddd, tau
            **{kind.quantity: json_floats(lim.bound(kind.name)) for kind in LIMITS[1:]},
        },
        "lower_bound": {
            "T_min": json_float(lb.T_min),
            "per_joint": json_floats(lb.times),
            "limiting_joint": int(lb.limiting_joint),
            "delta": json_floats(lb.delta),
            "cases": list(lb.cases),
        },
        "gap": r.gap,
        "best": {
            "index": r.best.index,
            "objectives": json_floats(r.best_objectives),
            "f_c": r.best.f_c,
            "F_avg": r.best.f_avg,
        },
        "certificate": encode_certificate(c),
        "metrics": metrics,
        "timing": dataclasses.asdict(r.timing),
        "versions": dict(r.versions),
        "front": [
            {
                "objectives": json_floats(r.front.objectives[i]),
                "x": json_floats(r.front.x[i]),
                "constraints": json_floats(r.front.constraints[i]),
                "feasible": bool(r.front.feasible[i]),
            }
            | encode_member_certificate(r.front, i)
            for i in range(len(r.front))
        ],
        "best_trajectory": {name: json_floats(getattr(c.dense, name)) for name in DENSE_FIELDS},
        "history": history,
    }
    if r.front.n_certified is not None:  # optional key (absent in files of older versions)
        out["n_certified"] = r.front.n_certified
    if r.unchecked:  # optional key (absent: everything checked, or an older version's file)
        out["unchecked"] = list(r.unchecked)
    if r.self_pairs is not None:  # optional key (absent: self-collision off, or older files)
        out["self_collision"] = {
            "checked": [list(p) for p in r.self_pairs.checked],
            "left_out": [{"pair": [a, b], "reason": why} for a, b, why in r.self_pairs.left_out],
        }
    return out


def _version(r: PlanningResult) -> int:
    """2 when the front carries its members' certificates, else 1 (a result read from a
    version-1 file is written back as it was)."""
    return VERSION if r.front.certificates is not None else 1


def _dumps(value: Any, level: int = 0) -> str:
    """Pretty JSON: objects one key a line, lists of scalars on one line (a matrix: one row
    a line). Refuses NaN and infinity."""
    pad, end = "  " * (level + 1), "  " * level
    if isinstance(value, dict):
        if not value:
            return "{}"
        items = [f"{pad}{_scalar(str(k))}: {_dumps(v, level + 1)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + end + "}"
    if isinstance(value, list):
        if all(not isinstance(v, (dict, list)) for v in value):
            return _scalar(value)  # one line "[a, b, …]", encoded at C speed
        if all(type(v) is list and all(type(x) in _NUMBERS for x in v) for v in value):
            # a matrix of numbers, encoded at once at C speed and cut into its rows (no
            # "], [" inside a number): the same text as row by row
            rows = _ENCODER.encode(value)[2:-2].split("], [")
            return "[\n" + ",\n".join(f"{pad}[{row}]" for row in rows) + "\n" + end + "]"
        return "[\n" + ",\n".join(pad + _dumps(v, level + 1) for v in value) + "\n" + end + "]"
    return _scalar(value)


#: The one encoder of :func:`_dumps` (``json.dumps`` with options makes one a call).
_ENCODER = json.JSONEncoder(allow_nan=False, ensure_ascii=False)
#: The element types of a row :func:`_dumps` encodes with its matrix.
_NUMBERS = (int, float)


def _scalar(value: Any) -> str:
    return _ENCODER.encode(value)


# ============================================================================ decoding
def _decode(top: Node, result_type: type[PlanningResult]) -> PlanningResult:
    top.table()
    top["format"].string(choices=(FORMAT,))
    version = top["version"].integer()
    if version not in READ_VERSIONS:
        readable = ", ".join(map(str, READ_VERSIONS))
        raise top["version"].error(
            f"unsupported version {version} (this adept_traj reads {readable})"
        )
    rob = top["robot"]
    lock = rob["locked_joints"]
    robot = rob.build(
        parts.RobotInfo,
        name=rob["name"].string(),
        joint_names=rob["joint_names"].strings(),
        urdf=rob["urdf"].string(),
        params=rob["params"].string(null=None, default=None),
        tool_frame=rob["tool_frame"].string(null=None, default=None),
        package_dirs=rob["package_dirs"].strings(default=()),
        srdf=rob["srdf"].string(default=None),
        locked_joints={k: lock[k].number("[rad | m]") for k in lock.table()}
        if lock.present
        else {},
    )
    nq = len(robot.joint_names)
    ps = top["problem_settings"].check_keys([f.name for f in dataclasses.fields(ProblemSettings)])
    settings = {k: tuple(v) if isinstance(v, list) else v for k, v in ps.table().items()}
    settings.setdefault("search_buffer", 0.0)  # absent: written before the field (no buffer)
    settings.setdefault("self_collision", False)  # absent: off (or written before the field)
    scene = top["scene"]
    scene.build(Scene.from_dict, scene.table(), source=f"{top.file} (scene)")
    lim = top["limits"]

    def limit(key: str, null: float = math.inf) -> np.ndarray:
        return lim[key].array((nq,), null=null)

    limits = lim.build(
        JointLimits,
        names=lim["joint_names"].strings(),
        units=lim["units"].strings(),
        lower=limit("q_lower", -math.inf),
        upper=limit("q_upper"),
        **{kind.name: limit(kind.quantity) for kind in LIMITS[1:]},
    )
    lb = top["lower_bound"]
    lower_bound = lb.build(
        KinematicBound,
        times=lb["per_joint"].array((nq,)),
        delta=lb["delta"].array((nq,)),
        cases=lb["cases"].strings(),
        T_min=lb["T_min"].number(),
        limiting_joint=lb["limiting_joint"].integer(),
    )
    n_certified = top["n_certified"]
    if version >= 2 and not n_certified.present:
        raise n_certified.error("is required in a result of version 2")
    front = _decode_front(top["front"], n_certified.integer(minimum=0, default=None), version)
    bd = top["best"]
    best = bd.build(
        parts.BestSolution,
        index=bd["index"].integer(),
        f_c=bd["f_c"].number(null=None),
        f_avg=bd["F_avg"].number(null=None),
    )
    if best.index >= len(front):
        raise bd["index"].error(f"{best.index} is not a row of the front ({len(front)} rows)")
    certificate = decode_certificate(top["certificate"], decode_dense(top["best_trajectory"], nq))
    if not deep_equal(certificate.x, front.x[best.index]):
        raise top["certificate"]["x"].error(
            f"differs from front[{best.index}].x (the best solution)"
        )
    md, td, vd = top["metrics"], top["timing"], top["versions"]
    metrics = md.build(
        parts.Metrics,
        **{name: md[key].number(null=None) for name, key in _JSON_METRICS.items()},
        hv_reference_point=md["HV_reference_point"].array((len(OBJECTIVE_NAMES),), nullable=True),
        t_best=md["T_best"].number("s", default=None),
        t_best_source=md["T_best_source"].string(choices=parts.T_BEST_SOURCES, default=None),
    )
    timing = td.build(
        parts.Timing,
        total_s=td["total_s"].number(),
        evaluation_s=td["evaluation_s"].number(),
        n_evaluations=td["n_evaluations"].integer(),
        n_generations=td["n_generations"].integer(),
    )
    alg = top["algorithm"]
    result = top.build(
        result_type,
        start=top["start"].array((nq,)),
        goal=top["goal"].array((nq,)),
        robot=robot,
        scene=scene.value,
        problem_settings=ps.build(ProblemSettings, **settings),
        limits=limits,
        lower_bound=lower_bound,
        algorithm=alg["name"].string(),
        algorithm_settings=alg["settings"].table(),
        seed=top["seed"].integer(null=None),
        front=front,
        best=best,
        certificate=certificate,
        timing=timing,
        metrics=metrics,
        history=_decode_history(top["history"]),
        warning=top["warning"].string(null=None, default=None),
        versions={k: vd[k].string() for k in vd.table()},
        self_pairs=_decode_self_pairs(top["self_collision"]),
        unchecked=_decode_unchecked(top["unchecked"], limits, ProblemSettings(**settings)),
    )
    stored = top["certificate"]["feasible"]
    if stored.boolean() != certificate.feasible:
        raise stored.error(f"is {stored.value} but the stored checks say {certificate.feasible}")
    _check_derived(top, result)
    return result


def _check_derived(top: Node, result: PlanningResult) -> None:
    """Refuse a file whose fields the decoder derives rather than reads (``best.objectives``,
    ``gap``, ``certificate.n_samples``, each check's ``worst`` and ``within``, …) disagree
    with what the rest of the file gives: the file re-encoded from the decoded result must be
    the file read. The walk is iterative (the nesting is already bounded)."""
    # json.dumps (C) gives the same data as the file's own layout (_dumps), faster
    stack: list[tuple[Any, Any, str]] = [(top.value, json.loads(json.dumps(_encode(result))), "")]
    while stack:
        stored, derived, path = stack.pop()
        if stored == derived:  # whole subtrees at C speed; the walk below only finds where
            continue  # (the reader has already checked the types: bools, ints, numbers)
        if isinstance(stored, dict) and isinstance(derived, dict):
            if stored.keys() != derived.keys():
                extra = sorted(set(stored) ^ set(derived))
                raise top.error_at(
                    path, f"fields {extra} are not those of a result of version {_version(result)}"
                )
            stack.extend((stored[k], derived[k], f"{path}.{k}" if path else k) for k in stored)
        elif isinstance(stored, list) and isinstance(derived, list) and len(stored) == len(derived):
            stack.extend((s, d, f"{path}[{i}]") for i, (s, d) in enumerate(zip(stored, derived)))
        else:
            raise top.error_at(path, f"is {stored!r} but the rest of the file gives {derived!r}")


def _decode_unchecked(
    node: Node, limits: JointLimits, settings: ProblemSettings
) -> tuple[str, ...] | None:
    """The ``unchecked`` statements (absent: a file written before the field, or nothing
    unchecked), which must be those the file's limits and settings give."""
    if not node.present:
        return None
    stored = node.strings()
    derived = unchecked(limits, settings)
    if stored != derived:
        raise node.error(
            f"is {list(stored)} but the file's limits and settings give {list(derived)}"
        )
    return stored


def _decode_self_pairs(node: Node) -> SelfPairs | None:
    """The ``self_collision`` object (absent: off, or a file written before the field)."""
    if not node.present:
        return None
    node.check_keys(("checked", "left_out"))
    checked = tuple(tuple(p.strings()) for p in node["checked"].items())
    left = []
    for entry in node["left_out"].items():
        entry.check_keys(("pair", "reason"))
        a, b = entry["pair"].strings()
        left.append((a, b, entry["reason"].string()))
    return node.build(SelfPairs, checked=checked, left_out=tuple(left))


def _decode_front(node: Node, n_certified: int | None, version: int) -> parts.Front:
    xs, objs, cons, feas, certificates = [], [], [], [], []
    n_var = n_con = None
    for item in node.items(min_items=1):
        xs.append(item["x"].array((n_var,)))
        objs.append(item["objectives"].array((len(OBJECTIVE_NAMES),)))
        cons.append(item["constraints"].array((n_con,)))
        feas.append(item["feasible"].boolean())
        n_var, n_con = xs[-1].size, cons[-1].size
        if version >= 2:
            certificates.append(decode_member_certificate(item["certificate"]))
    return node.build(
        parts.Front,
        x=np.array(xs),
        objectives=np.array(objs),
        constraints=np.array(cons),
        feasible=np.array(feas, dtype=bool),
        n_certified=n_certified,
        certificates=tuple(certificates) if version >= 2 else None,
    )


def _decode_history(node: Node) -> tuple[parts.GenerationRecord, ...] | None:
    if not node.present or node.value is None:
        return None
    return tuple(
        item.build(
            parts.GenerationRecord,
            generation=item["generation"].integer(),
            n_evaluations=item["n_evaluations"].integer(),
            n_feasible=item["n_feasible"].integer(),
            hypervolume=item["hypervolume"].number(null=None),
        )
        for item in node.items()
    )
