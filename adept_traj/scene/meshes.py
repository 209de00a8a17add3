r"""Mesh obstacles: triangle meshes read from CAD files (STL, OBJ, DAE, PLY…), with an inside test.

A :class:`Mesh` is a triangle mesh in its own frame (the frame of the CAD file, scaled;
an obstacle's pose places that frame in the world; the mesh is *not* re-centred). Its
distances are coal's exact distances to the triangles (:meth:`Mesh.to_coal`: a
``coal.BVHModelOBBRSS``). Those see the *surface* only: a robot solid wholly inside a
closed mesh is at a positive distance from every triangle. So a closed mesh also answers
"is this point inside?" by its generalised winding number (Jacobson et al. 2013),

.. math::
    w(p) = \frac{1}{4\pi} \sum_{\text{triangles } (a, b, c)} \Omega_{abc}(p), \qquad
    \tan\frac{\Omega}{2} = \frac{\mathbf a \cdot (\mathbf b \times \mathbf c)}
    {|\mathbf a||\mathbf b||\mathbf c| + (\mathbf a\cdot\mathbf b)|\mathbf c|
    + (\mathbf b\cdot\mathbf c)|\mathbf a| + (\mathbf c\cdot\mathbf a)|\mathbf b|},

with :math:`\mathbf a = a - p` etc.: :math:`|w| = 1` inside a closed, consistently oriented
mesh, 0 outside (exactly, up to rounding, away from the surface; no ray, so no degenerate
ray–edge hits). The collision checker flips the sign of a distance when the solid's witness
point is inside (:mod:`adept_traj.collision.mesh_distance`).

**Closed** means every edge (after joining vertices at equal coordinates, as an STL file's
triangle soup needs) is shared by exactly two triangles that traverse it in opposite
directions. An open mesh (a single wall, a sheet) is a thin surface: no inside test; an
:class:`~adept_traj.errors.OpenMeshWarning` says so when it is built.
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import coal
import numpy as np

from adept_traj.errors import InvalidInputError, MeshFileError, OpenMeshWarning
from adept_traj.scene.shapes import Shape
from adept_traj.validation import as_finite_array, readonly_copy

__all__ = ["MAX_MESH_TRIANGLES", "MESH_SUFFIXES", "Mesh", "merge_meshes", "read_mesh_arrays"]

#: Most triangles one mesh may have (8 million: about 0.6 GB of vertices, triangles and
#: coal's bounding-volume tree); a larger mesh is refused before it is built.
MAX_MESH_TRIANGLES = 8_000_000

#: File suffixes read as meshes (through coal's assimp loader).
MESH_SUFFIXES = (".stl", ".obj", ".dae", ".ply", ".off")

#: Largest mesh file read [B] (1 GiB), checked before the loader sees it.
_MAX_MESH_FILE_BYTES = 2**30

#: Points × triangles per block of the winding-number sum (about 100 MB of temporaries).
_BLOCK = 2_000_000


def _unit_scale(scale: Any) -> np.ndarray:
    s = as_finite_array(scale, "scale")
    if s.ndim == 0:
        s = np.full(3, float(s))
    if s.shape != (3,) or (s <= 0.0).any():
        raise InvalidInputError(
            f"scale must be a positive number or 3 positive numbers [-]; got {s.tolist()!r}"
        )
    return s


@dataclass(frozen=True, eq=False)
class Mesh(Shape):
    """A triangle mesh obstacle in its own frame (see the module docstring).

    Attributes
    ----------
    vertices: (n, 3) vertex positions in the mesh frame [m] (already scaled).
    triangles: (m, 3) int vertex indices of each triangle (m ≥ 1).
    source: the file it was read from ("" if built from arrays); scene files write it.
    scale: (3,) the scale applied to the file's coordinates [-] (CAD in mm: 0.001).
    """

    vertices: np.ndarray
    triangles: np.ndarray
    source: str = ""
    scale: np.ndarray = field(default_factory=lambda: np.ones(3))
    kind: ClassVar[str] = "mesh"

    def __post_init__(self) -> None:
        v = as_finite_array(self.vertices, "vertices")
        if v.ndim != 2 or v.shape[1] != 3 or len(v) < 3:
            raise InvalidInputError(
                f"vertices must have shape (n, 3) [m] with n ≥ 3; got shape {v.shape}"
            )
        tri = np.asarray(self.triangles)
        if tri.ndim != 2 or tri.shape[1] != 3 or len(tri) == 0:
            raise InvalidInputError(f"triangles must have shape (m, 3), m ≥ 1; got {tri.shape}")
        if tri.dtype.kind not in "iu" or tri.min() < 0 or tri.max() >= len(v):
            raise InvalidInputError(
                f"triangles must hold integer vertex indices in [0, {len(v) - 1}]"
            )
        if len(tri) > MAX_MESH_TRIANGLES:
            raise InvalidInputError(
                f"mesh {self.source or '<arrays>'}: {len(tri)} triangles, more than the limit "
                f"MAX_MESH_TRIANGLES = {MAX_MESH_TRIANGLES}"
            )
        tri = tri.astype(np.int64)  # a new array
        tri.setflags(write=False)
        object.__setattr__(self, "vertices", readonly_copy(v))
        object.__setattr__(self, "triangles", tri)
        object.__setattr__(self, "source", str(self.source))
        object.__setattr__(self, "scale", readonly_copy(_unit_scale(self.scale)))
        corners = v[tri]  # (m, 3, 3): not fields
        object.__setattr__(
            self, "_corners", [np.ascontiguousarray(corners[:, i]) for i in range(3)]
        )
        object.__setattr__(self, "_lo", v.min(axis=0))
        object.__setattr__(self, "_hi", v.max(axis=0))
        closed = _is_closed(v, tri)
        object.__setattr__(self, "_closed", closed)
        if not closed:
            warnings.warn(
                f"mesh {self.source or '<arrays>'} is not closed (an edge is not shared by "
                "exactly two consistently oriented triangles): it is treated as a thin "
                "surface, a robot solid inside it is not seen",
                OpenMeshWarning,
                stacklevel=3,
            )

    @classmethod
    def from_file(cls, path: str | os.PathLike[str], scale: Any = 1.0) -> Mesh:
        """Read a mesh file (:data:`MESH_SUFFIXES`, by coal's assimp loader) and scale it.

        Parameters
        ----------
        path: the file.
        scale: a positive number or (3,) per-axis factors applied to the file's
            coordinates [-] (0.001 for a CAD file in millimetres).

        Raises
        ------
        MeshFileError
            the file does not exist, is too large, cannot be read, or holds
            no triangle (the message names the file).
        """
        s = _unit_scale(scale)
        vertices, triangles = read_mesh_arrays(path)
        return cls(vertices * s, triangles, str(Path(path).resolve()), s)

    # ------------------------------------------------------------------ geometry
    @property
    def closed(self) -> bool:
        """True when the mesh is closed and consistently oriented (an inside test exists)."""
        return bool(self._closed)  # type: ignore[attr-defined]

    @property
    def local_box(self) -> tuple[np.ndarray, np.ndarray]:
        """Corners ``(lo, hi)`` (3,) [m] of the vertices' bounding box in the mesh frame."""
        return self._lo.copy(), self._hi.copy()  # type: ignore[attr-defined]

    @property
    def n_triangles(self) -> int:
        """Number of triangles."""
        return len(self.triangles)

    @property
    def bounding_radius(self) -> float:
        """Largest distance of a vertex from the mesh frame's origin [m]."""
        return float(np.sqrt(np.einsum("ij,ij->i", self.vertices, self.vertices).max()))

    def to_coal(self) -> coal.BVHModelOBBRSS:
        """Return a new ``coal.BVHModelOBBRSS`` of the triangles (mesh frame = coal's)."""
        model = coal.BVHModelOBBRSS()
        model.beginModel(len(self.triangles), len(self.vertices))
        model.addVertices(np.array(self.vertices))  # writable copies: eigenpy refuses read-only
        model.addTriangles(np.array(self.triangles))
        model.endModel()
        return model

    def winding_number(self, points: Any) -> np.ndarray:
        """Generalised winding number (k,) of points (k, 3) in the mesh frame [m] (module
        docstring): ±1 inside a closed mesh, 0 outside."""
        p = as_finite_array(points, "points").reshape(-1, 3)
        a0, b0, c0 = self._corners  # type: ignore[attr-defined]
        out = np.empty(len(p))
        step = max(1, _BLOCK // len(a0))
        for i in range(0, len(p), step):
            q = p[i : i + step, None, :]
            a, b, c = a0 - q, b0 - q, c0 - q  # (k, m, 3)
            la, lb, lc = (np.sqrt(np.einsum("...i,...i->...", x, x)) for x in (a, b, c))
            det = np.einsum("...i,...i->...", a, np.cross(b, c))
            den = (
                la * lb * lc
                + np.einsum("...i,...i->...", a, b) * lc
                + np.einsum("...i,...i->...", b, c) * la
                + np.einsum("...i,...i->...", c, a) * lb
            )
            out[i : i + step] = np.arctan2(det, den).sum(axis=-1) / (2.0 * math.pi)
        return out

    def contains(self, points: Any) -> np.ndarray:
        """(k,) bool: points (k, 3) in the mesh frame [m] strictly inside the closed mesh
        (``|w| > 1/2``; points outside the bounding box are answered without the sum). An
        open mesh has no inside: all False."""
        p = as_finite_array(points, "points").reshape(-1, 3)
        out = np.zeros(len(p), dtype=bool)
        if not self.closed:
            return out
        box = ((p >= self._lo) & (p <= self._hi)).all(axis=1)  # type: ignore[attr-defined]
        if box.any():
            out[box] = np.abs(self.winding_number(p[box])) > 0.5
        return out


def _is_closed(vertices: np.ndarray, triangles: np.ndarray) -> bool:
    """Whether every edge, vertices joined at equal coordinates, is traversed exactly once
    in each direction (degenerate triangles left out)."""
    _, weld = np.unique(vertices, axis=0, return_inverse=True)
    t = weld.reshape(-1)[triangles]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 2] != t[:, 0])]
    if len(t) == 0:
        return False
    n = int(t.max()) + 1
    directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    code = directed[:, 0] * n + directed[:, 1]
    unique, counts = np.unique(code, return_counts=True)
    if (counts != 1).any():
        return False
    reverse = np.sort(directed[:, 1] * n + directed[:, 0])
    return bool(np.array_equal(unique, reverse))


def read_mesh_arrays(path: str | os.PathLike[str]) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) [file units] and triangles (m, 3) of a mesh file, through coal's
    assimp loader (STL, OBJ, DAE, PLY, OFF…).

    Raises
    ------
    MeshFileError
        missing file, a suffix not in :data:`MESH_SUFFIXES`, larger than
        1 GiB, unreadable by the loader, or no triangle; the message names the file.
    """
    p = Path(path)
    if p.suffix.lower() not in MESH_SUFFIXES:
        raise MeshFileError(
            f"mesh file {str(p)!r}: suffix {p.suffix!r} is not one of {', '.join(MESH_SUFFIXES)}"
        )
    if not p.is_file():
        raise MeshFileError(f"mesh file {str(p)!r} does not exist (or is not a file)")
    size = p.stat().st_size
    if size > _MAX_MESH_FILE_BYTES:
        raise MeshFileError(
            f"mesh file {str(p)!r}: {size} bytes, more than the limit {_MAX_MESH_FILE_BYTES}"
        )
    try:
        model = coal.MeshLoader().load(str(p), np.ones(3))
    except (ValueError, RuntimeError) as exc:
        reason = " ".join(str(exc).split("message:")[-1].split()).split(" Hint:")[0]
        raise MeshFileError(f"mesh file {str(p)!r} cannot be read: {reason}") from None
    if model.num_tris == 0 or model.num_vertices < 3:
        raise MeshFileError(f"mesh file {str(p)!r} holds no triangle")
    if model.num_tris > MAX_MESH_TRIANGLES:
        raise MeshFileError(
            f"mesh file {str(p)!r}: {model.num_tris} triangles, more than the limit "
            f"MAX_MESH_TRIANGLES = {MAX_MESH_TRIANGLES}"
        )
    vertices = np.array(model.vertices(), dtype=float).reshape(-1, 3)
    tri = [model.tri_indices(i) for i in range(model.num_tris)]
    triangles = np.array([(t[0], t[1], t[2]) for t in tri], dtype=np.int64).reshape(-1, 3)
    if not np.isfinite(vertices).all():
        raise MeshFileError(f"mesh file {str(p)!r} holds a non-finite vertex coordinate")
    return vertices, triangles


def merge_meshes(*meshes: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """One triangle mesh of several ``(vertices (v, 3), triangles (f, 3))``: the vertices
    stacked and each mesh's triangle indices shifted by the vertices before it (not a
    boolean union: overlapping parts stay separate shells)."""
    vs, ts, offset = [], [], 0
    for v, t in meshes:
        vs.append(v)
        ts.append(t + offset)
        offset += len(v)
    return np.vstack(vs), np.vstack(ts)
