"""The robot: a Pinocchio model with collision geometry, limits and batched evaluations.

:class:`Robot` loads a URDF (plus an optional parameter file, see
:mod:`adept_traj.robot.parameter_file`) into Pinocchio and offers the quantities the planner needs,
batched over any leading axes (population, time, …):

- :meth:`Robot.inverse_dynamics` — joint torques/forces with rotor inertia and friction;
- :meth:`Robot.manipulability` — the paper's z4 = ``|det J|`` (eq. 4);
- :meth:`Robot.tool_pose`, :meth:`Robot.tool_jacobian`, :meth:`Robot.geometry_poses`.

Joint values are in SI units: [rad] for revolute joints, [m] for prismatic ones. For the
AdeptOne XL they are exactly the DH variables (θ1, θ2, d3, θ4) of the paper's Table 1.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from adept_traj.errors import (
    ConfigurationError,
    InputShapeError,
    InvalidInputError,
    RobotModelError,
)
from adept_traj.robot.collision_meshes import HullReport, convex_hull_solids
from adept_traj.robot.forward_kinematics import ForwardKinematics, place_solids, solid_frames
from adept_traj.robot.kinematics import BatchKinematics, compose, frames_to_poses
from adept_traj.robot.limits import JointLimits
from adept_traj.robot.manipulability import manipulability_measure
from adept_traj.robot.package_paths import resolve_package_file
from adept_traj.robot.parameter_file import TASK_ROWS, RobotParameters
from adept_traj.robot.urdf_loading import (
    apply_parameters,
    load_urdf_models,
    read_srdf_disabled_pairs,
    shipped_file,
)
from adept_traj.validation import DerivedData, FrozenAttributes, as_batch, check_type

__all__ = ["VELOCITY_AT_REST", "ForwardKinematics", "Robot", "coulomb_sign"]

#: Joint speeds with ``|v| ≤ VELOCITY_AT_REST`` [rad/s | m/s] count as rest for Coulomb
#: friction (sign 0): a joint held still must not flip ±F_c on rounding noise (1e-17).
VELOCITY_AT_REST = 1e-9

#: Below this many configurations a plain loop over ``pinocchio.rnea`` is used.
_PARALLEL_MIN_BATCH = 16


class Robot(FrozenAttributes, DerivedData):
    """A serial robot: Pinocchio model, collision model, limits and batched evaluations.

    Build one with :meth:`adept_one_xl` or :meth:`from_urdf`. Its attributes are fixed at
    construction (:class:`~adept_traj.errors.FrozenObjectError`; :meth:`replace` makes a
    copy with other limits or name).

    Attributes
    ----------
    model : pinocchio.Model
        The kinematic and dynamic model. Rotor inertia is in ``model.armature``, viscous
        friction in ``model.damping`` and Coulomb friction in ``model.friction`` (joint
        side), so every Pinocchio algorithm sees them; :meth:`inverse_dynamics` reads them
        at each call.
    collision_model : pinocchio.GeometryModel
        The link solids, named ``"<link>/<solid>"`` when the URDF names its collisions.
    visual_model : pinocchio.GeometryModel
        The visual geometry (same solids for the AdeptOne XL), for display (given, or read
        on first access by a loader given instead).
    limits : JointLimits
        Position, velocity, acceleration, jerk and torque limits (``inf`` when unknown).
    tool_frame : str
        Name of the tool frame used by :meth:`tool_pose` and :meth:`manipulability`.
    task_rows : tuple of str or None
        Rows of the tool Jacobian (among ``vx vy vz wx wy wz``) used by
        :meth:`manipulability`.
    package_dirs : tuple of pathlib.Path
        The folders where the URDF's ``package://`` meshes were found (recorded in results).
    locked_joints : dict
        Joints fixed at a value [rad | m] (name → value), removed from q.
    srdf_path : pathlib.Path or None
        The SRDF given (its ``disable_collisions`` pairs: :attr:`disabled_pairs`).
    disabled_pairs : tuple of (str, str)
        Link pairs left out of self-collision: the SRDF's, then the parameter file's.
    mesh_hulls : tuple of HullReport
        The collision meshes replaced by their convex hulls (see
        :mod:`adept_traj.robot.collision_meshes`).
    """

    def __init__(
        self,
        model: pin.Model,
        collision_model: pin.GeometryModel,
        visual_model: pin.GeometryModel | Callable[[], pin.GeometryModel],
        limits: JointLimits,
        tool_frame: str,
        task_rows: tuple[str, ...] | None,
        name: str,
        urdf_path: Path | None = None,
        params_path: Path | None = None,
        *,
        package_dirs: Sequence[Path] = (),
        locked_joints: Mapping[str, float] | None = None,
        mesh_hulls: tuple[HullReport, ...] = (),
        srdf_path: Path | None = None,
        disabled_pairs: Sequence[tuple[str, str]] = (),
    ) -> None:  # the keyword-only arguments: see the class attributes
        self.model = model
        self.collision_model = collision_model
        self._visual_model = visual_model
        self.limits = limits
        self.name = name
        self.urdf_path = urdf_path
        self.params_path = params_path
        self.package_dirs = tuple(Path(p) for p in package_dirs)
        self.locked_joints = dict(locked_joints or {})
        self.mesh_hulls = tuple(mesh_hulls)
        self.srdf_path = srdf_path  # its pairs are excluded from self-collision checks
        srdf_pairs = () if srdf_path is None else read_srdf_disabled_pairs(srdf_path)
        self.disabled_pairs = srdf_pairs + tuple((str(a), str(b)) for a, b in disabled_pairs)
        if not model.existFrame(tool_frame):
            frames = [f.name for f in model.frames]
            raise RobotModelError(f"robot '{name}': no frame '{tool_frame}'; frames are {frames}")
        self._tool_frame = tool_frame
        if task_rows is not None:
            task_rows = tuple(task_rows)
            if not task_rows or any(r not in TASK_ROWS for r in task_rows):
                raise RobotModelError(
                    f"robot '{name}': task_rows must be names from {list(TASK_ROWS)}; "
                    f"got {list(task_rows)}"
                )
        self.task_rows = task_rows
        self.kinematics = BatchKinematics(model)
        self._tool_id = model.getFrameId(tool_frame)
        self._data = model.createData()
        self._freeze()

    def replace(self, **changes: Any) -> Robot:
        """A copy with other ``limits`` or ``name`` (``dataclasses.replace`` for the frozen
        robot; the Pinocchio models are shared, not copied).

        Parameters
        ----------
        **changes:
            ``limits`` (:class:`~adept_traj.robot.JointLimits` of the same joints) and/or
            ``name``.

        Returns
        -------
        Robot

        Raises
        ------
        ConfigurationError
            Another name than these, or limits of other joints (another model: build
            another Robot).
        """
        unknown = sorted(set(changes) - {"limits", "name"})
        if unknown:
            raise ConfigurationError(f"Robot.replace() takes limits or name; got {unknown}")
        limits = changes.get("limits", self.limits)
        check_type(limits, JointLimits, "limits")
        if limits.names != self.limits.names:
            raise ConfigurationError(
                f"limits must be of the joints {list(self.limits.names)}; got {list(limits.names)}"
            )
        new = copy.copy(self)
        name = str(changes.get("name", self.name))
        vars(new).update(limits=limits, name=name, _data=self.model.createData(), _derived={})
        return new  # (its own derived data: e.g. a collision matrix sampled in its limits)

    # ------------------------------------------------------------------ construction
    @classmethod
    def adept_one_xl(cls) -> Robot:
        """The AdeptOne XL SCARA shipped with the library (``urdf/adept_one_xl.urdf`` and
        its parameter file ``urdf/adept_one_xl.toml``; see ``docs/robot-model.md``)."""
        return cls.from_urdf(shipped_file("adept_one_xl.urdf"), shipped_file("adept_one_xl.toml"))

    @classmethod
    def from_urdf(
        cls,
        urdf: str | Path,
        params: str | Path | RobotParameters | None = None,
        *,
        package_dirs: Sequence[str | Path] = (),
        srdf: str | Path | None = None,
        tool_frame: str | None = None,
        locked_joints: Mapping[str, float] | None = None,
        task_rows: Sequence[str] | None = None,
    ) -> Robot:
        """Load a robot from a URDF file and an optional parameter file.

        Parameters
        ----------
        urdf:
            Path of the URDF, or a ``package://pkg/path`` URI (found like its meshes).
            Its ``<inertial>``, ``<limit>`` and ``<dynamics damping friction>`` give masses,
            position/velocity/torque (URDF: effort) limits and friction.
        params:
            Optional parameter file (TOML path or :class:`RobotParameters`): acceleration
            and jerk limits, rotor inertia × gear ratio² (→ ``model.armature``), and
            overrides of any URDF joint value. See :mod:`adept_traj.robot.parameter_file`.
        package_dirs:
            Folders searched first for ``package://`` meshes (then ``ROS_PACKAGE_PATH``,
            then installed robot data; :mod:`adept_traj.robot.package_paths`).
        srdf:
            Optional SRDF (path or ``package://`` URI): its ``disable_collisions`` pairs
            are left out of the self-collision check (:class:`~adept_traj.collision.SelfCollision`).
        tool_frame:
            Tool frame name; default: the parameter file's ``tool_frame``, else the last
            frame of the model. An unknown name is refused with the list of frames.
        locked_joints:
            Joints fixed at a value [rad | m] (name → value), removed from q. Continuous
            joints have one angle coordinate; mimic joints follow their leader and have none
            (:mod:`adept_traj.robot.urdf_loading`). Collision meshes become their convex
            hulls (:mod:`adept_traj.robot.collision_meshes`).
        task_rows:
            Jacobian rows for :meth:`manipulability`; default: the parameter file's, else
            all six rows for robots with ≥ 6 joints.

        Raises
        ------
        RobotModelError
            Missing or malformed URDF or parameter file, unsupported joint types, a
            parameter file naming a joint the URDF does not have, an unknown tool frame.
        """
        path = resolve_package_file(str(urdf), package_dirs)
        name, model, collision, visual, dirs = load_urdf_models(path, package_dirs, locked_joints)
        hulls = convex_hull_solids(collision, path)

        if params is not None and not isinstance(params, RobotParameters):
            params_path: Path | None = Path(params)
            params = RobotParameters.from_file(params_path)
        else:
            params_path = None
        limits = apply_parameters(model, params, path)
        if tool_frame is None:
            tool_frame = params.tool_frame if params and params.tool_frame else None
        if tool_frame is None:
            tool_frame = model.frames[len(model.frames) - 1].name
        if task_rows is None and params is not None and params.task_rows is not None:
            task_rows = params.task_rows
        if task_rows is None and model.nq >= 6:
            task_rows = TASK_ROWS
        return cls(
            model=model,
            collision_model=collision,
            visual_model=visual,
            limits=limits,
            tool_frame=tool_frame,
            task_rows=tuple(task_rows) if task_rows is not None else None,
            name=name,
            urdf_path=path,
            params_path=params_path,
            package_dirs=dirs,
            locked_joints=locked_joints,
            mesh_hulls=hulls,
            srdf_path=None if srdf is None else resolve_package_file(str(srdf), package_dirs),
            disabled_pairs=params.disabled_pairs if params is not None else (),
        )

    # ------------------------------------------------------------------ basic facts
    @property
    def visual_model(self) -> pin.GeometryModel:
        """The visual geometry (read on first access when a loader was given)."""
        if callable(self._visual_model):
            self._visual_model = self._visual_model()
        return self._visual_model

    @property
    def tool_frame(self) -> str:
        """Name of the tool frame (fixed at construction; build another Robot to change it)."""
        return self._tool_frame

    @property
    def nq(self) -> int:
        """Number of joint variables."""
        return self.model.nq

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Joint names in the order of q."""
        return self.limits.names

    def __repr__(self) -> str:
        return f"Robot(name={self.name!r}, nq={self.nq}, tool_frame={self.tool_frame!r})"

    # ------------------------------------------------------------------ public, batched
    def inverse_dynamics(self, q: object, v: object, a: object) -> np.ndarray:
        r"""Joint torques/forces (..., nq) [N·m | N] to follow ``q, v, a``.

        .. math::
            u = M(q)\,\ddot q + C(q,\dot q)\,\dot q + g(q)
                + \operatorname{diag}(J_a)\,\ddot q + F_v\,\dot q + F_c \operatorname{sign}(\dot q)

        (the paper's Euler–Lagrange model "with actuator inertia and friction"): rigid-body
        terms by Pinocchio's RNEA, rotor inertia :math:`J_a` = ``model.armature`` (added by
        RNEA), viscous :math:`F_v` = ``model.damping``, Coulomb :math:`F_c` =
        ``model.friction``. At rest (:math:`|\dot q_i| \le` ``VELOCITY_AT_REST`` = 1e-9) the
        Coulomb term is 0: static friction is indeterminate, and rounding noise must not
        switch ±F_c on and off.

        Parameters
        ----------
        q, v, a:
            Positions [rad | m], velocities [rad/s | m/s], accelerations [rad/s² | m/s²],
            each (..., nq); they are broadcast against each other.

        Returns
        -------
        numpy.ndarray
            (..., nq) with the broadcast leading shape.
        """
        qa = as_batch(q, "q", self.nq, "[rad | m]")
        va = as_batch(v, "v", self.nq, "[rad/s | m/s]")
        aa = as_batch(a, "a", self.nq, "[rad/s² | m/s²]")
        try:
            qa, va, aa = np.broadcast_arrays(qa, va, aa)
        except ValueError:
            raise InputShapeError(
                f"q, v, a must broadcast together; got shapes {qa.shape}, {va.shape}, {aa.shape}"
            ) from None
        return self._inverse_dynamics(qa, va, aa)

    def manipulability(self, q: object) -> np.ndarray:
        r"""Manipulability (...) of configurations ``q`` (..., nq) [rad | m].

        With the task Jacobian :math:`J_t` = the rows :attr:`task_rows` of the tool frame's
        Jacobian (world axes at the tool point):

        .. math::
            w = |\det J_t| \ \text{(square } J_t\text{, the paper's eq. 4)}, \qquad
            w = \sqrt{\det(J_t J_t^\top)} \ \text{(Yoshikawa, fewer rows than joints)}

        and :math:`\sqrt{\det(J_t^\top J_t)}` with more rows than joints
        (:func:`manipulability_measure`).

        For the AdeptOne XL (rows v_x, v_y, v_z, ω_z) this is :math:`a_1 a_2 |\sin\theta_2|`
        [m²].
        """
        if self.task_rows is None:
            raise RobotModelError(
                f"robot '{self.name}' has {self.nq} joints and no task_rows: give them in the "
                "parameter file or Robot.from_urdf(..., task_rows=[...]), e.g. ['vx', 'vy']"
            )
        qa = as_batch(q, "q", self.nq, "[rad | m]")
        return self._manipulability(qa)

    def tool_pose(self, q: object) -> np.ndarray:
        """Tool frame poses (..., 4, 4) in the robot base frame for ``q`` (..., nq)."""
        return self.frame_pose(q, self.tool_frame)

    def frame_pose(self, q: object, frame: str) -> np.ndarray:
        """Poses (..., 4, 4) of the named frame in the base frame for ``q`` (..., nq)."""
        if not self.model.existFrame(frame):
            raise InvalidInputError(
                f"frame '{frame}' does not exist; frames are {[f.name for f in self.model.frames]}"
            )
        qa = as_batch(q, "q", self.nq, "[rad | m]")
        f = self.model.frames[self.model.getFrameId(frame)]
        return self.kinematics.joint_poses(qa)[..., f.parentJoint, :, :] @ f.placement.homogeneous

    def tool_jacobian(self, q: object) -> np.ndarray:
        """Tool Jacobians (..., 6, nq): rows (v_x, v_y, v_z, ω_x, ω_y, ω_z) of the tool point
        in base-frame axes (Pinocchio's ``LOCAL_WORLD_ALIGNED``) for ``q`` (..., nq)."""
        return self._tool_jacobian(as_batch(q, "q", self.nq, "[rad | m]"))

    def geometry_poses(self, q: object, model: pin.GeometryModel | None = None) -> np.ndarray:
        """Poses (..., n_geom, 4, 4) in the base frame of every object of ``model`` (default:
        :attr:`collision_model`) for ``q`` (..., nq)."""
        gm = self.collision_model if model is None else model
        qa = as_batch(q, "q", self.nq, "[rad | m]")
        return self._geometry_poses(self.kinematics.joint_poses(qa), gm)

    def forward_kinematics(self, q: object) -> ForwardKinematics:
        """Joint, solid and tool poses and the manipulability of ``q`` (..., nq) from one
        kinematics pass (what :meth:`geometry_poses`, :meth:`tool_pose` and
        :meth:`manipulability` would each recompute)."""
        qa = as_batch(q, "q", self.nq, "[rad | m]")
        frames = self.kinematics.joint_frames(qa)
        tool = self._tool_frames(frames)
        w = None
        if self.task_rows is not None:
            w = self._manipulability_from(frames, tool).reshape(qa.shape[:-1])
        return ForwardKinematics(
            joint_frames=frames,
            tool_pose=frames_to_poses(tool[None], qa.shape[:-1])[..., 0, :, :],
            manipulability=w,
            solid_frames=solid_frames(self.collision_model),
        )

    # ------------------------------------------------------------------ private hooks
    def _geometry_poses(self, joint_poses: np.ndarray, gm: pin.GeometryModel) -> np.ndarray:
        return place_solids(joint_poses, solid_frames(gm))

    def _inverse_dynamics(self, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        shape = q.shape
        qf, vf, af = (x.reshape(-1, self.nq) for x in (q, v, a))
        n = qf.shape[0]
        if n < _PARALLEL_MIN_BATCH:
            tau = np.array([pin.rnea(self.model, self._data, *row) for row in zip(qf, vf, af)])
            tau = tau.reshape(n, self.nq)
        else:
            # A fresh pool each call: it copies the model, so later edits of
            # model.armature etc. are always seen (negligible for a batch).
            pool = pin.ModelPool(self.model, 1)
            qf_, vf_, af_ = (np.asfortranarray(x.T) for x in (qf, vf, af))
            tau = pin.rneaInParallel(1, pool, qf_, vf_, af_).reshape(self.nq, n).T  # (n,): 1 joint
        tau = tau + self.model.damping * vf + self.model.friction * coulomb_sign(vf)
        return tau.reshape(shape)

    def _tool_frames(self, frames: np.ndarray) -> np.ndarray:
        """Tool frame (3, 4, N), component-major, from joint frames (njoints, 3, 4, N)."""
        f = self.model.frames[self._tool_id]
        return compose(frames[f.parentJoint], f.placement.homogeneous)

    def _tool_jacobian(self, q: np.ndarray) -> np.ndarray:
        frames = self.kinematics.joint_frames(q)
        parent = self.model.frames[self._tool_id].parentJoint
        jac = self.kinematics.frame_jacobian(frames, parent, self._tool_frames(frames)[:, 3])
        return np.moveaxis(jac, -1, 0).reshape(*q.shape[:-1], 6, self.nq)

    def _manipulability(self, q: np.ndarray) -> np.ndarray:
        frames = self.kinematics.joint_frames(q)
        return self._manipulability_from(frames, self._tool_frames(frames)).reshape(q.shape[:-1])

    def _manipulability_from(self, frames: np.ndarray, tool: np.ndarray) -> np.ndarray:
        """(N,) manipulability from joint frames (njoints, 3, 4, N) and the tool frame
        (3, 4, N), component-major (the determinant reads contiguous entries)."""
        rows = [TASK_ROWS.index(r) for r in self.task_rows]
        parent = self.model.frames[self._tool_id].parentJoint
        jac = self.kinematics.jacobian_rows(frames, parent, tool[:, 3], rows)  # (m, nq, N)
        return manipulability_measure(np.moveaxis(jac, -1, 0))


def coulomb_sign(v: np.ndarray) -> np.ndarray:
    """sign(v) with a dead band: 0 where ``|v| ≤ VELOCITY_AT_REST`` (a joint at rest)."""
    return np.where(np.abs(v) > VELOCITY_AT_REST, np.sign(v), 0.0)
