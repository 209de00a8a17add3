r"""Sound collision meshes: every link mesh is replaced by its convex hull, with a stated gap.

coal treats a triangle mesh as a hollow surface: an obstacle wholly inside a link mesh is
reported *clear* (a positive distance to the nearest triangle), and penetration depths
between meshes are per triangle, not monotone. :func:`convex_hull_solids` therefore
replaces every mesh of a collision model by its **convex hull** (coal's ``buildConvexHull``,
qhull), which contains the link. For any obstacle :math:`O`:

.. math::
    d(\text{hull}, O) \le d(\text{mesh}, O) \le d(\text{hull}, O) + g

where :math:`g` is the hull's **gap** (:attr:`HullReport.gap`): the first inequality because
the hull contains the mesh (an obstacle inside or overlapping the link is a penetration of
the hull, never a clearance), the second because every point of the hull's surface lies
within :math:`g` of the mesh (the one-sided Hausdorff distance from hull to mesh; the
closest hull point to an outside obstacle is on the hull's surface). The gap is bounded on
request (:attr:`HullReport.gap`), conservatively: the faces of hull and mesh are sampled on
grids of spacing at most :data:`GAP_SAMPLE_STEP` (2 mm), and

.. math:: g = \max_{s} \min_{m} |s - m| + h

over the hull samples :math:`s` and the mesh samples :math:`m` (points of the mesh, so
:math:`d(s, \text{mesh}) \le |s - m|`), with :math:`h` the hull grid's largest cell edge
(the distance to the mesh is 1-Lipschitz). So the reported clearance is never larger than
the true clearance of the link, and at most :math:`g` smaller; :attr:`Robot.mesh_hulls
<adept_traj.robot.Robot.mesh_hulls>` gives :math:`g` per link.

Size budget: a hull with more than :data:`MAX_HULL_POINTS` vertices (coal's support
function is linear in them) is **simplified conservatively**: it is replaced by the
intersection of its supporting half-spaces in :data:`SIMPLIFY_DIRECTIONS` directions spread
over the sphere (a Fibonacci lattice),

.. math:: P = \{x : n_i \cdot x \le \max_{v \in \text{hull}} n_i \cdot v\},

a polytope that contains the hull (each half-space does), hence the mesh, with at most
about twice as many vertices as directions. It costs clearance: a distance to :math:`P` is
smaller than to the hull by at most :attr:`HullReport.extra` [m], the largest distance of
a vertex of :math:`P` to the hull (the distance to a convex set is convex: its largest value
over :math:`P` is at a vertex); :attr:`HullReport.gap` bounds the whole gap of :math:`P`
to the mesh. A warning names each simplified link with its extra clearance.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from functools import cached_property

import coal
import numpy as np
import pinocchio as pin

from adept_traj.errors import RobotModelError

__all__ = [
    "GAP_SAMPLE_STEP",
    "MAX_HULL_POINTS",
    "SIMPLIFY_DIRECTIONS",
    "HullReport",
    "bounding_polytope",
    "convex_hull_solids",
]

#: Largest spacing [m] of the samples on hull faces used to bound the gap.
GAP_SAMPLE_STEP = 2e-3

#: Most vertices a link's convex hull may have (the Jaco2's largest shipped hull has 1 498);
#: a larger hull is simplified (:func:`bounding_polytope`).
MAX_HULL_POINTS = 4000
#: Support directions of the polytope that replaces a hull with too many vertices.
SIMPLIFY_DIRECTIONS = 1000


@dataclass(frozen=True)
class HullReport:
    """How a link mesh became a convex hull.

    Attributes
    ----------
    solid: name of the collision solid (``"<link>_<k>"`` or ``"<link>/<name>"``).
    mesh_vertices, mesh_triangles: size of the mesh as loaded.
    hull_points: vertices of the solid used (the convex hull, or the polytope that
        replaced a hull with more than :data:`MAX_HULL_POINTS` vertices).
    simplified_from: vertices of the convex hull that was simplified (``None``: not).
    extra: bound [m] of the clearance the simplification costs against the exact hull
        (0: not simplified).
    """

    solid: str
    mesh_vertices: int
    mesh_triangles: int
    hull_points: int
    #: (the mesh as loaded, its hull), kept for :attr:`gap`.
    shapes: tuple[coal.BVHModelBase, coal.ConvexBase] = field(repr=False, compare=False)
    simplified_from: int | None = None
    extra: float = 0.0

    @cached_property
    def gap(self) -> float:
        """Bound [m] on how much smaller a distance to the hull can be than the distance to
        the mesh (see the module docstring; computed on first access: too slow for a large
        mesh to do at every load)."""
        mesh, hull = self.shapes
        return hull_gap(np.asarray(hull.points(), dtype=float), triangle_corners(mesh))


def convex_hull_solids(gm: pin.GeometryModel, source: object) -> tuple[HullReport, ...]:
    """Replace, in place, every triangle mesh of ``gm`` (a collision model freshly loaded, not
    yet shared) by its convex hull; return one :class:`HullReport` per replaced mesh.

    ``source`` (the URDF path) names the robot in messages.

    Raises
    ------
    RobotModelError
        A mesh without triangles, or a hull with more than :data:`MAX_HULL_POINTS`
        vertices.
    """
    reports = []
    for obj in gm.geometryObjects:
        mesh = obj.geometry
        if not isinstance(mesh, coal.BVHModelBase):
            continue
        if mesh.num_tris == 0 or mesh.num_vertices < 4:
            raise RobotModelError(f"{source}: collision mesh of '{obj.name}' has no volume")
        mesh.buildConvexHull(False, "Qt")
        hull, simplified, extra = mesh.convex, None, 0.0
        if hull.num_points > MAX_HULL_POINTS:
            simplified = int(hull.num_points)
            hull, extra = bounding_polytope(np.asarray(hull.points(), dtype=float), hull)
            if hull.num_points > MAX_HULL_POINTS:  # (not with the default directions)
                raise RobotModelError(
                    f"{source}: the convex hull of the collision mesh of '{obj.name}' has "
                    f"{simplified} vertices and its simplification {hull.num_points} (at "
                    f"most {MAX_HULL_POINTS}): give the link primitive collision shapes"
                )
            warnings.warn(
                f"{source}: the convex hull of the collision mesh of '{obj.name}' has "
                f"{simplified} vertices (at most {MAX_HULL_POINTS}): replaced by a polytope "
                f"of {hull.num_points} vertices that contains it; clearances to this link "
                f"are up to {extra * 1e3:.2f} mm smaller than to the hull",
                UserWarning,
                stacklevel=3,
            )
        reports.append(
            HullReport(
                solid=obj.name,
                mesh_vertices=int(mesh.num_vertices),
                mesh_triangles=int(mesh.num_tris),
                hull_points=int(hull.num_points),
                shapes=(mesh, hull),
                simplified_from=simplified,
                extra=extra,
            )
        )
        obj.geometry = hull
    return tuple(reports)


def bounding_polytope(
    points: np.ndarray, hull: coal.ConvexBase, n_directions: int = SIMPLIFY_DIRECTIONS
) -> tuple[coal.ConvexBase, float]:
    """The polytope (coal convex) bounded by the supporting planes of ``points`` (k, 3)
    [m] in ``n_directions`` directions of a Fibonacci lattice (it contains their convex
    hull ``hull``), and the largest distance [m] of its vertices to ``hull`` (module doc).
    """
    from scipy.spatial import HalfspaceIntersection  # lazy: scipy is heavy to import

    k = np.arange(n_directions) + 0.5
    z = 1.0 - 2.0 * k / n_directions
    phi = np.pi * (1.0 + 5.0**0.5) * k
    r = np.sqrt(1.0 - z * z)
    normals = np.column_stack([r * np.cos(phi), r * np.sin(phi), z])  # (n, 3) unit
    centre = points.mean(axis=0)
    offsets = (points - centre) @ normals.T  # (k, n): support values about the centre
    # n·(x − c) − h ≤ 0, each plane moved out by 1 µm so that rounding in the intersection
    # and the hull of its corners cannot cut a vertex of the mesh off
    halfspaces = np.column_stack([normals, -(offsets.max(axis=0) + 1e-6)])
    corners = HalfspaceIntersection(halfspaces, np.zeros(3)).intersections + centre
    vertices = coal.StdVec_Vec3s()
    for p in corners:
        vertices.append(p)
    polytope = coal.ConvexBase.convexHull(vertices, False, "Qt")
    # distance of each vertex to the hull (coal: a ball of radius 1 µm at the vertex)
    ball, request, at = coal.Sphere(1e-6), coal.DistanceRequest(), coal.Transform3s()
    extra = 0.0
    for p in np.asarray(polytope.points(), dtype=float):
        d = coal.distance(ball, coal.Transform3s(np.eye(3), p), hull, at, request,
                          coal.DistanceResult())  # fmt: skip
        extra = max(extra, d + 1e-6)
    return polytope, extra


def hull_gap(
    hull_points: np.ndarray, triangles: np.ndarray, step: float = GAP_SAMPLE_STEP
) -> float:
    """Upper bound [m] of the distance from any point of the convex hull of ``hull_points``
    (k, 3) [m] to the mesh of ``triangles`` (m, 3, 3) [m]: the largest distance from a
    sample of the hull's faces to the nearest sample of the mesh's faces (samples spaced at
    most ``step`` [m]; a mesh sample is on the mesh), plus the hull samples' largest cell
    edge (the distance to the mesh is 1-Lipschitz). Hull samples whose distance to a
    coarser mesh sampling is already at most the running maximum are not refined (that
    distance bounds theirs)."""
    from scipy.spatial import ConvexHull, cKDTree  # lazy: scipy is heavy to import

    hull_samples, cell = _surface_samples(hull_points[ConvexHull(hull_points).simplices], step)
    # Upper bounds first from coarse mesh samples (a far hull sample has many fine samples
    # within reach), then the fine samples only where the coarse bound may raise the max.
    coarse = cKDTree(_surface_samples(triangles, 5.0 * step)[0]).query(hull_samples)[0]
    fine = cKDTree(_surface_samples(triangles, step)[0])
    top = np.argsort(coarse)[-1000:]
    worst = float(fine.query(hull_samples[top])[0].max())
    rest = np.flatnonzero(coarse > worst)
    if rest.size:
        worst = max(worst, float(fine.query(hull_samples[rest])[0].max()))
    return worst + cell


def _surface_samples(triangles: np.ndarray, step: float) -> tuple[np.ndarray, float]:
    """Points (p, 3) on ``triangles`` (m, 3, 3), every triangle cut into a grid of
    sub-triangles with edges ≤ ``step``, and the largest sub-triangle edge."""
    edges = np.linalg.norm(triangles - np.roll(triangles, 1, axis=1), axis=2).max(axis=1)
    counts = np.maximum(1, np.ceil(edges / step)).astype(int)
    out, cell = [], 0.0
    for k in np.unique(counts).tolist():
        sel = counts == k
        i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
        keep = i + j <= k
        w = np.stack([i[keep], j[keep], k - i[keep] - j[keep]], axis=1) / k  # (p, 3)
        out.append(np.einsum("pa,mad->mpd", w, triangles[sel]).reshape(-1, 3))
        cell = max(cell, float(edges[sel].max()) / k)
    return np.concatenate(out), cell


def triangle_corners(mesh: coal.BVHModelBase) -> np.ndarray:
    """The triangles (m, 3, 3) [m] of a coal mesh, as vertex coordinates."""
    vertices = np.asarray(mesh.vertices(), dtype=float)
    index = np.array([[t[0], t[1], t[2]] for t in map(mesh.tri_indices, range(mesh.num_tris))])
    return vertices[index.reshape(-1, 3)]
