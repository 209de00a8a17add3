"""CAD-like meshes made in code, for the shipped example cell, the benchmarks and the docs:
tessellated boxes (a fixture, a guard), a table with legs (a concave closed mesh), and a
binary STL writer. Nothing here is used by the planner itself."""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np

from adept_traj.scene.meshes import merge_meshes

__all__ = ["box_mesh", "merge_meshes", "table_mesh", "write_stl"]


def box_mesh(size, subdivisions: int = 1, centre=(0.0, 0.0, 0.0)):
    """A closed, outward-oriented box mesh of full side lengths ``size`` (3,) [m] about
    ``centre`` (3,) [m], each face cut into s × s squares, s = ``subdivisions`` (12·s² triangles).

    Returns
    -------
    (vertices (n, 3) [m], triangles (m, 3) int), vertices shared between faces.
    """
    s = int(subdivisions)
    h = 0.5 * np.asarray(size, dtype=float)
    g = np.linspace(-1.0, 1.0, s + 1)
    verts: dict[tuple[float, float, float], int] = {}
    tris = []

    def index(p) -> int:
        key = tuple(np.round(p, 12))
        if key not in verts:
            verts[key] = len(verts)
        return verts[key]

    for axis in range(3):
        u, v = (axis + 1) % 3, (axis + 2) % 3
        for sign in (-1.0, 1.0):
            for i in range(s):
                for j in range(s):
                    corners = []
                    for a, b in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)):
                        p = np.zeros(3)
                        p[axis], p[u], p[v] = sign, g[a], g[b]
                        corners.append(index(p))
                    c0, c1, c2, c3 = corners if sign > 0 else corners[::-1]
                    tris += [(c0, c1, c2), (c0, c2, c3)]
    vertices = np.array(list(verts)) * h + np.asarray(centre, dtype=float)
    return vertices, np.array(tris, dtype=np.int64)


def table_mesh(top=(0.6, 0.4), height=0.4, thickness=0.04, leg=0.05, subdivisions=2):
    """A table (top and four legs, each a closed box shell) standing on z = 0: a concave,
    closed mesh (every shell closed), its frame at the centre of its footprint."""
    lx, ly = top
    parts = [box_mesh((lx, ly, thickness), subdivisions, (0.0, 0.0, height - 0.5 * thickness))]
    leg_h = height - thickness
    for sx in (-1, 1):
        for sy in (-1, 1):
            centre = (sx * (0.5 * lx - leg), sy * (0.5 * ly - leg), 0.5 * leg_h)
            parts.append(box_mesh((leg, leg, leg_h), subdivisions, centre))
    return merge_meshes(*parts)


def write_stl(path: str | os.PathLike[str], vertices, triangles, scale: float = 1.0) -> Path:
    """Write a binary STL (float32 triangle soup, normals from the corners) of the mesh,
    coordinates multiplied by ``scale`` (1000: a CAD file in millimetres); returns the path."""
    p = Path(path)
    v = np.asarray(vertices, dtype=float) * scale
    t = np.asarray(triangles)
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    n = np.cross(b - a, c - a)
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    record = np.zeros(len(t), dtype=[("n", "<f4", 3), ("p", "<f4", (3, 3)), ("attr", "<u2")])
    record["n"], record["p"] = n, np.stack([a, b, c], axis=1)
    with open(p, "wb") as f:
        f.write(b"adept_traj cad_meshes".ljust(80, b" "))
        f.write(struct.pack("<I", len(t)))
        f.write(record.tobytes())
    return p
