"""The library's exception hierarchy.

Every error the library raises on purpose derives from :class:`AdeptTrajError`, so a caller
can catch them all with one clause. Input errors also derive from :class:`ValueError`
(or :class:`FileNotFoundError`) so that generic code keeps working.
"""

from __future__ import annotations

import dataclasses
import os
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

__all__ = [
    "AdeptTrajError",
    "CheckpointFormatError",
    "CollidingConfigurationError",
    "ConfigurationError",
    "CycleError",
    "FigureError",
    "FrozenObjectError",
    "InputShapeError",
    "InvalidInputError",
    "JointLimitError",
    "MeshFileError",
    "MeshcatServerError",
    "MotionFileError",
    "OpenMeshWarning",
    "PlanningInterrupted",
    "ResourceLimitError",
    "ResultFormatError",
    "RobotMismatchError",
    "RobotModelError",
    "SceneError",
    "SceneFileNotFoundError",
    "UnreachableLocationError",
    "WorkerDiedError",
    "WorkerError",
    "error_from_process",
]


class AdeptTrajError(Exception):
    """Base class of every error raised by adept_traj."""


class InvalidInputError(AdeptTrajError, ValueError):
    """An argument has a bad value: NaN or infinite, out of its valid range, unknown name."""


class InputShapeError(InvalidInputError):
    """An array argument has the wrong shape (e.g. ``(..., 3)`` where ``(..., 4)`` is needed)."""


class JointLimitError(InvalidInputError):
    """A joint value lies outside the robot's joint limits where that matters."""


class RobotModelError(AdeptTrajError):
    """A robot description (URDF or parameter file) is missing, malformed or unsupported."""


class RobotMismatchError(RobotModelError):
    """A robot given for a saved result (``verify``/``show --robot``) is not the robot the
    result records: other joints, tool frame, limits or dynamics."""


class SceneError(AdeptTrajError):
    """A scene (file or object) is missing, malformed or inconsistent."""


class ConfigurationError(InvalidInputError):
    """Settings of a problem, an algorithm or a run are inconsistent."""


class CheckpointFormatError(ConfigurationError):
    """A checkpoint file is damaged: truncated, not an ``.npz`` archive, or an array of it
    missing, unexpected, or of the wrong shape or dtype (or its metadata malformed).
    Raised before any generation runs: a damaged checkpoint is never resumed.

    Attributes
    ----------
    file: path of the checkpoint file.
    array: name of the offending array (e.g. ``"X"``, ``"data.rank"``, ``"meta"``), or
        ``None`` when the whole file is at fault.
    reason: what is wrong, without the file's name.
    """

    def __init__(self, file: str | os.PathLike[str], array: str | None, reason: str) -> None:
        self.file = str(file)
        self.array = array
        self.reason = reason
        where = f" (array '{array}')" if array else ""
        super().__init__(f"{self.file}: damaged checkpoint{where}: {reason}; it cannot be resumed")

    def __reduce__(self) -> tuple[type, tuple[str, str | None, str]]:
        return type(self), (self.file, self.array, self.reason)


class PlanningInterrupted(AdeptTrajError):
    """The run was interrupted (Ctrl-C); the last finished generation is checkpointed."""

    def __init__(self, message: str, checkpoint: Path | None) -> None:
        super().__init__(message)
        self.checkpoint = checkpoint


class ResultFormatError(AdeptTrajError, ValueError):
    """A result folder is missing a file, or a file is malformed.

    Attributes
    ----------
    file: path of the offending file.
    field: dotted path of the offending field (e.g. ``"front[3].x"``, ``"certificate"``),
        or ``None`` when the whole file is at fault.
    """

    def __init__(self, file: str | os.PathLike[str], field: str | None, message: str) -> None:
        self.file = str(file)
        self.field = field
        where = f"{self.file}: field '{field}'" if field else self.file
        super().__init__(f"{where}: {message}")


class SceneFileNotFoundError(SceneError, FileNotFoundError):
    """A scene file does not exist (both a :class:`SceneError` and a FileNotFoundError)."""


class MeshFileError(SceneError):
    """A mesh or point-cloud file of a scene is missing, unreadable, empty or too large; the
    message names the file and the problem."""


class MotionFileError(SceneError):
    """A recorded-motion (pose trajectory) CSV file of a scene is missing or malformed (a
    non-monotonic time column, a bad number): the message names the file, the line and the
    problem."""


class OpenMeshWarning(UserWarning):
    """A mesh obstacle is not closed (some edge is not shared by exactly two consistently
    oriented triangles): it is treated as a thin surface, so a robot solid inside it is not
    seen (``docs/scene-files.md``)."""


class MeshcatServerError(AdeptTrajError, RuntimeError):
    """The local meshcat server, or the page server ``adept-traj show`` starts beside it
    (:mod:`adept_traj.viz.page_server`), could not be started or does not answer."""


class WorkerError(AdeptTrajError, RuntimeError):
    """A worker process (:mod:`adept_traj.process_pool`) failed with an error that could
    not be handed back as itself (it does not unpickle); the message holds the worker's
    traceback."""


#: The figures' name of :class:`WorkerError` (drawing the figures in a worker process).
FigureError = WorkerError


class WorkerDiedError(WorkerError, BrokenProcessPool):
    """A worker process (:mod:`adept_traj.process_pool`) ended without a word (killed, or
    out of memory); also a :class:`concurrent.futures.process.BrokenProcessPool`."""


class ResourceLimitError(InvalidInputError):
    """An option or input would need more memory, or a file is larger or deeper, than a
    documented limit (or than the machine has available): refused before the work starts.

    The message names the option (or file), its value, the estimate and the limit.
    """


class CollidingConfigurationError(InvalidInputError):
    """A start or goal configuration of a move is closer than the safety margin to an
    obstacle or to another of the robot's links: no move from or to it can be certified,
    so it is refused before any search (the message names the pair and the distance)."""


class UnreachableLocationError(InvalidInputError):
    """A tool location that the robot cannot reach: out of its workspace, or reachable only
    with a joint outside its limits, or (numeric inverse kinematics) not reached from any
    start.

    Attributes
    ----------
    location: the location's name (``"<pose>"`` when it has none).
    distance: how far it is out of reach, in ``unit`` (e.g. 0.12 [m] beyond the arm's
        reach, 0.3 [rad] beyond a joint limit, or the smallest residual of the numeric
        solver).
    unit: ``"m"`` or ``"rad"``.
    """

    def __init__(self, location: str, distance: float, unit: str, message: str) -> None:
        self.location = location
        self.distance = float(distance)
        self.unit = unit
        super().__init__(f"location {location!r}: {message}")


class CycleError(ConfigurationError):
    """A cycle file (``docs/cycles.md``) is missing or malformed, or a cycle run folder
    does not match its cycle. The message names the file, the field and the valid range."""


class FrozenObjectError(AdeptTrajError, dataclasses.FrozenInstanceError):
    """An attribute of a frozen object (a :class:`~adept_traj.problem.TrajectoryProblem`,
    a :class:`~adept_traj.robot.Robot`) was set or deleted after construction. Its
    ``replace(...)`` method makes a changed copy. A :class:`dataclasses.FrozenInstanceError`
    (an :class:`AttributeError`), as the frozen dataclasses of the package raise."""


def error_from_process(
    text: str, pickled: bytes | None, note: str, fallback: BaseException
) -> BaseException:
    """An exception raised in another (forked) process, to raise here: the exception
    ``pickled`` there, with that process' traceback ``text`` as a note (``note``, a colon,
    the traceback), or ``fallback`` if it does not unpickle (e.g. an exception class whose
    ``__init__`` needs other arguments)."""
    import pickle  # here: the command line's start-up never needs it

    try:
        error = pickle.loads(pickled) if pickled is not None else None
    except Exception:  # any failure to unpickle: the fallback, which holds the text
        error = None
    if not isinstance(error, BaseException):
        return fallback
    error.add_note(f"{note}:\n{text}")
    return error
