"""The hierarchy of a cloud's leaves and its batched descent (adept_traj.collision.cloud_tree)
and the batched search of (motion, cloud) pairs (cloud_search), against coal called directly:
its octree distance, and its distance of each solid to each leaf cube."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial.transform import Rotation

from adept_traj.collision import distance_request
from adept_traj.collision.cloud_distance import cloud_cells
from adept_traj.collision.cloud_search import cloud_obstacles
from adept_traj.collision.cloud_tree import cloud_tree, descend, solid_support

CAP = 0.05


SOLIDS = {
    "box": coal.Box(0.45, 0.1, 0.05),
    "cylinder": coal.Cylinder(0.05, 0.3),
    "capsule": coal.Capsule(0.04, 0.2),
    "sphere": coal.Sphere(0.07),
}


def test_every_level_holds_every_leaf_in_its_box_and_slab(fence):
    """Each level's nodes partition the leaves (contiguous runs, children inside their
    parent), every leaf cube lies in its node's box and, corner by corner, in its slab."""
    cells = cloud_cells(fence.to_coal(), fence)
    tree = cloud_tree(cells)
    k = len(cells.centre)
    assert len(tree.leaf_centre) == k
    assert len(tree.levels[-1].rep) == k
    assert len(tree.levels[0].rep) <= 16
    corners = np.array(np.meshgrid(*[[-1.0, 1.0]] * 3, indexing="ij")).reshape(3, -1).T
    for j, level in enumerate(tree.levels[:-1]):
        finer = tree.levels[j + 1]
        assert level.first[0] == 0
        assert level.first[-1] == len(finer.rep)
        assert (np.diff(level.first) > 0).all()
        # the leaves of each node: those of its children, down to the leaves
        span = level.first
        for nxt in tree.levels[j + 1 : -1]:
            span = nxt.first[span]
        node = np.repeat(np.arange(len(level.rep)), np.diff(span))
        assert len(node) == k
        pts = tree.leaf_centre[:, None, :] + tree.leaf_half[:, None, None] * corners  # (k, 8, 3)
        lo, hi = level.centre - level.half, level.centre + level.half
        assert (pts >= lo[node][:, None] - 1e-12).all()
        assert (pts <= hi[node][:, None] + 1e-12).all()
        along = np.einsum("kci,ki->kc", pts, level.normal[node])
        assert (along >= level.low[node][:, None] - 1e-12).all()
        assert (along <= level.high[node][:, None] + 1e-12).all()
        np.testing.assert_allclose(np.linalg.norm(level.normal, axis=1), 1.0)
        assert (node[level.rep] == np.arange(len(level.rep))).all()  # a leaf of its node


def _queries(rng, n, solid):
    """Poses (rotations (n, 3, 3), positions (n, 3)) of ``solid`` whose extent towards the
    fence (its support along the radius) ends −0.4 to 6 cm from the scan's leaves: most near
    the scan, some through it, some beyond the cap."""
    ang, z = rng.uniform(0, 2 * np.pi, n), rng.uniform(0.0, 0.6, n)
    rot = Rotation.random(n, random_state=int(rng.integers(1 << 30))).as_matrix()
    radial = np.column_stack([np.cos(ang), np.sin(ang), np.zeros(n)])
    reach = solid_support(solid, np.einsum("nji,nj->ni", rot, radial))
    side = rng.choice([-1.0, 1.0], n)
    rad = 1.0 - side * (reach + 0.005 + rng.uniform(-0.004, 0.06, n))  # 0.005: a leaf's half
    return rot, radial * rad[:, None] + np.column_stack([np.zeros((n, 2)), z])


@pytest.mark.parametrize("kind", sorted(SOLIDS))
def test_descent_bounds_and_finds_coal_nearest_leaf(fence, kind):
    """Against coal: every leaf bound left is at most coal's distance of the solid to that
    leaf; the floor of what was left out at most coal's octree distance of every query in
    the group; the upper bound at least the group's smallest octree distance; and where
    that is within the cap, coal's smallest leaf distance among the leaves left equals it
    (to 1e-6 m): the nearest leaf is never left out."""
    solid, octree = SOLIDS[kind], fence.to_coal()
    tree = cloud_tree(cloud_cells(octree, fence))
    rng = np.random.default_rng(len(kind))
    rot, pos = _queries(rng, 60, solid)
    group = np.repeat(np.arange(30), 2)  # two poses a group
    got = descend(tree, solid, rot, pos, group, np.full(30, CAP), np.full(30, np.inf))
    request, unit = distance_request(), coal.Transform3s()
    ref = np.array([
        coal.distance(solid, coal.Transform3s(r, p), octree, unit, request, coal.DistanceResult())
        for r, p in zip(rot, pos)
    ])  # fmt: skip
    leaf_d = np.array([
        coal.distance(solid, coal.Transform3s(rot[q], pos[q]),
                      coal.Box(*(2 * tree.leaf_half[leaf],) * 3),
                      coal.Transform3s(np.eye(3), tree.leaf_centre[leaf]),
                      request, coal.DistanceResult())
        for q, leaf in zip(got.query.tolist(), got.leaf.tolist())
    ])  # fmt: skip
    assert (got.bound <= leaf_d + 1e-9).all()
    best = np.full(30, np.inf)
    np.minimum.at(best, group, ref)
    low = got.floor.copy()  # the smallest bound of the group, left out or left
    np.minimum.at(low, group[got.query], got.bound)
    assert (low <= best + 1e-9).all()
    assert (got.upper >= best - 1e-9).all()
    found = np.full(30, np.inf)
    np.minimum.at(found, group[got.query], leaf_d)
    near = (best > 0.0) & (best <= CAP)
    assert near.sum() >= 5, best
    assert (best < 0.0).sum() >= 2, best
    np.testing.assert_allclose(found[near], best[near], atol=1e-6)
    inside = best < 0.0
    assert (found[inside] < 0.0).all()
    assert (got.floor[best > CAP] > CAP).all()


def _coal_minimum(robot, octree, tf_cloud, q):
    """Per motion of ``q`` (m, n_t, nq), the smallest coal octree distance over its
    samples and the robot's solids."""
    model, gm = robot.model, robot.collision_model
    data, gdata = model.createData(), gm.createData()
    request, out = distance_request(), np.full(q.shape[0], np.inf)
    for m in range(q.shape[0]):
        for n in range(q.shape[1]):
            pin.updateGeometryPlacements(model, data, gm, gdata, q[m, n])
            for k, obj in enumerate(gm.geometryObjects):
                tf = coal.Transform3s(gdata.oMg[k].rotation, gdata.oMg[k].translation)
                d = coal.distance(obj.geometry, tf, octree, tf_cloud, request,
                                  coal.DistanceResult())  # fmt: skip
                out[m] = min(out[m], d)
    return out


@pytest.mark.slow  # coal's octree distance, the reference, takes ms a call
def test_checker_searches_motions_beside_a_cloud_as_coal(fence_checker):
    """Motions of 6 samples past the fence (the batched search, many candidates a pair):
    the checker's smallest distance per motion equals coal's octree distance of every
    solid at every sample, called directly (to 1e-6 m within the influence, negative where
    coal finds a penetration, a lower bound above the influence beyond it)."""
    robot, checker = fence_checker  # the fence within the arm's reach
    assert checker.influence == CAP
    scene = checker.scene
    (ob,) = scene.obstacles
    fence = ob.shape
    assert cloud_obstacles(checker).all()
    rng = np.random.default_rng(9)
    lo, hi = robot.limits.lower, robot.limits.upper
    a, b = lo + (hi - lo) * rng.uniform(size=(2, 40, 1, robot.nq))
    q = a + (b - a) * np.linspace(0.0, 0.1, 6)[None, :, None]  # short straight moves
    got = checker.min_distances(q, np.zeros(q.shape[:-1]))
    pose = scene.base_from_world @ ob.pose(0.0)
    ref = _coal_minimum(robot, fence.to_coal(), coal.Transform3s(pose[:3, :3], pose[:3, 3]), q)
    d = got.distance[..., 0]
    inside, far = ref <= 0.0, ref > CAP
    near = ~inside & ~far
    assert min(inside.sum(), near.sum(), far.sum()) >= 5, (inside.sum(), near.sum(), far.sum())
    assert (d[inside] <= 0.0).all()
    np.testing.assert_allclose(d[near], ref[near], atol=1e-6)
    assert (got.sample[near, 0] >= 0).all()
    assert (got.solid[near, 0] >= 0).all()
    assert (d[far] > CAP).all()
    assert (d[far] <= ref[far] + 1e-9).all()
