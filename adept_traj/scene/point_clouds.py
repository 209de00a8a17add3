r"""Point-cloud obstacles: a sensor's points as an octree of occupied cells (coal's ``OcTree``).

A :class:`PointCloud` holds points in its own frame and a ``resolution`` r [m]: coal's
``makeOctree`` marks every cell of edge r that holds a point as occupied, and distances are
coal's exact distances to those cells (cubes). Each point lies in its cell, so the distance
to the points is at least the reported one (and at most :math:`r\sqrt 3` more): **a
clearance certified against the octree holds for the points**, at the resolution stated
(:attr:`PointCloud.guarantee`). The cloud has no inside (it samples surfaces); a robot solid
overlapping an occupied cell is a collision (distance ≤ 0).

**Broad phase.** Besides its bounding box, a cloud has a coarse distance field
(:meth:`PointCloud.lower_bound`: cells of at least r, at most a million over the box, each
with the distance from its centre to the nearest occupied cell's), so a robot near a cloud
that surrounds it (a scanned fence) is bounded away from it without a coal call. Closer,
the collision checker's own levels take over (:mod:`adept_traj.collision.cloud_bounds`,
:mod:`adept_traj.collision.cloud_distance`; figures in ``docs/scene-files.md``).

Files: ``.ply`` (ASCII or binary, the vertex element's x, y, z), ``.pcd`` (ASCII or binary,
fields x, y, z), ``.xyz`` (text, the first three numbers of each line), ``.npy`` ((n, 3)
floats). The number of points is read from the header before the data, and a cloud whose
octree would need more memory than the budget (:mod:`adept_traj.memory`) is refused
before it is read; once read, the cloud with its distance fields (the checker's
cube-distance field up to :data:`CUBE_FIELD_CELLS` cells, sized from the points' box) is
checked again before any field or octree is made (:func:`check_cloud_memory`).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import coal
import numpy as np

from adept_traj.errors import InvalidInputError, MeshFileError, ResourceLimitError
from adept_traj.memory import check_memory
from adept_traj.scene.shapes import Shape
from adept_traj.validation import DerivedData, as_finite_array, as_scalar, readonly_copy

__all__ = [
    "CLOUD_SUFFIXES",
    "CUBE_FIELD_CELLS",
    "PointCloud",
    "check_cloud_memory",
    "cloud_bytes",
    "cube_field_step",
    "read_cloud_points",
]

#: File suffixes read as point clouds.
CLOUD_SUFFIXES = (".ply", ".pcd", ".xyz", ".npy")

#: Bytes per point: its (n, 3) float64 array twice (read, kept), coal's octree (≤ 480 B,
#: a point a cell), the coarse field's passes (≈ 100 B), the checker's leaf arrays
#: (``CloudCells``: ≤ 600 B a leaf) and their hierarchy (``CloudTree``: 459 B a leaf at
#: its making's peak); ``tracemalloc`` peaks, ``tests/scene/test_point_clouds.py``.
_BYTES_PER_POINT = 48 + 480 + 100 + 600 + 460

#: Most cells of a cloud's coarse distance field (4 MB of float32).
_FIELD_CELLS = 1_000_000

#: Most cells of the checker's cube-distance field
#: (:meth:`~adept_traj.collision.cloud_distance.CloudCells.point_bound`; 32 MB of float32).
CUBE_FIELD_CELLS = 8_000_000

#: Peak bytes per cell of the cube-distance field while it is built (the occupied and
#: dilated grids, scipy's distance transform with its feature transform, the float32
#: result kept): 51.4–51.8 B measured with ``tracemalloc``; plus the coarse field's.
_BYTES_PER_FIELD_CELL = 56


def cube_field_step(lo: Any, hi: Any, leaf: float) -> tuple[float, int]:
    """The cube edge h [m] of the cube-distance field over the box ``lo``–``hi`` (3,) [m]
    of the leaves, edge ``leaf`` [m]: the smallest power-of-2 multiple of ``leaf`` for at
    most :data:`CUBE_FIELD_CELLS` cells (with spares); and that number of cells."""
    extent = np.asarray(hi, dtype=float) - np.asarray(lo, dtype=float)
    h = float(leaf)
    while np.prod(np.ceil(extent / h) + 3) > CUBE_FIELD_CELLS:
        h *= 2.0
    return h, int(np.prod(np.ceil(extent / h) + 3))


def cloud_bytes(n_points: int, field_cells: int = 0) -> int:
    """Memory [B] a cloud of ``n_points`` points may need: its arrays and octree, and the
    distance fields — the coarse one (:data:`_FIELD_CELLS` at most) and the checker's
    cube-distance field of ``field_cells`` cells (:func:`cube_field_step`; 0 when not yet
    known, before the points are read)."""
    fields = _FIELD_CELLS * _BYTES_PER_FIELD_CELL if field_cells else 0
    return int(n_points) * _BYTES_PER_POINT + int(field_cells) * _BYTES_PER_FIELD_CELL + fields


def check_cloud_memory(
    points: np.ndarray, resolution: float, source: str, budget: int | None = None
) -> None:
    """Refuse a cloud whose arrays, octree and distance fields (:func:`cloud_bytes`, the
    cube-distance field's size from the points' box) exceed the memory budget, before any
    of them is made.

    Parameters
    ----------
    points: (n, 3) the cloud's points [m].
    resolution: the octree's cell edge [m].
    source: the file the points come from ("" for an array), for the message.
    budget: the limit [B] (default :func:`~adept_traj.memory.memory_budget`).

    Raises
    ------
    ResourceLimitError
        Naming the cloud (its file, or "an array"), its points, the estimate, the
        cube-distance field's cells and the limit.
    """
    lo, hi = points.min(axis=0) - resolution, points.max(axis=0) + resolution
    _, cells = cube_field_step(lo, hi, resolution)
    name = repr(source) if source else "an array"
    try:
        what = f"{name} ({len(points)} points)"
        check_memory(cloud_bytes(len(points), cells), "point cloud", what, budget)
    except ResourceLimitError as exc:
        raise ResourceLimitError(
            f"{exc} (about {_BYTES_PER_POINT} B per point and {_BYTES_PER_FIELD_CELL} B per "
            f"cell of its cube-distance field, {cells} cells at {resolution:g} m)"
        ) from None


@dataclass(frozen=True, eq=False)
class PointCloud(DerivedData, Shape):
    """Points in the cloud's frame, as an octree of cells of edge ``resolution``.

    Attributes
    ----------
    points: (n, 3) points [m], n ≥ 1.
    resolution: r, the octree's cell edge [m], positive.
    source: the file it was read from ("" if built from an array).
    """

    points: np.ndarray
    resolution: float
    source: str = ""
    kind: ClassVar[str] = "cloud"

    def __post_init__(self) -> None:
        p = as_finite_array(self.points, "points")
        if p.ndim != 2 or p.shape[1] != 3 or len(p) == 0:
            raise InvalidInputError(f"points must have shape (n, 3) [m], n ≥ 1; got {p.shape}")
        r = as_scalar(self.resolution, "resolution", "[m]", minimum=0.0, strict=True)
        check_cloud_memory(p, r, str(self.source))  # before the fields and the octree
        object.__setattr__(self, "points", readonly_copy(p))
        object.__setattr__(self, "resolution", r)
        object.__setattr__(self, "source", str(self.source))
        object.__setattr__(self, "_lo", p.min(axis=0) - r)  # cells reach r beyond a point
        object.__setattr__(self, "_hi", p.max(axis=0) + r)
        object.__setattr__(self, "_field", _coarse_field(p, r, self._lo, self._hi))  # type: ignore[attr-defined]

    @classmethod
    def from_file(
        cls, path: str | os.PathLike[str], resolution: float, *, budget: int | None = None
    ) -> PointCloud:
        """Read a cloud file (:func:`read_cloud_points`) at the octree ``resolution`` [m]."""
        r = as_scalar(resolution, "resolution", "[m]", minimum=0.0, strict=True)
        points, source = read_cloud_points(path, budget=budget), str(Path(path).resolve())
        check_cloud_memory(points, r, source, budget)  # with the distance fields
        return cls(points, r, source)

    @property
    def n_points(self) -> int:
        """Number of points."""
        return len(self.points)

    @property
    def guarantee(self) -> str:
        """What a distance to this cloud means, for certificates and reports."""
        return (
            f"distances to the occupied cells of a {self.resolution:g} m octree: the points "
            f"are at least that far (and at most {self.resolution * math.sqrt(3):.3g} m farther)"
        )

    @property
    def local_box(self) -> tuple[np.ndarray, np.ndarray]:
        """Corners (lo, hi) (3,) [m] of a box holding every occupied cell (cloud frame)."""
        return self._lo.copy(), self._hi.copy()  # type: ignore[attr-defined]

    @property
    def bounding_radius(self) -> float:
        """Largest distance from the frame's origin of a point, plus a cell diagonal [m]."""
        far = np.sqrt(np.einsum("ij,ij->i", self.points, self.points).max())
        return float(far + self.resolution * math.sqrt(3.0))

    def lower_bound(self, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray | None:
        """A lower bound [m] of the distance of points (x, y, z) (...) in the cloud frame to
        the occupied cells, from the coarse distance field (module docstring); None when
        the cloud has no field (it fits in a few coarse cells)."""
        field = self._field  # type: ignore[attr-defined]
        if field is None:
            return None
        origin, step, dist, slack = field
        shape = np.array(dist.shape)
        cell = [np.floor((c - o) / step) for c, o in zip((x, y, z), origin)]
        inside = np.ones(np.shape(cell[0]), dtype=bool)
        for c, n in zip(cell, shape):
            inside &= (c >= 0) & (c < n)
        idx = [np.clip(c, 0, n - 1).astype(np.int64) for c, n in zip(cell, shape)]
        return np.where(inside, dist[idx[0], idx[1], idx[2]] - slack, -np.inf)

    def to_coal(self) -> coal.OcTree:
        """A new ``coal.OcTree`` of the points at the resolution (``coal.makeOctree``)."""
        return coal.makeOctree(np.array(self.points), self.resolution)

    def __getstate__(self) -> dict[str, Any]:
        state = dict(self.__dict__)
        state.pop("_derived", None)  # coal objects, made again where needed
        return state


def _coarse_field(points: np.ndarray, r: float, lo: np.ndarray, hi: np.ndarray) -> Any:
    r"""The coarse distance field of a cloud: cubic cells of edge :math:`h` (the smallest
    multiple of r for at most :data:`_FIELD_CELLS` cells over the box), marked occupied
    where a point is, and each cell's Euclidean distance :math:`e` [m] between its centre
    and the nearest occupied cell's centre (``scipy.ndimage.distance_transform_edt``). A
    point p in cell c is at least :math:`e_c - h\sqrt 3 - r\sqrt 3` from every occupied
    octree cell (p is within :math:`h\sqrt3/2` of c's centre, every occupied octree cell
    within :math:`h\sqrt 3 / 2 + r\sqrt 3` of an occupied coarse cell's centre); the field
    covers the box (a point outside it gets no bound from it, ``-inf``). ``(origin (3,), h,
    e (nx, ny, nz) float32, slack)`` or None for a cloud of a few cells."""
    extent = hi - lo
    h = r * max(1.0, math.ceil((float(np.prod(extent)) / _FIELD_CELLS) ** (1.0 / 3.0) / r))
    dims = np.maximum(np.ceil(extent / h).astype(np.int64), 1)
    if int(np.prod(dims)) < 8:
        return None
    from scipy.ndimage import distance_transform_edt

    cells = np.minimum(((points - lo) / h).astype(np.int64), dims - 1)
    free = np.ones(tuple(dims.tolist()), dtype=bool)
    free[cells[:, 0], cells[:, 1], cells[:, 2]] = False
    dist = (distance_transform_edt(free) * h).astype(np.float32)
    slack = h * math.sqrt(3.0) + r * math.sqrt(3.0) + 1e-6  # + float32 rounding of e
    return lo.copy(), h, dist, slack


def read_cloud_points(path: str | os.PathLike[str], *, budget: int | None = None) -> np.ndarray:
    """The points (n, 3) [file units] of a cloud file (module docstring).

    Raises
    ------
    MeshFileError
        missing file, unknown suffix, a malformed header or data, no point
        (the message names the file).
    ResourceLimitError
        the cloud's octree would need more memory than ``budget`` [B]
        (default :func:`~adept_traj.memory.memory_budget`), from the header's point
        count, before the data is read.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in CLOUD_SUFFIXES:
        raise MeshFileError(
            f"point-cloud file {str(p)!r}: suffix {suffix!r} is not one of "
            f"{', '.join(CLOUD_SUFFIXES)}"
        )
    if not p.is_file():
        raise MeshFileError(f"point-cloud file {str(p)!r} does not exist (or is not a file)")
    try:
        with open(p, "rb") as f:
            points = _READERS[suffix](f, p, budget)
    except ResourceLimitError:
        raise
    except (OSError, ValueError, EOFError, KeyError, IndexError) as exc:
        raise MeshFileError(f"point-cloud file {str(p)!r} cannot be read: {exc}") from None
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    if len(points) == 0:
        raise MeshFileError(f"point-cloud file {str(p)!r} holds no point")
    if not np.isfinite(points).all():
        raise MeshFileError(f"point-cloud file {str(p)!r} holds a non-finite coordinate")
    return points


def _check_count(n: int, path: Path, budget: int | None) -> None:
    try:
        check_memory(cloud_bytes(n), "point cloud", f"{str(path)!r} ({n} points)", budget)
    except ResourceLimitError as exc:
        raise ResourceLimitError(f"{exc} (about {_BYTES_PER_POINT} B per point)") from None


def _read_npy(f: Any, path: Path, budget: int | None) -> np.ndarray:
    version = np.lib.format.read_magic(f)
    read = np.lib.format.read_array_header_1_0 if version == (1, 0) else None
    shape, _, dtype = (read or np.lib.format.read_array_header_2_0)(f)
    if len(shape) != 2 or shape[1] != 3 or dtype.kind != "f":
        raise ValueError(f"expected an (n, 3) float array; got {shape} of {dtype}")
    _check_count(shape[0], path, budget)
    f.seek(0)
    return np.load(f, allow_pickle=False)


def _read_xyz(f: Any, path: Path, budget: int | None) -> np.ndarray:
    _check_count(os.fstat(f.fileno()).st_size // 12, path, budget)  # ≥ 12 bytes a line
    rows = [line.split()[:3] for line in f.read().decode("ascii").splitlines()]
    rows = [r for r in rows if r and not r[0].startswith("#")]
    if any(len(r) < 3 for r in rows):
        raise ValueError("a line with fewer than 3 numbers")
    return np.array(rows, dtype=float)


def _header(f: Any, end: bytes, limit: int = 200) -> list[str]:
    lines = []
    for _ in range(limit):
        line = f.readline()
        if not line:
            raise ValueError("the header does not end")
        lines.append(line.decode("ascii", errors="replace").strip())
        if lines[-1].split()[:1] == [end.decode()]:
            return lines
    raise ValueError("header longer than 200 lines")


_PLY_TYPES = {"float": "f4", "float32": "f4", "double": "f8", "float64": "f8", "uchar": "u1",
              "uint8": "u1", "char": "i1", "int8": "i1", "short": "i2", "int16": "i2",
              "ushort": "u2", "uint16": "u2", "int": "i4", "int32": "i4", "uint": "u4",
              "uint32": "u4"}  # fmt: skip


def _read_ply(f: Any, path: Path, budget: int | None) -> np.ndarray:
    lines = _header(f, b"end_header")
    if lines[0] != "ply":
        raise ValueError("not a PLY file (no 'ply' first line)")
    fmt = next((ln.split()[1] for ln in lines if ln.startswith("format ")), "")
    count, props, element = None, [], None
    for ln in lines:
        words = ln.split()
        if words[:1] == ["element"]:
            element = words[1]
            if element == "vertex":
                count = int(words[2])
            elif count is None:
                raise ValueError("the vertex element must come first")
        elif words[:1] == ["property"] and element == "vertex":
            if words[1] == "list":
                raise ValueError("a list property in the vertex element")
            props.append((words[2], _PLY_TYPES[words[1]]))
    names = [n for n, _ in props]
    if count is None or not {"x", "y", "z"} <= set(names):
        raise ValueError("no vertex element with x, y, z")
    _check_count(count, path, budget)
    if fmt == "ascii":
        rows = [f.readline().split() for _ in range(count)]
        data = np.array(rows, dtype=float)
        return data[:, [names.index(c) for c in "xyz"]]
    order = {"binary_little_endian": "<", "binary_big_endian": ">"}.get(fmt)
    if order is None:
        raise ValueError(f"unknown PLY format {fmt!r}")
    dtype = np.dtype([(n, order + t) for n, t in props])
    data = np.frombuffer(f.read(dtype.itemsize * count), dtype=dtype, count=count)
    return np.column_stack([data[c] for c in "xyz"]).astype(float)


def _read_pcd(f: Any, path: Path, budget: int | None) -> np.ndarray:
    lines = _header(f, b"DATA")
    fields: dict[str, list[str]] = {ln.split()[0].upper(): ln.split()[1:] for ln in lines if ln}
    names = fields.get("FIELDS", [])
    if not {"x", "y", "z"} <= set(names):
        raise ValueError("no fields x, y, z")
    count = int(fields.get("POINTS", ["-1"])[0])
    if count < 0:
        raise ValueError("no POINTS line")
    _check_count(count, path, budget)
    mode = fields["DATA"][0]
    if mode == "ascii":
        data = np.array([f.readline().split() for _ in range(count)], dtype=float)
        return data[:, [names.index(c) for c in "xyz"]]
    if mode != "binary":
        raise ValueError(f"DATA {mode!r} not supported (ascii or binary)")
    kinds = {("F", "4"): "f4", ("F", "8"): "f8", ("U", "1"): "u1", ("U", "2"): "u2",
             ("U", "4"): "u4", ("I", "1"): "i1", ("I", "2"): "i2", ("I", "4"): "i4"}  # fmt: skip
    types = [kinds[(t, s)] for t, s in zip(fields["TYPE"], fields["SIZE"])]
    counts = [int(c) for c in fields.get("COUNT", ["1"] * len(names))]
    dtype = np.dtype(
        [(n, "<" + t, (c,)) if c > 1 else (n, "<" + t) for n, t, c in zip(names, types, counts)]
    )
    data = np.frombuffer(f.read(dtype.itemsize * count), dtype=dtype, count=count)
    return np.column_stack([data[c] for c in "xyz"]).astype(float)


_READERS = {".npy": _read_npy, ".xyz": _read_xyz, ".ply": _read_ply, ".pcd": _read_pcd}
