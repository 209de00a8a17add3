r"""Inverse kinematics: joint values that put the tool at a given location.

Two solvers:

- :func:`scara_ik` — closed form for a SCARA (two parallel vertical revolute joints, a
  vertical prismatic joint, a vertical wrist; tool on the wrist axis). The location is
  ``(x, y, z, yaw)`` ([m], [m], [m], [rad]) of the tool in the robot base frame. The
  geometry (link lengths, joint directions, offsets) is read from the robot's own forward
  kinematics by :meth:`ScaraGeometry.of` and checked against it, so no number of a
  particular robot is written here. Two arm configurations reach a point inside the
  workspace; they are named as in Adept's V+ language: ``"righty"`` (seen from above, the
  elbow lies right of the line from the shoulder to the wrist, like a human right arm)
  and ``"lefty"`` (left of it). For the AdeptOne XL righty is θ2 < 0.
- :func:`numeric_ik` — any robot, on a plain ``pinocchio.Model`` and a frame id: damped
  least squares on the full pose error :math:`\log_6(T(q)^{-1} T^*)`, from several starts
  (the hint, then seeded uniform draws within the joint limits), each step clipped to the
  limits.

:func:`solve_location` picks the closed form when the robot is a SCARA and the numeric
solver otherwise. A location out of reach raises
:class:`~adept_traj.errors.UnreachableLocationError` naming it and saying how far out of
reach it is.

Where a revolute joint has several solutions ``θ + 2πk`` within its limits (the
AdeptOne XL's wrist spans ±270°), the one nearest 0 is used.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from adept_traj.errors import InvalidInputError, RobotModelError, UnreachableLocationError
from adept_traj.transforms import as_rigid_transform
from adept_traj.validation import as_batch, as_integer, as_vector, check_type

if TYPE_CHECKING:
    from adept_traj.robot.robot import Robot

__all__ = [
    "ELBOWS",
    "ScaraGeometry",
    "numeric_ik",
    "scara_ik",
    "scara_location",
    "solve_location",
]

#: Names of the two SCARA arm configurations (Adept V+).
ELBOWS = ("lefty", "righty")

#: Largest difference [m | rad] between the fitted SCARA geometry and the robot's forward
#: kinematics for the robot to count as a SCARA.
_FIT_TOL = 1e-9
#: Numeric solver: position [m] and rotation [rad] tolerance of a solution.
_POSITION_TOL = 1e-7
_ROTATION_TOL = 1e-7


def _wrap(angle: np.ndarray | float) -> np.ndarray:
    """Angles [rad] wrapped to (-π, π]."""
    return -np.remainder(-np.asarray(angle, dtype=float) + np.pi, 2.0 * np.pi) + np.pi


def _yaw(rotation: np.ndarray) -> np.ndarray:
    """Yaw [rad] (...,) of rotations (..., 3, 3) about the base z axis (of the x axis)."""
    return np.arctan2(rotation[..., 1, 0], rotation[..., 0, 0])


@dataclass(frozen=True)
class ScaraGeometry:
    r"""The planar geometry of a SCARA read from its forward kinematics.

    With :math:`\sigma_i = \pm 1` the direction of joint i along base z,

    .. math::
        p_{xy} = o + a_1 e(\beta_1 + \sigma_1\theta_1)
                 + a_2 e(\gamma_0 + \sigma_1\theta_1 + \sigma_2\theta_2), \quad
        z = z_0 + \sigma_3 d_3, \quad
        \psi = \psi_0 + \sigma_1\theta_1 + \sigma_2\theta_2 + \sigma_4\theta_4

    with :math:`e(\alpha) = (\cos\alpha, \sin\alpha)`.

    Attributes
    ----------
    a1, a2: link lengths [m].
    origin: (2,) shoulder axis in the base xy plane [m].
    beta1, gamma0: directions [rad] of link 1 and link 2 at q = 0.
    z0: tool height at q = 0 [m]; psi0: tool yaw at q = 0 [rad].
    signs: (4,) the σ_i.
    lower, upper: (4,) joint limits [rad | m].
    """

    a1: float
    a2: float
    origin: tuple[float, float]
    beta1: float
    gamma0: float
    z0: float
    psi0: float
    signs: tuple[int, int, int, int]
    lower: tuple[float, ...]
    upper: tuple[float, ...]

    @classmethod
    def of(cls, robot: Robot) -> ScaraGeometry:
        """The geometry of ``robot``; :class:`~adept_traj.errors.RobotModelError` when it is
        not a SCARA of the form above (checked on the forward kinematics of 16 seeded
        configurations within its limits)."""
        kin = robot.kinematics
        if robot.nq != 4 or list(kin.revolute) != [True, True, False, True]:
            raise RobotModelError(
                f"robot '{robot.name}' is not a SCARA (joints revolute, revolute, prismatic, "
                "revolute): use numeric_ik"
            )
        q0 = np.zeros(4)
        frames = kin.joint_poses(q0)  # (5, 4, 4)
        z_axes = np.einsum("jab,jb->ja", frames[1:, :3, :3], kin.axes)  # (4, 3) in base
        if not np.allclose(np.abs(z_axes[:, 2]), 1.0, atol=_FIT_TOL, rtol=0.0):
            raise RobotModelError(f"robot '{robot.name}': the SCARA joint axes must be vertical")
        signs = tuple(int(s) for s in np.sign(z_axes[:, 2]))
        tool = robot.tool_pose(q0)
        o1, o2, p = frames[1, :2, 3], frames[2, :2, 3], tool[:2, 3]
        lim = robot.limits
        geo = cls(
            a1=float(np.hypot(*(o2 - o1))),
            a2=float(np.hypot(*(p - o2))),
            origin=(float(o1[0]), float(o1[1])),
            beta1=float(np.arctan2(*(o2 - o1)[::-1])),
            gamma0=float(np.arctan2(*(p - o2)[::-1])),
            z0=float(tool[2, 3]),
            psi0=float(_yaw(tool[:3, :3])),
            signs=signs,  # type: ignore[arg-type]
            lower=tuple(float(v) for v in lim.lower),
            upper=tuple(float(v) for v in lim.upper),
        )
        rng = np.random.default_rng(0)
        lo, hi = np.maximum(lim.lower, -np.pi), np.minimum(lim.upper, np.pi)
        q = rng.uniform(lo, hi, size=(16, 4))
        poses = robot.tool_pose(q)
        want = np.column_stack([poses[:, :3, 3], _yaw(poses[:, :3, :3])])
        err = np.abs(geo.location(q) - want)
        err[:, 3] = np.abs(_wrap(err[:, 3]))
        vertical = np.abs(np.abs(poses[:, 2, 2]) - 1.0).max()
        if err.max() > _FIT_TOL or vertical > _FIT_TOL:
            raise RobotModelError(
                f"robot '{robot.name}' is not a SCARA with its tool on the wrist axis "
                f"(closed-form error {err.max():.3g}): use numeric_ik"
            )
        return geo

    def location(self, q: np.ndarray) -> np.ndarray:
        """Tool locations (..., 4): x, y, z [m], yaw [rad] in (-π, π] of joints ``q``
        (..., 4) [rad, rad, m, rad] (the forward map of the class docstring)."""
        s1, s2, s3, s4 = self.signs
        t1, t2, d3, t4 = np.moveaxis(np.asarray(q, dtype=float), -1, 0)
        a = self.beta1 + s1 * t1
        b = self.gamma0 + s1 * t1 + s2 * t2
        x = self.origin[0] + self.a1 * np.cos(a) + self.a2 * np.cos(b)
        y = self.origin[1] + self.a1 * np.sin(a) + self.a2 * np.sin(b)
        z = self.z0 + s3 * d3
        psi = _wrap(self.psi0 + s1 * t1 + s2 * t2 + s4 * t4)
        return np.stack([x, y, z, psi], axis=-1)

    def _in_limits(self, k: int, angle: float, name: str, elbow: str) -> float:
        """The value ``angle + 2πm`` [rad] of revolute joint ``k`` within its limits nearest
        0; UnreachableLocationError saying how far outside the limits it is otherwise."""
        lo, hi = self.lower[k], self.upper[k]
        base = float(_wrap(angle))
        candidates = base + 2.0 * np.pi * np.arange(-3, 4)
        inside = candidates[(candidates >= lo) & (candidates <= hi)]
        if inside.size:
            return float(inside[np.argmin(np.abs(inside))])
        out = np.minimum(np.abs(candidates - lo), np.abs(candidates - hi)).min()
        raise UnreachableLocationError(
            name,
            out,
            "rad",
            f"the {elbow} arm needs joint {k + 1} = {base:.4g} rad, {out:.4g} rad outside its "
            f"limits [{lo:.4g}, {hi:.4g}] rad",
        )


def scara_location(geometry: ScaraGeometry, q: object) -> np.ndarray:
    """Tool locations (..., 4) (x, y, z [m], yaw [rad]) of joints ``q`` (..., 4)."""
    check_type(geometry, ScaraGeometry, "geometry")
    return geometry.location(as_batch(q, "q", 4, "[rad, rad, m, rad]"))


def scara_ik(
    geometry: ScaraGeometry, location: object, elbow: str, name: str = "<pose>"
) -> np.ndarray:
    r"""Joints (4,) [rad, rad, m, rad] placing the tool at ``location``.

    With :math:`r` the distance of the wrist from the shoulder axis, the relative angle of
    link 2 is

    .. math::
        \varphi = \pm\arccos\frac{r^2 - a_1^2 - a_2^2}{2 a_1 a_2}

    (+ righty, − lefty; seen from above with base z up).

    Parameters
    ----------
    geometry: the robot's :class:`ScaraGeometry`.
    location: (4,) x, y, z [m] and yaw [rad] of the tool in the robot base frame.
    elbow: ``"righty"`` or ``"lefty"`` (see the module docstring).
    name: the location's name, for messages.

    Raises
    ------
    UnreachableLocationError
        The point lies outside the annulus :math:`|a_1 - a_2| \le r \le a_1 + a_2` (the
        distance to it [m] is given), or a joint value is outside its limits (by how much
        [rad | m]).
    InvalidInputError
        A malformed location or an unknown elbow.
    """
    check_type(geometry, ScaraGeometry, "geometry")
    loc = as_vector(location, f"location {name!r}", 4, "[m, m, m, rad]")
    if elbow not in ELBOWS:
        raise InvalidInputError(f"location {name!r}: elbow must be one of {ELBOWS}; got {elbow!r}")
    g = geometry
    s1, s2, s3, s4 = g.signs
    d = loc[:2] - np.asarray(g.origin)
    r = float(np.hypot(*d))
    far, near = g.a1 + g.a2, abs(g.a1 - g.a2)
    if r > far + _FIT_TOL or r < near - _FIT_TOL:
        out = r - far if r > far else near - r
        side = "beyond the arm's reach" if r > far else "inside the arm's inner dead zone"
        raise UnreachableLocationError(
            name,
            out,
            "m",
            f"({loc[0]:.4g}, {loc[1]:.4g}) m is {r:.4g} m from the shoulder axis, {out:.4g} m "
            f"{side} (the arm reaches {near:.4g} to {far:.4g} m)",
        )
    c = np.clip((r * r - g.a1**2 - g.a2**2) / (2.0 * g.a1 * g.a2), -1.0, 1.0)
    phi = np.arccos(c) * (1.0 if elbow == "righty" else -1.0)
    link1 = np.arctan2(d[1], d[0]) - np.arctan2(g.a2 * np.sin(phi), g.a1 + g.a2 * np.cos(phi))
    t1 = g._in_limits(0, s1 * (link1 - g.beta1), name, elbow)
    t2 = g._in_limits(1, s2 * (phi - (g.gamma0 - g.beta1)), name, elbow)
    d3 = s3 * (loc[2] - g.z0)
    if not g.lower[2] <= d3 <= g.upper[2]:
        out = max(g.lower[2] - d3, d3 - g.upper[2])
        raise UnreachableLocationError(
            name,
            out,
            "m",
            f"z = {loc[2]:.4g} m needs joint 3 = {d3:.4g} m, {out:.4g} m outside its stroke "
            f"[{g.lower[2]:.4g}, {g.upper[2]:.4g}] m",
        )
    t4 = g._in_limits(3, s4 * (loc[3] - g.psi0 - s1 * t1 - s2 * t2), name, elbow)
    return np.array([t1, t2, d3, t4])


def numeric_ik(
    model: pin.Model,
    frame_id: int,
    target: object,
    *,
    hint: object = None,
    starts: int = 8,
    seed: int = 0,
    max_iter: int = 300,
    damping: float = 1e-6,
    name: str = "<pose>",
) -> np.ndarray:
    r"""Joints (nq,) [rad | m] placing frame ``frame_id`` of ``model`` at ``target``.

    Damped least squares on the full pose: with :math:`e = \log_6(T(q)^{-1} T^*)` (6,) and
    :math:`J = -J_{\log}(T^{*-1} T(q))\,J_f(q)` (Pinocchio's ``log6``, ``Jlog6`` and the
    frame Jacobian in the frame's axes),

    .. math::
        q \leftarrow \operatorname{clip}\big(q - J^\top (J J^\top + \lambda I)^{-1} e,\
        q_{\min}, q_{\max}\big)

    from ``hint`` (default: the middle of the limits), then from ``starts - 1`` seeded
    uniform draws within the limits ([-π, π] where a limit is infinite), until
    :math:`\|e_{xyz}\| \le 10^{-7}` m and :math:`\|e_\omega\| \le 10^{-7}` rad.

    Parameters
    ----------
    model: a Pinocchio model (``nq == nv``: revolute and prismatic joints).
    frame_id: the frame to place (e.g. ``model.getFrameId("tool0")``).
    target: (4, 4) the frame's wanted pose in the model's world frame.
    hint: (nq,) first start [rad | m].
    starts, seed, max_iter, damping: number of starts, their seed, iterations per start,
        :math:`\lambda`.
    name: the location's name, for messages.

    Raises
    ------
    UnreachableLocationError
        No start converged; ``distance`` is the smallest position residual [m] found.
    """
    check_type(model, pin.Model, "model")
    frame_id = as_integer(frame_id, "frame_id", minimum=0, maximum=len(model.frames) - 1)
    starts = as_integer(starts, "starts", minimum=1)
    max_iter = as_integer(max_iter, "max_iter", minimum=1)
    goal = pin.SE3(as_rigid_transform(target, f"location {name!r}"))
    lo = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -np.pi)
    hi = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, np.pi)
    first = 0.5 * (lo + hi) if hint is None else as_vector(hint, "hint", model.nq, "[rad | m]")
    rng = np.random.default_rng(as_integer(seed, "seed", minimum=0))
    data = model.createData()
    best = (np.inf, np.inf)
    for k in range(starts):
        q = np.clip(first, lo, hi) if k == 0 else rng.uniform(lo, hi)
        q, err = _dls(model, data, frame_id, goal, q, lo, hi, max_iter, damping)
        if err[0] <= _POSITION_TOL and err[1] <= _ROTATION_TOL:
            return q
        best = min(best, err)
    raise UnreachableLocationError(
        name,
        best[0],
        "m",
        f"not reached by numeric IK from {starts} starts within the joint limits: best "
        f"residual {best[0]:.4g} m, {best[1]:.4g} rad",
    )


def _dls(
    model: pin.Model,
    data: pin.Data,
    frame_id: int,
    goal: pin.SE3,
    q: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    max_iter: int,
    damping: float,
) -> tuple[np.ndarray, tuple[float, float]]:
    """One damped-least-squares descent; (q, (position error [m], rotation error [rad]))."""
    err = (np.inf, np.inf)
    for _ in range(max_iter):
        pin.framesForwardKinematics(model, data, q)
        delta = data.oMf[frame_id].actInv(goal)
        e = pin.log6(delta).vector
        err = (float(np.linalg.norm(e[:3])), float(np.linalg.norm(e[3:])))
        if err[0] <= _POSITION_TOL and err[1] <= _ROTATION_TOL:
            break
        jf = pin.computeFrameJacobian(model, data, q, frame_id, pin.LOCAL)
        jac = -pin.Jlog6(delta.inverse()) @ jf
        step = -jac.T @ np.linalg.solve(jac @ jac.T + damping * np.eye(6), e)
        q = np.clip(pin.integrate(model, q, step), lo, hi)
    return q, err


def solve_location(
    robot: Robot,
    location: object,
    *,
    elbow: str | None = None,
    name: str = "<pose>",
    hint: object = None,
) -> tuple[np.ndarray, str | None]:
    """(joints (nq,) [rad | m], elbow used) placing ``robot``'s tool at ``location``.

    For a SCARA (:meth:`ScaraGeometry.of` succeeds) ``location`` is (4,) x, y, z [m],
    yaw [rad] in the base frame, solved in closed form with ``elbow`` (``None``: righty
    if it reaches the location, else lefty — the documented rule). For any other robot it
    is a (4, 4) pose in the base frame, solved by :func:`numeric_ik` (elbow ``None``).
    """
    try:
        geometry = ScaraGeometry.of(robot)
    except RobotModelError:
        if elbow is not None:
            raise InvalidInputError(
                f"location {name!r}: elbow {elbow!r} is only for SCARA robots; robot "
                f"'{robot.name}' is solved numerically"
            ) from None
        frame = robot.model.getFrameId(robot.tool_frame)
        return numeric_ik(robot.model, frame, location, hint=hint, name=name), None
    if elbow is not None:
        return scara_ik(geometry, location, elbow, name), elbow
    try:
        return scara_ik(geometry, location, "righty", name), "righty"
    except UnreachableLocationError as righty:
        try:
            return scara_ik(geometry, location, "lefty", name), "lefty"
        except UnreachableLocationError:
            raise righty from None
