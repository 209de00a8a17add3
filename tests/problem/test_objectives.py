"""Tests of the objective table and pymoo's sign convention (written out by hand), and of the
paper's collision penalty z3 (eqs. 13–16) against hand-computed values."""

from __future__ import annotations

import re

import numpy as np
import pytest

from adept_traj.errors import InputShapeError, InvalidInputError
from adept_traj.problem import (
    MAXIMISED,
    OBJECTIVE_NAMES,
    OBJECTIVES,
    from_pymoo,
    objectives,
    paper_penalty,
    to_pymoo,
)


def test_objective_table() -> None:
    assert OBJECTIVE_NAMES == ("z1", "z2", "z3", "z4", "z5", "z6")
    assert MAXIMISED == (False, False, False, True, False, False)  # only z4 (manipulability)
    assert [o.equation for o in OBJECTIVES] == [1, 2, 3, 4, 5, 6]
    assert [o.unit for o in OBJECTIVES] == ["s", "N²·m²·s", "-", "m²", "rad²/s⁵", "rad²/s³"]
    assert OBJECTIVES[0].label == "z1 time [s]"
    assert OBJECTIVES[3].label == "z4 min|det J| [m²] (max)"


def test_module_docstring_table_matches_the_objectives() -> None:
    """The table in objectives.py's docstring (the API page) says what OBJECTIVES holds."""
    rows = re.findall(r"^(z\d)\s.*?\s(\S+)\s+eq\. (\d)\s+(minimised|maximised)$",
                      objectives.__doc__, flags=re.M)  # fmt: skip
    assert [(r[0], r[1].replace("\\-", "-"), int(r[2]), r[3] == "maximised") for r in rows] == [
        (o.name, o.unit, o.equation, o.maximised) for o in OBJECTIVES
    ]


def test_pymoo_sign_convention() -> None:
    rng = np.random.default_rng(3)
    z = rng.normal(size=(4, 6))
    z[0, 3] = 0.0
    expected = np.column_stack([z[:, 0], z[:, 1], z[:, 2], -z[:, 3], z[:, 4], z[:, 5]])
    before = z.copy()
    F = to_pymoo(z)
    np.testing.assert_array_equal(F, expected)
    assert np.signbit(F[0, 3])  # -0.0: a true negation, as pymoo's F had it before
    np.testing.assert_array_equal(z, before)  # the caller's array is not changed
    back = from_pymoo(F)
    assert back.tobytes() == z.tobytes()  # bit for bit
    assert to_pymoo(z[0]).shape == (6,)
    assert to_pymoo(np.ones((2, 3, 6))).shape == (2, 3, 6)
    np.testing.assert_array_equal(to_pymoo(np.ones((2, 3, 6)))[..., 3], -1.0)


def test_pymoo_sign_convention_bad_input() -> None:
    with pytest.raises(
        InputShapeError, match=r"objectives must have shape \(\.\.\., 6\).*\(4, 5\)"
    ):
        to_pymoo(np.zeros((4, 5)))
    with pytest.raises(InputShapeError, match=r"F must have shape \(\.\.\., 6\).*\(\)"):
        from_pymoo(1.0)
    with pytest.raises(InvalidInputError, match="F must be a numeric array"):
        from_pymoo([["a"] * 6])


SPHERE_AXES = np.array([[0.5, 0.5, 0.5]])


CENTRE = np.array([1.0, 2.0, 3.0])


def test_paper_penalty_zero_outside() -> None:
    pts = CENTRE + np.array([[0.6, 0, 0], [0, -0.51, 0], [0.3, 0.3, 0.3], [2, 2, 2]])
    c = np.broadcast_to(CENTRE, (1, 4, 3))
    out = paper_penalty(pts, c, SPHERE_AXES)
    assert np.ndim(out) == 0
    assert float(out) == 0.0


def test_paper_penalty_sphere() -> None:
    # nearest point at r = 0.2 from the centre: r_e = (0.2 / 0.5)² = 0.16 → 1 / 0.16²
    pts = CENTRE + np.array([[0.4, 0, 0], [0, 0.2, 0], [0, 0, -0.3], [1, 1, 1]])
    c = np.broadcast_to(CENTRE, (1, 4, 3))
    assert float(paper_penalty(pts, c, SPHERE_AXES)) == pytest.approx(1.0 / 0.16**2, rel=1e-12)
    # on the surface: r_e = 1 counts as inside, penalty 1
    on = CENTRE + np.array([[0.5, 0.0, 0.0]])
    assert float(paper_penalty(on, c[:, :1], SPHERE_AXES)) == pytest.approx(1.0, rel=1e-12)


def test_paper_penalty_ellipsoid_and_moving_centre() -> None:
    axes = np.array([[0.5, 0.25, 1.0]])
    # r_e = 0.1²/0.5² + 0.1²/0.25² + 0.5²/1 = 0.04 + 0.16 + 0.25 = 0.45
    pts = np.zeros((3, 3))
    centres = -np.array([[[2.0, 0, 0], [0.1, 0.1, 0.5], [0, 0, 1.5]]])  # moves over time
    out = paper_penalty(pts, centres, axes)
    assert float(out) == pytest.approx(1.0 / 0.45**2, rel=1e-12)
    # along the long axis a point 0.9 away is inside, across it it is not
    assert float(paper_penalty([[0, 0, 0.9]], np.zeros((1, 1, 3)), axes)) == pytest.approx(
        1.0 / 0.81**2, rel=1e-12
    )
    assert float(paper_penalty([[0.9, 0, 0]], np.zeros((1, 1, 3)), axes)) == 0.0


def test_paper_penalty_sums_over_obstacles() -> None:
    pts = np.array([[0.2, 0, 0], [5.0, 5.0, 5.3]])
    centres = np.array([[[0, 0, 0]] * 2, [[5.0, 5.0, 5.0]] * 2, [[9.0, 9.0, 9.0]] * 2])
    axes = np.array([[0.5, 0.5, 0.5], [1.0, 1.0, 0.6], [0.1, 0.1, 0.1]])
    expected = 1.0 / (0.2 / 0.5) ** 4 + 1.0 / (0.3 / 0.6) ** 4
    assert float(paper_penalty(pts, centres, axes)) == pytest.approx(expected, rel=1e-12)


def penalty_by_hand(points: np.ndarray, centres: np.ndarray, axes: np.ndarray) -> float:
    """Eqs. 15–16 of one motion with plain loops: per obstacle o the smallest
    r_e = Σ_i ((p_i − c_i) / a_i)² over the samples (points (n_t, 3), centres (n_obs, n_t, 3)),
    adding 1 / r_e² when r_e ≤ 1."""
    total = 0.0
    for o in range(len(axes)):
        r_e = min(
            sum(((p[i] - c[i]) / axes[o][i]) ** 2 for i in range(3))
            for p, c in zip(points, centres[o])
        )
        if r_e <= 1.0:
            total += 1.0 / r_e**2
    return total


def test_paper_penalty_batched() -> None:
    rng = np.random.default_rng(41)
    n_obs, n_t = 2, 5
    pts = rng.uniform(-1, 1, size=(3, 4, n_t, 3))
    centres = rng.uniform(-1, 1, size=(n_obs, 3, 4, n_t, 3))
    axes = np.array([[0.6, 0.5, 0.7], [0.8, 0.8, 0.8]])
    out = paper_penalty(pts, centres, axes)
    assert out.shape == (3, 4)
    expected = [
        [penalty_by_hand(pts[i, j], centres[:, i, j], axes) for j in range(4)] for i in range(3)
    ]
    np.testing.assert_allclose(out, expected, rtol=1e-12)
    assert (out > 0).any()
    assert (out == 0).any()
    # centres shared by every motion, given with singleton batch axes
    shared = centres[:, :1, :1]
    out = paper_penalty(pts, shared, axes)
    expected = [
        [penalty_by_hand(pts[i, j], shared[:, 0, 0], axes) for j in range(4)] for i in range(3)
    ]
    np.testing.assert_allclose(out, expected, rtol=1e-12)


def test_paper_penalty_centres_broadcast_over_motions() -> None:
    pts = np.array([[[0.0, 0.0, 0.0]], [[0.1, 0.0, 0.0]]])  # 2 motions, 1 sample
    centres = np.array([[[0.0, 0.0, 0.0]], [[10.0, 10.0, 10.0]]])  # 2 obstacles, 1 time
    axes = np.full((2, 3), 0.5)
    out = paper_penalty(pts, centres, axes)
    # motion 0 sits on obstacle 0's centre: r_e = 0, which the library floors at 1e-12: 1 / 1e-24;
    # motion 1 at 0.1 from it: r_e = (0.1 / 0.5)² = 0.04, 1 / 0.04² = 625; obstacle 1 is far
    np.testing.assert_allclose(out, [1e24, 625.0], rtol=1e-12)


@pytest.mark.parametrize(
    "axes",
    [
        np.array([[0.5, 0.0, 0.5]]),
        np.array([[0.5, -0.1, 0.5]]),
        np.array([0.5, 0.5, 0.5]),  # missing the obstacle axis
        np.array([[0.5, 0.5]]),
        np.array([[0.5, np.nan, 0.5]]),
    ],
)
def test_paper_penalty_bad_semi_axes(axes: np.ndarray) -> None:
    with pytest.raises(InvalidInputError):
        paper_penalty(np.zeros((2, 3)), np.zeros((1, 2, 3)), axes)


@pytest.mark.parametrize(
    ("points", "centres"),
    [
        (np.zeros((2, 2)), np.zeros((1, 2, 3))),  # points not (..., 3)
        (np.zeros((2, 3)), np.zeros((1, 2, 4))),  # centres not (..., 3)
        (np.zeros((2, 3)), np.zeros((2, 2, 3))),  # 2 centres for 1 obstacle
    ],
)
def test_paper_penalty_bad_shapes(points: np.ndarray, centres: np.ndarray) -> None:
    with pytest.raises(InputShapeError):
        paper_penalty(points, centres, SPHERE_AXES)


def test_paper_penalty_mismatched_times_is_a_shape_error() -> None:
    with pytest.raises(InputShapeError):
        paper_penalty(np.zeros((4, 3)), np.zeros((1, 5, 3)), SPHERE_AXES)
    with pytest.raises(InputShapeError):
        paper_penalty(np.zeros((2, 4, 3)), np.zeros((1, 3, 4, 3)), SPHERE_AXES)


def test_paper_penalty_points_need_a_time_axis() -> None:
    centres = np.array([[0.1, 0.0, 0.0], [0.3, 0.0, 0.0]])
    with pytest.raises(InputShapeError):
        paper_penalty(np.zeros(3), centres, np.full((2, 3), 0.5))


def test_paper_penalty_rejects_nan() -> None:
    with pytest.raises(InvalidInputError, match="points"):
        paper_penalty([[np.nan, 0, 0]], np.zeros((1, 1, 3)), SPHERE_AXES)
    with pytest.raises(InvalidInputError, match="centres"):
        paper_penalty([[0, 0, 0]], np.full((1, 1, 3), np.inf), SPHERE_AXES)


def test_paper_penalty_equation_14_and_rotated_ellipsoids() -> None:
    # Eq. 14: a point at r_t = 0.5 inside a sphere of r0 = 1 gives 1 / 0.5**2 = 4.
    pts = np.array([[0.5, 0.0, 0.0], [2.0, 0.0, 0.0]])
    centre = np.zeros((1, 1, 3))
    assert float(paper_penalty(pts, centre, np.ones((1, 3)), equation=14)) == pytest.approx(4.0)
    with pytest.raises(InvalidInputError, match="equal semi-axes"):
        paper_penalty(pts, centre, np.array([[1.0, 2.0, 1.0]]), equation=14)
    with pytest.raises(InvalidInputError, match="equation must be 14"):
        paper_penalty(pts, centre, np.ones((1, 3)), equation=15)
    # A long ellipsoid along its own x axis, turned 90° about z: a point on the world y axis
    # is inside only when the rotation is taken into account.
    axes = np.array([[1.0, 0.1, 0.1]])
    point = np.array([[0.0, 0.5, 0.0]])
    turn = np.array([[[[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]]])  # Rz(90°)
    assert float(paper_penalty(point, centre, axes)) == 0.0  # axis-aligned: outside
    inside = float(paper_penalty(point, centre, axes, rotations=turn))
    assert inside == pytest.approx(1.0 / 0.25**2)  # r_e = 0.5² / 1²


def test_paper_semi_axes_closed_form() -> None:
    """Eq. 13: a sphere of the shape's bounding radius; eq. 15 (``paper-ellipsoid``): a box's
    semi-axes √3 × its half sides, other shapes still spheres."""
    from adept_traj.problem import paper_semi_axes
    from adept_traj.scene import Box, Obstacle, Sphere

    obstacles = (Obstacle("box", Box((0.2, 0.4, 0.6))), Obstacle("ball", Sphere(0.1)))
    sphere = paper_semi_axes(obstacles, "paper-sphere")
    ellipsoid = paper_semi_axes(obstacles, "paper-ellipsoid")
    half_diagonal = 0.5 * np.sqrt(0.2**2 + 0.4**2 + 0.6**2)
    np.testing.assert_allclose(sphere, [[half_diagonal] * 3, [0.1] * 3], rtol=1e-15)
    np.testing.assert_allclose(
        ellipsoid, [[0.1 * 3**0.5, 0.2 * 3**0.5, 0.3 * 3**0.5], [0.1] * 3], rtol=1e-15
    )
    assert paper_semi_axes((), "paper-sphere").shape == (0, 3)
