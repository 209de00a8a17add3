"""Obstacle geometries: boxes, spheres, cylinders and capsules, convertible to coal shapes.

Every shape is centred on the origin of its own frame (the frame an obstacle's pose places in
the world): a :class:`Box` is centred with its edges along the local axes, a :class:`Cylinder`
and a :class:`Capsule` have their axis along the local z axis. Dimensions are in metres.

The shapes are frozen value objects: their array fields are new read-only numpy arrays, and
two shapes compare equal when their type and dimensions are equal. :meth:`Shape.to_coal`
returns a *new* coal collision geometry on every call (coal objects are mutable).
"""

from __future__ import annotations

import dataclasses
import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import coal
import numpy as np

from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.validation import (
    DeepEqual,
    as_finite_array,
    as_scalar,
    as_vector,
    describe_bad_values,
    readonly_copy,
)

__all__ = [
    "Box",
    "Capsule",
    "Cylinder",
    "Shape",
    "Sphere",
    "ValueObject",
    "coal_transform",
]


class ValueObject(DeepEqual):
    """Equality and hashing by field values, numpy arrays compared element-wise.

    A dataclass's generated ``__eq__`` fails on array fields (``bool(array == array)`` is
    ambiguous); frozen dataclasses of this package declare ``eq=False`` and inherit these
    (the equality of :class:`~adept_traj.validation.DeepEqual`, with a hash).
    """

    def _key(self) -> tuple[Any, ...]:
        values: list[Any] = []
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            value = getattr(self, f.name)
            if isinstance(value, np.ndarray):
                value = (value.shape, (value + 0.0).tobytes())  # + 0.0: -0.0 hashes as 0.0
            values.append(value)
        return tuple(values)

    def __hash__(self) -> int:
        return hash((type(self).__name__, self._key()))


def _store_positive_lengths(shape: Shape, *names: str) -> None:
    """Replace the named fields of a frozen ``shape`` by positive finite floats [m]."""
    for name in names:
        value = as_scalar(getattr(shape, name), name, "[m]", minimum=0.0, strict=True)
        object.__setattr__(shape, name, value)


def coal_transform(transform: np.ndarray) -> coal.Transform3s:
    """Return the coal rigid transform of a homogeneous transform.

    Parameters
    ----------
    transform: (4, 4) homogeneous transform (rotation block and translation [m]).

    Returns
    -------
    A new :class:`coal.Transform3s` with the same rotation and translation.
    """
    t = as_finite_array(transform, "transform")
    if t.shape != (4, 4):
        raise InputShapeError(f"transform must have shape (4, 4); got shape {t.shape}")
    return coal.Transform3s(np.ascontiguousarray(t[:3, :3]), np.ascontiguousarray(t[:3, 3]))


class Shape(ValueObject, ABC):
    """A solid centred on the origin of its local frame.

    Subclasses are frozen dataclasses; ``kind`` is the name used in scene files.
    """

    kind: ClassVar[str]

    @abstractmethod
    def to_coal(self) -> coal.ShapeBase:
        """Return a new coal collision geometry of this shape (local frame = coal's)."""

    @property
    @abstractmethod
    def bounding_radius(self) -> float:
        """Radius [m] of the smallest ball about the local origin that contains the shape."""


@dataclass(frozen=True, eq=False)
class Box(Shape):
    """Rectangular box centred on the origin, edges along the local axes.

    Attributes
    ----------
    size: (3,) full side lengths along local x, y, z [m]; positive, finite.
    """

    size: np.ndarray
    kind: ClassVar[str] = "box"

    def __post_init__(self) -> None:
        size = as_vector(self.size, "size", 3, "[m]")
        if (size <= 0.0).any():
            where = describe_bad_values(size, size <= 0.0)
            raise InvalidInputError(f"size must be 3 positive side lengths [m]; bad: {where}")
        object.__setattr__(self, "size", readonly_copy(size))

    def to_coal(self) -> coal.Box:
        """Return a new :class:`coal.Box` (coal takes the full side lengths)."""
        return coal.Box(*(float(s) for s in self.size))

    @property
    def bounding_radius(self) -> float:
        """Half the space diagonal, ``|size| / 2`` [m]."""
        return 0.5 * float(np.linalg.norm(self.size))


@dataclass(frozen=True, eq=False)
class Sphere(Shape):
    """Sphere centred on the origin.

    Attributes
    ----------
    radius: radius [m]; positive, finite.
    """

    radius: float
    kind: ClassVar[str] = "sphere"

    def __post_init__(self) -> None:
        _store_positive_lengths(self, "radius")

    def to_coal(self) -> coal.Sphere:
        """Return a new :class:`coal.Sphere`."""
        return coal.Sphere(self.radius)

    @property
    def bounding_radius(self) -> float:
        """The radius itself [m]."""
        return self.radius


@dataclass(frozen=True, eq=False)
class _AxialShape(Shape):
    """A solid of a radius and a length along local z, centred on the origin, made in coal
    by ``coal_class(radius, length)``: the base of :class:`Cylinder` and :class:`Capsule`."""

    radius: float
    length: float
    coal_class: ClassVar[type[coal.ShapeBase]]

    def __post_init__(self) -> None:
        _store_positive_lengths(self, "radius", "length")

    def to_coal(self) -> coal.ShapeBase:
        """Return a new coal shape of the class's kind (coal takes the radius and the length)."""
        return self.coal_class(self.radius, self.length)


@dataclass(frozen=True, eq=False)
class Cylinder(_AxialShape):
    """Solid cylinder centred on the origin, axis along local z (as :class:`coal.Cylinder`).

    Attributes
    ----------
    radius: radius [m]; positive, finite.
    length: full length along local z [m] (from z = -length/2 to +length/2); positive.
    """

    kind: ClassVar[str] = "cylinder"
    coal_class: ClassVar[type[coal.ShapeBase]] = coal.Cylinder

    @property
    def bounding_radius(self) -> float:
        """Distance from the centre to a rim point, ``hypot(radius, length / 2)`` [m]."""
        return math.hypot(self.radius, 0.5 * self.length)


@dataclass(frozen=True, eq=False)
class Capsule(_AxialShape):
    """Capsule (a segment swept by a ball) centred on the origin, axis along local z.

    Attributes
    ----------
    radius: radius of the swept ball [m]; positive, finite.
    length: length of the axis segment [m], excluding the two hemispherical caps (as
        :class:`coal.Capsule`); the capsule's total extent along z is
        ``length + 2 * radius``. Positive.
    """

    kind: ClassVar[str] = "capsule"
    coal_class: ClassVar[type[coal.ShapeBase]] = coal.Capsule

    @property
    def bounding_radius(self) -> float:
        """Distance from the centre to a cap tip, ``length / 2 + radius`` [m]."""
        return 0.5 * self.length + self.radius
