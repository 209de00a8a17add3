"""Cycle files: a robot's work cycle in TOML — named locations and a sequence of moves.

The format is described in ``docs/cycles.md``. :func:`read_cycle_file` checks every field
(with :class:`~adept_traj.schema.Node`; a bad value raises
:class:`~adept_traj.errors.CycleError` naming the file, the field and the valid range),
loads the robot and the scene, and turns every location into joints: a ``pose`` through
:func:`~adept_traj.robot.solve_location` (closed form with the chosen elbow for a SCARA,
numeric IK otherwise), so that a location out of reach is refused before any planning
(:class:`~adept_traj.errors.UnreachableLocationError`, naming the file, the field and how
far out of reach it is).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from adept_traj.analysis import PAPER_WEIGHTS
from adept_traj.errors import CycleError, RobotModelError, UnreachableLocationError
from adept_traj.files import read_toml
from adept_traj.optimise import ALGORITHMS
from adept_traj.robot import (
    ELBOWS,
    ROBOT_FILE_KEYS,
    Robot,
    RobotSource,
    ScaraGeometry,
    solve_location,
)
from adept_traj.scene import SHIPPED_SCENES, Scene
from adept_traj.schema import Node, error_factory
from adept_traj.transforms import transform_from_xyz_rpy
from adept_traj.validation import readonly_copy

__all__ = [
    "CHOICES",
    "MAX_DWELL_CANDIDATES",
    "MAX_MOVES",
    "Cycle",
    "Location",
    "MoveSpec",
    "read_cycle_file",
]

_ERROR = error_factory(CycleError)
_TOP_KEYS = ("name", "robot", "scene", "repeat", "plan", "location", "move", "dwell")
_DWELL_KEYS = ("step", "max")
#: Most dwell candidates of one move (``max / step + 1``): each is a planning run.
MAX_DWELL_CANDIDATES = 32
_PLAN_KEYS = ("algorithm", "seed", "pop_size", "n_gen", "weights", "rate_hz", "choose")
_MOVE_KEYS = ("name", "from", "to", "algorithm", "seed", "pop_size", "n_gen", "weights", "choose")
#: What a move reports of its front (``choose``): the best trade-off (f_c and F_avg ranks,
#: today's rule), the fastest certified member, the certified member of least f_c alone.
CHOICES = ("trade-off", "fastest", "weighted-sum")
#: Most moves of a cycle file (each is a planning run).
MAX_MOVES = 1000


@dataclass(frozen=True)
class Location:
    """A named location, resolved to joints.

    Attributes
    ----------
    name: its name.
    joints: (nq,) [rad | m] within the joint limits.
    pose: as written (SCARA: x, y, z [m], yaw [rad]; other robots: x, y, z [m], roll,
        pitch, yaw [rad]; in the robot base frame), or ``None`` for a joint location.
    elbow: ``"lefty"``/``"righty"`` used for a SCARA pose, else ``None``.
    """

    name: str
    joints: np.ndarray
    pose: tuple[float, ...] | None
    elbow: str | None


@dataclass(frozen=True)
class MoveSpec:
    """One move of the sequence: from one location to another, at rest at both ends.

    Attributes
    ----------
    index: 0-based position in the sequence; name: unique (default ``"{from}-{to}"``,
        numbered when repeated).
    start, goal: location names.
    algorithm, seed, pop_size, n_gen, weights: the planning run (``pop_size``/``n_gen``
        ``None``: the algorithm's paper budget); the seed defaults to the cycle's seed +
        ``index``, so it does not depend on where or when the move is planned.
    choose: which member of the front the cycle runs (:data:`CHOICES`,
        :func:`~adept_traj.cycle.chosen_member`).
    """

    index: int
    name: str
    start: str
    goal: str
    algorithm: str
    seed: int
    pop_size: int | None
    n_gen: int | None
    weights: tuple[float, ...]
    choose: str = "trade-off"


@dataclass(frozen=True)
class Cycle:
    """A work cycle read from a file (:func:`read_cycle_file`).

    Attributes
    ----------
    name, source: the cycle's name and its file.
    robot: where workers load the robot from; scene: the scene (pickled to the workers).
    locations: by name; moves: the sequence, in order.
    repeat: times the sequence runs per cycle (each move is planned once).
    rate_hz: dense-certificate rate [Hz].
    dwell_step, max_dwell: the ``[dwell]`` table: the dwells [s] a move of a scene with
        moving obstacles may wait before it starts are ``0, step, 2·step, …, ≤ max``
        (``None``: the defaults of :func:`~adept_traj.cycle.dwell_grid`).
    """

    name: str
    source: str
    robot: RobotSource
    scene: Scene
    locations: dict[str, Location]
    moves: tuple[MoveSpec, ...]
    repeat: int
    rate_hz: float
    dwell_step: float | None = None
    max_dwell: float | None = None


def read_cycle_file(path: str | os.PathLike[str]) -> Cycle:
    """Read and check a cycle file; load its robot and scene; solve its locations.

    Raises
    ------
    CycleError
        Missing file, bad TOML, an unknown or malformed field, an unknown location name in
        a move, a joint location outside the limits.
    UnreachableLocationError
        A pose out of the robot's reach (with how far).
    """
    p = Path(path)
    data = read_toml(p, CycleError, what="cycle file")
    top = Node(data, p, _ERROR).check_keys(_TOP_KEYS)
    folder = p.resolve().parent
    robot_node = top["robot"].check_keys(ROBOT_FILE_KEYS) if top["robot"].present else top["robot"]
    robot_source = RobotSource.from_table(robot_node, folder)
    robot = robot_node.build(robot_source.load)
    scene = _scene(top["scene"], folder)
    plan_node = top["plan"] if top["plan"].present else Node({}, p, _ERROR)  # all defaults
    defaults = plan_node.check_keys(_PLAN_KEYS)
    locations = _locations(top["location"], robot)
    moves = _moves(top["move"], locations, defaults)
    step, most = _dwell(top["dwell"], scene) if top["dwell"].present else (None, None)
    return Cycle(
        name=top["name"].string(nonempty=True, default=p.stem or "cycle"),
        source=str(p),
        robot=robot_source,
        scene=scene,
        locations=locations,
        moves=moves,
        repeat=top["repeat"].integer(minimum=1, maximum=10**6, default=1),
        rate_hz=defaults["rate_hz"].number("[Hz]", minimum=100.0, default=1000.0),
        dwell_step=step,
        max_dwell=most,
    )


def _dwell(node: Node, scene: Scene) -> tuple[float | None, float | None]:
    """``step`` and ``max`` [s] of the ``[dwell]`` table (``None``: not given)."""
    dwell = node.check_keys(_DWELL_KEYS)
    if not scene.moving:
        raise dwell.error(f"scene {scene.name!r} has no moving obstacle: its moves never dwell")
    step = dwell["step"].number("[s]", minimum=0.0, strict=True, default=None)
    most = dwell["max"].number("[s]", minimum=0.0, default=None)
    if step is not None and most is not None and most / step + 1 > MAX_DWELL_CANDIDATES:
        raise dwell.error(
            f"max / step + 1 = {most / step + 1:.0f} dwell candidates per move, more than "
            f"MAX_DWELL_CANDIDATES = {MAX_DWELL_CANDIDATES}"
        )
    return step, most


def _scene(node: Node, folder: Path) -> Scene:
    name = node.string(nonempty=True, default="paper")
    if name in SHIPPED_SCENES:  # the command line's rule (cli.arguments.scene_from_argument)
        return Scene.shipped(name)
    return node.build(Scene.from_file, folder / name)


def _locations(node: Node, robot: Robot) -> dict[str, Location]:
    try:
        ScaraGeometry.of(robot)
        pose_size, pose_text = 4, "x, y, z [m], yaw [rad]"
    except RobotModelError:
        pose_size, pose_text = 6, "x, y, z [m], roll, pitch, yaw [rad]"
    joints_text = (
        f"[rad | m], one per joint of robot '{robot.name}' ({', '.join(robot.joint_names)})"
    )
    out: dict[str, Location] = {}
    entries = node.named_tables()
    if not entries:
        raise node.error("missing; must be an array of tables ([[location]]), at least two")
    for name, entry in entries:
        entry.check_keys(("name", "pose", "joints", "elbow"))
        if name in out:
            raise entry["name"].error(f"location {name!r} is defined twice")
        if entry["pose"].present == entry["joints"].present:
            raise entry.error("give exactly one of 'pose' and 'joints'")
        if entry["joints"].present:
            if entry["elbow"].present:
                raise entry["elbow"].error("only for a 'pose' location")
            q = entry["joints"].array((robot.nq,), joints_text)
            joints = entry["joints"].build(robot.limits.check_position, q, "joints")
            out[name] = Location(name, readonly_copy(joints), None, None)
            continue
        pose = entry["pose"].array((pose_size,), f"({pose_text})")
        elbow = entry["elbow"].string(choices=ELBOWS, default=None) if pose_size == 4 else None
        if pose_size == 6 and entry["elbow"].present:
            raise entry["elbow"].error(f"only for SCARA robots; robot '{robot.name}' is not one")
        target = pose if pose_size == 4 else transform_from_xyz_rpy(pose[:3], pose[3:])
        try:
            joints, used = solve_location(robot, target, elbow=elbow, name=name)
        except UnreachableLocationError as exc:
            where = f"{entry['pose'].file}: field '{entry['pose'].path}'"
            message = str(exc).removeprefix(f"location {name!r}: ")
            raise UnreachableLocationError(
                name, exc.distance, exc.unit, f"{where}: {message}"
            ) from None
        out[name] = Location(name, readonly_copy(joints), tuple(float(v) for v in pose), used)
    return out


def _moves(node: Node, locations: dict[str, Location], defaults: Node) -> tuple[MoveSpec, ...]:
    items = node.items(min_items=1)
    if len(items) > MAX_MOVES:
        raise node.error(f"must hold at most {MAX_MOVES} moves; got {len(items)}")
    base = _plan_fields(defaults, None)
    seed0 = base["seed"] if base["seed"] is not None else 1
    names = list(locations)
    moves, seen = [], {}
    for index, item in enumerate(items):
        item.check_keys(_MOVE_KEYS)
        start = item["from"].string(choices=names)
        goal = item["to"].string(choices=names)
        if np.array_equal(locations[start].joints, locations[goal].joints):
            raise item.error(f"'from' and 'to' are the same configuration ({start!r}, {goal!r})")
        fields = _plan_fields(item, base)
        default = f"{start}-{goal}"
        count = seen.get(default, 0)
        seen[default] = count + 1
        name = item["name"].string(nonempty=True, default=default + (f"-{count}" if count else ""))
        if any(m.name == name for m in moves):
            raise item["name"].error(f"move name {name!r} is used twice")
        if "/" in name or name.startswith("."):
            raise item["name"].error("must not contain '/' nor start with '.' (a folder name)")
        moves.append(
            MoveSpec(
                index=index,
                name=name,
                start=start,
                goal=goal,
                algorithm=fields["algorithm"],
                seed=fields["seed"] if fields["seed"] is not None else seed0 + index,
                pop_size=fields["pop_size"],
                n_gen=fields["n_gen"],
                weights=fields["weights"],
                choose=fields["choose"],
            )
        )
    return tuple(moves)


def _plan_fields(node: Node, base: dict[str, Any] | None) -> dict[str, Any]:
    """algorithm, seed, pop_size, n_gen, weights of a ``[plan]`` table or a move (a move's
    absent fields: ``base``'s; the seed stays ``None`` there: derived per move)."""
    b = base or {
        "algorithm": "nsga2",
        "seed": None,
        "pop_size": None,
        "n_gen": None,
        "weights": tuple(PAPER_WEIGHTS),
        "choose": "trade-off",
    }
    out = {
        "algorithm": node["algorithm"].string(choices=tuple(ALGORITHMS), default=b["algorithm"]),
        "seed": node["seed"].integer(minimum=0, maximum=2**32 - 1, default=None),
        "pop_size": node["pop_size"].integer(minimum=2, maximum=100_000, default=b["pop_size"]),
        "n_gen": node["n_gen"].integer(minimum=1, maximum=100_000, default=b["n_gen"]),
        "weights": b["weights"],
        "choose": node["choose"].string(choices=CHOICES, default=b["choose"]),
    }
    if node["weights"].present:
        w = node["weights"].array((6,), "", minimum=0.0)
        if w.sum() <= 0.0:
            raise node["weights"].error("must not all be 0")
        out["weights"] = tuple(float(v) for v in w)
    return out
