"""The motion of a result, built once for playback, plots and export.

A :class:`Replay` holds the three objects a view of a result needs — the robot, the scene
and the B-spline trajectory of a decision vector — and nothing of the optimisation: no
collision tables, no evaluator, no worker pool. Build it once from a
:class:`~adept_traj.results.PlanningResult` (which loads the robot files and parses the
stored scene) or hand it the robot and scene you already have; the viewers, the plots and
the ROS export then only resample the spline.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.problem import BSplineTrajectory, TrajectorySamples
from adept_traj.results.record import PlanningResult
from adept_traj.robot import Robot
from adept_traj.scene import Scene
from adept_traj.validation import (
    as_finite_array,
    as_integer,
    check_type,
    deep_equal,
    readonly_copy,
)

__all__ = ["Replay"]


@dataclass(frozen=True, eq=False)
class Replay:
    """Robot, scene and trajectory of one move.

    Attributes
    ----------
    robot: the :class:`~adept_traj.robot.Robot`.
    scene: the :class:`~adept_traj.scene.Scene` (obstacles at their pose at each time).
    trajectory: the :class:`~adept_traj.problem.BSplineTrajectory` (start, goal, knots).
    x: (n_var,) the decision vector ``[T, free control points]`` of the move.
    start_time: scene time t0 [s] at which the move starts (default 0): the obstacles of
        the move's time t are at their pose at scene time :math:`t_0 + t`
        (:meth:`scene_time`).
    """

    robot: Robot
    scene: Scene
    trajectory: BSplineTrajectory
    x: np.ndarray
    start_time: float = 0.0

    def __post_init__(self) -> None:
        check_type(self.robot, Robot, "robot")
        check_type(self.scene, Scene, "scene")
        check_type(self.trajectory, BSplineTrajectory, "trajectory")
        if self.trajectory.nq != self.robot.nq:
            raise InputShapeError(
                f"trajectory has {self.trajectory.nq} joints, the robot {self.robot.nq}"
            )
        x = as_finite_array(self.x, "x")
        if x.shape != (self.trajectory.n_var,):
            raise InputShapeError(f"x must have shape ({self.trajectory.n_var},); got {x.shape}")
        object.__setattr__(self, "x", readonly_copy(x))
        t0 = float(self.start_time)
        if not (np.isfinite(t0) and t0 >= 0.0):
            raise InvalidInputError(f"start_time must be a finite scene time ≥ 0 [s]; got {t0}")
        object.__setattr__(self, "start_time", t0)

    @classmethod
    def of(
        cls,
        result: PlanningResult,
        x: Any = None,
        *,
        robot: Robot | None = None,
        scene: Scene | None = None,
    ) -> Replay:
        """The replay of ``x`` (default: the result's best solution).

        Parameters
        ----------
        result: the planning result.
        x: (n_var,) a decision vector, e.g. a row of ``result.front.x``; default
            ``result.best_x``.
        robot, scene: the run's robot and scene when the caller has them (no reload);
            by default the robot files named in ``result.robot`` are loaded and the stored
            scene is parsed, once.
        """
        check_type(result, PlanningResult, "result")
        if robot is not None:
            check_type(robot, Robot, "robot")
        if robot is not None and tuple(robot.joint_names) != result.robot.joint_names:
            raise InvalidInputError(
                f"robot has the joints {list(robot.joint_names)}, the result "
                f"{list(result.robot.joint_names)}"
            )
        robot = result.robot.load() if robot is None else robot
        scene = Scene.from_dict(result.scene, source="result scene") if scene is None else scene
        trajectory = BSplineTrajectory(
            result.start, result.goal, n_knots=int(result.problem_settings.n_knots)
        )
        t0 = result.problem_settings.start_time
        return cls(robot, scene, trajectory, result.best_x if x is None else x, t0)

    @classmethod
    def of_best(cls, result: PlanningResult, replay: Any = None) -> Replay:
        """The replay of ``result``'s best solution: ``replay`` when the caller has one,
        checked to show that motion, else :meth:`of` (robot files loaded, scene parsed,
        once).

        Raises
        ------
        InvalidInputError
            ``replay`` is not a :class:`Replay`, or its joints, start, goal, knots or
            decision vector differ from the result's (it shows another move).
        """
        check_type(result, PlanningResult, "result")
        if replay is None:
            return cls.of(result)
        check_type(replay, Replay, "replay")
        if not replay.shows(result, result.best_x):
            raise InvalidInputError(
                "replay must show the result's best solution, result.best_x "
                "(Replay.of(result)); its joints, start, goal, n_knots or x differ from the "
                f"result's (replay T = {replay.duration:.6g} s, best T = "
                f"{float(result.best_x[0]):.6g} s)"
            )
        return replay

    def shows(self, result: PlanningResult, x: Any) -> bool:
        """Whether this replay is the move of decision vector ``x`` (n_var,) of ``result``:
        the same joints, start, goal, knots, decision vector and start time."""
        tr = self.trajectory
        return (
            tuple(self.robot.joint_names) == tuple(result.robot.joint_names)
            and tr.n_knots == int(result.problem_settings.n_knots)
            and deep_equal(tr.start, result.start)
            and deep_equal(tr.goal, result.goal)
            and deep_equal(self.x, np.asarray(x, dtype=float))
            and self.start_time == result.problem_settings.start_time
        )

    def scene_time(self, times: Any) -> np.ndarray:
        """Scene times :math:`t_0 + t` [s] of the move's times ``times`` [s] (any shape):
        where the obstacles are drawn and checked."""
        t = np.asarray(times, dtype=float)
        return t if self.start_time == 0.0 else t + self.start_time

    @property
    def duration(self) -> float:
        """Travel time T [s] of the move."""
        return float(self.x[0])

    def sample(self, times: Any, orders: tuple[int, ...] = (0, 1, 2)) -> TrajectorySamples:
        """Joint positions and derivatives at ``times``.

        Parameters
        ----------
        times: (n,) times in [0, T] [s].
        orders: derivative orders to compute (subset of ``(0, 1, 2, 3)``).

        Returns
        -------
        :class:`~adept_traj.problem.TrajectorySamples`: ``t`` (n,) [s]; ``q``, ``qd``,
        ``qdd``, ``qddd`` (n, nq) [rad | m per s^r].
        """
        t = as_finite_array(times, "times")
        if t.ndim != 1:
            raise InputShapeError(f"times must have shape (n,); got {t.shape}")
        T = self.duration
        if t.size and (t.min() < 0.0 or t.max() > T * (1 + 1e-12)):
            raise InvalidInputError(
                f"times must lie in [0, T = {T:.6g} s]; got [{t.min():.6g}, {t.max():.6g}]"
            )
        return self.trajectory.sample(self.x, np.clip(t / T, 0.0, 1.0), orders=orders)

    def sample_uniform(
        self, n_samples: int, orders: tuple[int, ...] = (0, 1, 2)
    ) -> TrajectorySamples:
        r"""Joint positions and derivatives at ``n_samples`` uniform times over [0, T], both
        ends included.

        .. math::

            t_k = T \, \frac{k}{n - 1}, \qquad k = 0, \dots, n - 1

        The normalised times :math:`s_k = k / (n - 1)` are those of the dense certificate
        (:func:`~adept_traj.analysis.certify` with
        ``n = dense_samples(T, rate_hz) = ceil(T·rate_hz) + 1``), so the samples equal the
        stored ``certificate.dense`` ones.

        Parameters
        ----------
        n_samples: number of samples n ≥ 2.
        orders: derivative orders to compute (subset of ``(0, 1, 2, 3)``).

        Returns
        -------
        :class:`~adept_traj.problem.TrajectorySamples`: ``t`` (n,) [s]; ``q``, ``qd``,
        ``qdd``, ``qddd`` (n, nq) [rad | m per s^r].
        """
        n = as_integer(n_samples, "n_samples", minimum=2)
        return self.trajectory.sample(self.x, np.linspace(0.0, 1.0, n), orders=orders)

    def torques(self, samples: TrajectorySamples) -> np.ndarray:
        """Joint torques and forces along ``samples`` (from :meth:`sample` or
        :meth:`sample_uniform` with orders 0–2), by the robot's inverse dynamics with
        friction and rotor inertia (:meth:`Robot.inverse_dynamics`).

        Parameters
        ----------
        samples: :class:`~adept_traj.problem.TrajectorySamples` holding ``q``, ``qd`` and
            ``qdd`` (n, nq).

        Returns
        -------
        (n, nq) [N·m | N].
        """
        check_type(samples, TrajectorySamples, "samples")
        if samples.q is None or samples.qd is None or samples.qdd is None:
            raise InvalidInputError("samples must hold q, qd and qdd (orders 0, 1, 2)")
        return self.robot.inverse_dynamics(samples.q, samples.qd, samples.qdd)
