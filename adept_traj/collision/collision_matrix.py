r"""A robot's self-collision matrix, made by sampling: :func:`collision_matrix`.

Without an SRDF a robot still has its links checked against each other. Which pairs are
left out is decided once per robot, as MoveIt's setup assistant does, by sampling poses
within the joint limits — but more strictly: a certificate cannot rest on a sample, so a
pair is left out only when it is **in contact at every sample** (distance ≤ 0 at all
:data:`MATRIX_SAMPLES` poses: touching or overlapping by design, e.g. a cover around a
joint), never because it was never *seen* colliding. The pairs left out:

- ``"Adjacent"``: links on adjacent bodies (the nearest ancestor carrying a solid) or on
  the same joint body, as :class:`~adept_traj.collision.SelfCollision` leaves them out;
- ``"Always"``: in contact at every sampled pose.

Every other pair is checked. :meth:`CollisionMatrix.to_srdf` writes the matrix as an SRDF
(``<disable_collisions link1 link2 reason>``, MoveIt's reasons), reusable with
``--srdf`` / ``Robot.from_urdf(..., srdf=...)``; ``adept-traj robot --collision-matrix
OUT.srdf`` writes it, and ``adept-traj plan`` saves it beside the result
(``collision_matrix.srdf``) when it made one. The samples are drawn with a fixed seed, so
the same robot always gets the same matrix.

The distances are those of the convex hulls of the link meshes
(:mod:`adept_traj.robot.collision_meshes`), which contain the meshes: a pair of hulls
apart at a pose is apart, and a pair whose hulls touch at every pose is left out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from adept_traj.collision.self_collision import SelfCollision
from adept_traj.robot import Robot

__all__ = [
    "MATRIX_SAMPLES",
    "CollisionMatrix",
    "SelfPairs",
    "collision_matrix",
    "robot_collision_matrix",
    "self_collision_check",
]

#: Poses sampled within the joint limits (seed :data:`MATRIX_SEED`).
MATRIX_SAMPLES = 1000
#: Seed of the sampled poses.
MATRIX_SEED = 0
#: Samples looked at first: a pair apart at one of them is checked, the rest need not be.
_FIRST = 16


def quoteattr(text: str) -> str:
    """``text`` as a double-quoted XML attribute value (``&``, ``<``, ``>``, ``"`` escaped;
    xml.sax is not imported by the planning command)."""
    for char, entity in (("&", "&amp;"), ("<", "&lt;"), (">", "&gt;"), ('"', "&quot;")):
        text = text.replace(char, entity)
    return f'"{text}"'


@dataclass(frozen=True)
class CollisionMatrix:
    """Which of a robot's link pairs are checked for self-collision (module doc).

    Attributes
    ----------
    robot: the robot's name.
    adjacent: ``(link1, link2)`` pairs left out as adjacent (sorted).
    always: pairs left out as in contact at every sample (sorted).
    checked: every other pair of links with a collision solid (sorted).
    samples: poses sampled; seed: their seed.
    """

    robot: str
    adjacent: tuple[tuple[str, str], ...]
    always: tuple[tuple[str, str], ...]
    checked: tuple[tuple[str, str], ...]
    samples: int
    seed: int

    @property
    def reasons(self) -> dict[tuple[str, str], str]:
        """Why each left-out pair is left out (a sentence per pair)."""
        out = dict.fromkeys(self.adjacent, "adjacent links")
        out.update(
            dict.fromkeys(
                self.always,
                f"in contact at every one of {self.samples} poses sampled within the limits "
                "(collision matrix)",
            )
        )
        return out

    def to_srdf(self) -> str:
        """The matrix as SRDF text: one ``<disable_collisions>`` per left-out pair, with
        MoveIt's reason (``Adjacent``, ``Always``)."""
        lines = [
            '<?xml version="1.0"?>',
            f"<!-- Self-collision matrix of {self.robot} made by adept_traj: {self.samples} "
            f"poses sampled within the joint limits (seed {self.seed}); a pair is left out "
            "only when adjacent or in contact at every sample. Every other pair is checked. -->",
            f"<robot name={quoteattr(self.robot)}>",
        ]
        for reason, pairs in (("Adjacent", self.adjacent), ("Always", self.always)):
            for a, b in pairs:
                lines.append(
                    f"  <disable_collisions link1={quoteattr(a)} link2={quoteattr(b)} "
                    f"reason={quoteattr(reason)}/>"
                )
        lines.append("</robot>")
        return "\n".join(lines) + "\n"


def collision_matrix(
    robot: Robot, samples: int = MATRIX_SAMPLES, seed: int = MATRIX_SEED
) -> CollisionMatrix:
    """The :class:`CollisionMatrix` of ``robot`` from ``samples`` poses drawn uniformly
    within its joint limits (infinite limits clipped to ±2π) with ``seed``; the robot's own
    SRDF or parameter-file pairs are not used (the matrix is what replaces them).

    The pairs are first looked at in the first :data:`_FIRST` samples; only those in
    contact at each of them are computed at the others (exact distances, coal, where the
    broad phase does not already show them apart)."""
    check = SelfCollision(robot, robot_pairs=False)
    lo = np.clip(robot.limits.lower, -2 * math.pi, 2 * math.pi)
    hi = np.clip(robot.limits.upper, -2 * math.pi, 2 * math.pi)
    q = np.random.default_rng(seed).uniform(lo, hi, (samples, robot.nq))
    links = [tuple(sorted((check.links[a], check.links[b]))) for a, b in check.pairs.tolist()]
    names = sorted(set(links))
    index = {pair: k for k, pair in enumerate(names)}
    of_link = np.array([index[p] for p in links], dtype=int)  # (n_pairs,) its link pair
    touching = np.ones(len(names), dtype=bool)
    for rows in (slice(0, _FIRST), slice(_FIRST, samples)):
        chunk = q[rows]
        if not len(chunk) or not touching.any():
            break
        d = check.distances(chunk, exact_below=0.0)  # (n, n_pairs), exact where ≤ 0
        link_d = np.full((len(chunk), len(names)), np.inf)
        np.minimum.at(link_d.T, of_link, d.T)
        touching &= (link_d <= 0.0).all(axis=0)
    always = tuple(p for p, t in zip(names, touching) if t)
    return CollisionMatrix(
        robot=robot.name,
        adjacent=check.adjacent,
        always=always,  # type: ignore[arg-type]
        checked=tuple(p for p, t in zip(names, touching) if not t),  # type: ignore[arg-type]
        samples=int(samples),
        seed=int(seed),
    )


def robot_collision_matrix(robot: Robot) -> CollisionMatrix:
    """:func:`collision_matrix` of ``robot`` with the default samples, made the first time
    it is asked for and kept on the robot (:meth:`~adept_traj.robot.Robot.derived`)."""
    return robot.derived("collision.collision_matrix", collision_matrix)


@dataclass(frozen=True)
class SelfPairs:
    """Which link pairs a problem's self-collision check covers, and why the others are
    left out (recorded in a result: ``result.json`` ``self_collision``, the summary,
    ``verify``).

    Attributes
    ----------
    checked: the checked ``(link1, link2)`` pairs (sorted).
    left_out: ``(link1, link2, reason)`` of every other pair of links with a solid.
    """

    checked: tuple[tuple[str, str], ...]
    left_out: tuple[tuple[str, str, str], ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "checked", tuple((str(a), str(b)) for a, b in self.checked))
        object.__setattr__(
            self, "left_out", tuple((str(a), str(b), str(r)) for a, b, r in self.left_out)
        )

    def lines(self) -> tuple[str, ...]:
        """Two lines: the pairs checked, and those left out grouped by reason."""
        by_reason: dict[str, list[str]] = {}
        for a, b, reason in self.left_out:
            by_reason.setdefault(reason, []).append(f"{a}–{b}")
        left = "; ".join(f"{len(v)} {k}: {', '.join(v)}" for k, v in by_reason.items())
        return (
            f"{len(self.checked)} link pairs checked: "
            + ", ".join(f"{a}–{b}" for a, b in self.checked),
            f"{len(self.left_out)} left out: {left or 'none'}",
        )


def self_collision_check(
    robot: Robot,
    wanted: bool | None,
    disabled: tuple[tuple[str, str], ...],
    influence: float,
) -> tuple[bool, SelfCollision | None, SelfPairs | None]:
    """``(on, check, pairs)``: the self-collision check of a problem on ``robot`` with the
    settings ``self_collision = wanted`` and ``disabled_pairs = disabled``.

    ``wanted`` ``None`` (the default): on for every robot with a pair to check; when the
    robot has no SRDF, no parameter-file pairs and none are given, the pairs in contact at
    every sample of its :func:`robot_collision_matrix` are left out besides the adjacent
    ones (a saved result records them in ``disabled``, so it rebuilds the same check)."""
    matrix = None
    known = robot.srdf_path is not None or robot.disabled_pairs or disabled
    if wanted is None and not known:
        matrix = robot_collision_matrix(robot)
        disabled = matrix.always
    check = SelfCollision(robot, disabled, influence=influence)
    on = bool(check.n_pairs) if wanted is None else wanted
    if not on:
        return False, None, None
    srdf = set()
    if robot.srdf_path is not None:
        srdf = {tuple(sorted(p)) for p in robot.disabled_pairs}
    reasons = dict.fromkeys(check.adjacent, "adjacent links")
    for pair in check.disabled:
        if matrix is not None and pair in matrix.always:
            reasons[pair] = matrix.reasons[pair]
        elif pair in srdf:
            reasons[pair] = f"disabled in {robot.srdf_path.name} or the parameter file"
        elif {tuple(sorted(p)) for p in robot.disabled_pairs} & {pair}:
            reasons[pair] = "disabled in the parameter file"
        else:
            reasons[pair] = "disabled pair given"
    left = tuple((a, b, reasons[(a, b)]) for a, b in sorted(reasons))
    return True, check, SelfPairs(check.link_pairs, left)
