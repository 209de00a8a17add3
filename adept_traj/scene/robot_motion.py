r"""Another robot's planned motion as moving obstacles: its collision solids following a
joint trajectory.

A second robot of the cell (robot A) follows a joint table :math:`(t_k, q_k)` (an
adept_traj result's ``best_trajectory.csv``, or any joint trajectory CSV), interpolated
linearly in joint space and held before the first and after the last time. Each of its
collision solids becomes one obstacle (:func:`robot_obstacles`) moved by a
:class:`RobotSolidMotion`: the solid's world pose ``base @ solid pose(q(t))``. Planning robot
B with these obstacles times B's move against A's.

**Speed bound.** On segment k every joint moves at the constant rate
:math:`\dot q_{kj} = \Delta q_{kj} / \Delta t_k`; a point of the solid within ``radius`` of
``point`` (solid frame) moves at most at :math:`\sum_j |\dot q_{kj}|\, r_j`, with
:math:`r_j` a configuration-free bound of the distance from joint j's origin to the ball
(the joint placements along the chain, a prismatic joint's largest stroke, the ball), as
for the planned robot's own solids (``docs/problem.md``). The largest over the segments
bounds every t. The interpolated table is the motion certified against: a planned B-spline
sampled at 1 kHz (``best_trajectory.csv``) differs from its table by at most
:math:`\max|\ddot q|\,h^2/8` per joint (h = 1 ms: under 1 µrad for the AdeptOne XL's moves).
"""

from __future__ import annotations

import functools
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import coal
import numpy as np

from adept_traj.errors import InvalidInputError, MotionFileError, SceneError
from adept_traj.files import read_bytes_bounded
from adept_traj.robot import Robot, RobotSource
from adept_traj.robot.robot import solid_frames
from adept_traj.scene.motion_laws import MotionLaw, as_times, check_ball
from adept_traj.scene.scene import Obstacle
from adept_traj.scene.shapes import Box, Capsule, Cylinder, Shape, Sphere, ValueObject
from adept_traj.transforms import as_rigid_transform
from adept_traj.validation import as_finite_array, check_increasing, readonly_copy

__all__ = ["JointTrajectory", "RobotSolidMotion", "load_robot", "robot_obstacles"]


@functools.lru_cache(maxsize=8)
def load_robot(source: RobotSource) -> Robot:
    """The robot of ``source``, loaded once per source (every solid's law shares it)."""
    return source.load()


@dataclass(frozen=True, eq=False)
class JointTrajectory(ValueObject):
    """A joint table, interpolated linearly and held outside it.

    Attributes
    ----------
    times: (n,) strictly increasing times [s] (absolute scene time), n ≥ 2.
    q: (n, nq) joint positions [rad | m].
    source: the CSV it was read from ("" if built from arrays).
    """

    times: np.ndarray
    q: np.ndarray
    source: str = ""

    def __post_init__(self) -> None:
        t, q = as_finite_array(self.times, "times"), as_finite_array(self.q, "q")
        if t.ndim != 1 or len(t) < 2 or q.ndim != 2 or len(q) != len(t):
            raise InvalidInputError(
                f"times (n,) and q (n, nq) with n ≥ 2; got shapes {t.shape} and {q.shape}"
            )
        check_increasing(t)
        object.__setattr__(self, "times", readonly_copy(t))
        object.__setattr__(self, "q", readonly_copy(q))
        object.__setattr__(self, "source", str(self.source))
        object.__setattr__(self, "_rates", np.abs(np.diff(q, axis=0)) / np.diff(t)[:, None])

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str]) -> JointTrajectory:
        """Read a CSV whose header names ``t`` and the joint columns ``q_<joint>``, each
        name optionally followed by its unit (``t [s]``, ``q_joint1 [rad]``: as
        ``best_trajectory.csv``; other columns ignored). Errors (missing file, a bad
        number, a time not increasing) are :class:`~adept_traj.errors.MotionFileError`
        naming the file and line."""
        p = Path(path)
        text = read_bytes_bounded(p, MotionFileError, what="joint trajectory CSV")
        lines = text.decode("utf-8", errors="replace").splitlines()
        header = [c.split(" [")[0].strip() for c in lines[0].split(",")] if lines else []
        cols = [i for i, c in enumerate(header) if c.startswith("q_")]
        if not header or header[0] != "t" or not cols:
            raise MotionFileError(
                f"{p}: line 1: the header must start with 't' and name q_ columns"
            )
        rows = []
        for number, line in enumerate(lines[1:], start=2):
            if not line.strip():
                continue
            cells = line.split(",")
            try:
                values = [float(cells[0]), *(float(cells[i]) for i in cols)]
            except (ValueError, IndexError):
                raise MotionFileError(f"{p}: line {number}: not a number row") from None
            if rows and values[0] <= rows[-1][0]:
                raise MotionFileError(
                    f"{p}: line {number}: time column not increasing: t = {values[0]!r} s "
                    f"after t = {rows[-1][0]!r} s"
                )
            rows.append(values)
        try:
            a = np.array(rows, dtype=float).reshape(len(rows), 1 + len(cols))
            return cls(a[:, 0], a[:, 1:], str(p.resolve()))
        except InvalidInputError as exc:
            raise MotionFileError(f"{p}: {exc}") from None

    def sample(self, t: np.ndarray) -> np.ndarray:
        """Joint positions (..., nq) at times ``t`` (...) [s], linear between rows."""
        tc = np.clip(t, self.times[0], self.times[-1])
        k = np.clip(np.searchsorted(self.times, tc, side="right") - 1, 0, len(self.times) - 2)
        tau = ((tc - self.times[k]) / (self.times[k + 1] - self.times[k]))[..., None]
        return self.q[k] + tau * (self.q[k + 1] - self.q[k])


def _shape(geometry: Any, name: str) -> Shape:
    if isinstance(geometry, coal.Box):
        return Box(2.0 * np.asarray(geometry.halfSide))
    if isinstance(geometry, coal.Sphere):
        return Sphere(float(geometry.radius))
    if isinstance(geometry, coal.Cylinder):
        return Cylinder(float(geometry.radius), 2.0 * float(geometry.halfLength))
    if isinstance(geometry, coal.Capsule):
        return Capsule(float(geometry.radius), 2.0 * float(geometry.halfLength))
    raise SceneError(
        f"solid {name!r}: a {type(geometry).__name__} cannot be a moving obstacle (box, "
        "sphere, cylinder, capsule)"
    )


@dataclass(frozen=True, eq=False)
class RobotSolidMotion(MotionLaw):
    """World pose of collision solid ``solid`` of a robot following a joint trajectory.

    Attributes
    ----------
    source: the robot's files (:class:`~adept_traj.robot.RobotSource`).
    trajectory: its :class:`JointTrajectory` (nq columns, the robot's joint order).
    solid: index of the solid in the robot's collision model.
    base: (4, 4) world pose of the robot's base frame [m].
    group: the name of the robot in the scene (its obstacles' prefix).
    """

    source: RobotSource
    trajectory: JointTrajectory
    solid: int
    base: np.ndarray
    group: str = "robot"

    def __post_init__(self) -> None:
        robot = load_robot(self.source)
        if self.trajectory.q.shape[1] != robot.nq:
            raise InvalidInputError(
                f"the trajectory has {self.trajectory.q.shape[1]} joint columns; the robot "
                f"has nq = {robot.nq}"
            )
        n = robot.collision_model.ngeoms
        if not (isinstance(self.solid, int) and 0 <= self.solid < n):
            raise InvalidInputError(f"solid must be an index in [0, {n - 1}]; got {self.solid!r}")
        object.__setattr__(self, "base", readonly_copy(as_rigid_transform(self.base, "base")))

    @property
    def robot(self) -> Robot:
        """The robot (loaded once per source)."""
        return load_robot(self.source)

    def pose(self, t: Any) -> np.ndarray:
        """(..., 4, 4) world poses of the solid at times ``t`` (...) [s]."""
        times = as_times(t)
        q = self.trajectory.sample(times.reshape(-1))
        poses = self.robot.geometry_poses(q)[:, self.solid]
        return (self.base @ poses).reshape(*times.shape, 4, 4)

    def _arms(self, point: np.ndarray, radius: float) -> tuple[np.ndarray, float]:
        """(nq,) lever arms r_j of the ball (module docstring) and its reach from the base
        origin [m]."""
        robot = self.robot
        kin, model, lim = robot.kinematics, robot.model, robot.limits
        parents, local = solid_frames(robot.collision_model)
        arms = np.zeros(robot.nq)
        reach = float(np.linalg.norm(local[self.solid, :3, :3] @ point + local[self.solid, :3, 3]))
        reach += radius
        frame = int(parents[self.solid])
        while frame > 0:
            k = model.joints[frame].idx_q
            if kin.revolute[frame - 1]:
                arms[k] = reach
            else:
                arms[k] = 1.0
                reach += max(abs(float(lim.lower[k])), abs(float(lim.upper[k])))
            reach += float(np.linalg.norm(model.jointPlacements[frame].translation))
            frame = int(kin.parents[frame - 1])
        return arms, reach

    def swept_ball(
        self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0
    ) -> tuple[np.ndarray, float]:
        """The ball about the robot base's origin of radius the ball's reach (the chain's
        placements, strokes and the ball): it holds the ball in every configuration."""
        p, r = check_ball(point, radius)
        return self.base[:3, 3].copy(), self._arms(p, r)[1]

    def max_point_speed(self, point: Any = (0.0, 0.0, 0.0), radius: float = 0.0) -> float:
        """:math:`\\max_k \\sum_j |\\dot q_{kj}| r_j` [m/s] (module docstring)."""
        p, r = check_ball(point, radius)
        arms, _ = self._arms(p, r)
        return float((self.trajectory._rates @ arms).max())  # type: ignore[attr-defined]


def robot_obstacles(
    name: str, source: RobotSource, trajectory: JointTrajectory, base: Any = None
) -> tuple[Obstacle, ...]:
    """The collision solids of the robot of ``source`` following ``trajectory``, as moving
    obstacles named ``name + "." + solid name``, its base at ``base`` (4, 4) [m] in the
    world (default identity). Raises SceneError for a solid that is not a primitive."""
    if not isinstance(name, str) or not name:
        raise InvalidInputError(f"name must be a non-empty string; got {name!r}")
    pose = np.eye(4) if base is None else base
    robot = load_robot(source)
    out = []
    for k, g in enumerate(robot.collision_model.geometryObjects):
        law = RobotSolidMotion(source, trajectory, k, pose, name)
        out.append(Obstacle(f"{name}.{g.name}", _shape(g.geometry, g.name), law))
    return tuple(out)
