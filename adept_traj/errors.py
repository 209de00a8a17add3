"""The library's exception hierarchy.

Every error the library raises on purpose derives from :class:`AdeptTrajError`, so a caller
can catch them all with one clause. Input errors also derive from :class:`ValueError`
(or :class:`FileNotFoundError`) so that generic code keeps working.
"""

from __future__ import annotations

__all__ = [
    "AdeptTrajError",
    "ConfigurationError",
    "InputShapeError",
    "InvalidInputError",
    "JointLimitError",
    "RobotModelError",
    "SceneError",
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


class SceneError(AdeptTrajError):
    """A scene (file or object) is missing, malformed or inconsistent."""


class ConfigurationError(InvalidInputError):
    """Settings of a problem, an algorithm or a run are inconsistent."""
