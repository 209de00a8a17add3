"""The shipped URDF is generated from its parameter file; link inertials come from solids."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from adept_traj.errors import InputShapeError, InvalidInputError, RobotModelError
from adept_traj.robot import (
    RobotParameters,
    box_inertia,
    build_urdf,
    combine,
    cylinder_inertia,
    link_mass_properties,
    sphere_inertia,
)
from adept_traj.transforms import rotation_from_rpy

ROOT = Path(__file__).resolve().parents[2]
TOML = ROOT / "urdf" / "adept_one_xl.toml"
URDF = ROOT / "urdf" / "adept_one_xl.urdf"


def test_shipped_urdf_is_up_to_date_with_its_parameter_file() -> None:
    assert URDF.read_text() == build_urdf(TOML), (
        "urdf/adept_one_xl.urdf is stale: run "
        "`adept-traj build-urdf urdf/adept_one_xl.toml --output urdf/adept_one_xl.urdf`"
    )


def test_two_half_boxes_make_one_box() -> None:
    half = box_inertia(2.0, (0.2, 0.3, 0.4))
    whole = combine(
        [
            (2.0, np.array([-0.1, 0.0, 0.0]), np.eye(3), half),
            (2.0, np.array([0.1, 0.0, 0.0]), np.eye(3), half),
        ]
    )
    assert whole.mass == 4.0
    np.testing.assert_allclose(whole.com, 0.0, atol=1e-15)
    np.testing.assert_allclose(whole.inertia, box_inertia(4.0, (0.4, 0.3, 0.4)), rtol=1e-12)


def test_cylinder_inertia_against_numerical_integration() -> None:
    mass, radius, length = 3.0, 0.1, 0.5
    n = 400  # midpoint rule in r (the integrand is polynomial in z and exact in angle)
    r = (np.arange(n) + 0.5) / n * radius
    ring_mass = mass * 2 * r / radius**2 / n * radius  # density of area 2 r dr / R^2
    izz = np.sum(ring_mass * r**2)
    ixx = np.sum(ring_mass * r**2 / 2) + mass * length**2 / 12
    np.testing.assert_allclose(np.diag(cylinder_inertia(mass, radius, length)), [ixx, ixx, izz],
                               rtol=1e-5)  # fmt: skip
    np.testing.assert_allclose(sphere_inertia(5.0, 0.2), np.eye(3) * 0.08)


def test_solid_inertias_equal_the_closed_forms() -> None:
    """The textbook formulas (the reference; the library calls pin.Inertia.From*)."""
    m, (sx, sy, sz) = 2.7, (0.3, 0.5, 0.11)
    box = np.diag([sy**2 + sz**2, sx**2 + sz**2, sx**2 + sy**2]) * m / 12
    np.testing.assert_allclose(box_inertia(m, (sx, sy, sz)), box, rtol=1e-14, atol=0)
    r, length = 0.07, 0.42
    ixx = m * (3 * r**2 + length**2) / 12
    cylinder = np.diag([ixx, ixx, m * r**2 / 2])
    np.testing.assert_allclose(cylinder_inertia(m, r, length), cylinder, rtol=1e-14, atol=0)
    np.testing.assert_allclose(sphere_inertia(m, r), np.eye(3) * 2 / 5 * m * r**2, rtol=1e-14,
                               atol=0)  # fmt: skip


def test_rotated_box_equals_box_with_permuted_sides() -> None:
    rot = rotation_from_rpy((0.0, 0.0, np.pi / 2))
    turned = combine([(1.0, np.zeros(3), rot, box_inertia(1.0, (0.1, 0.5, 0.2)))])
    np.testing.assert_allclose(turned.inertia, box_inertia(1.0, (0.5, 0.1, 0.2)), atol=1e-15)


def test_model_inertials_are_the_sum_of_link_solids() -> None:
    params = RobotParameters.from_file(TOML)
    model = pin.buildModelFromUrdf(str(URDF))
    link_of_joint = {j.child: model.getJointId(j.name) for j in params.joints}
    for link in params.links:
        if link.name not in link_of_joint:
            continue
        inertia = model.inertias[link_of_joint[link.name]]
        props = link_mass_properties(link)
        if props is None:
            assert inertia.mass == 0.0
            continue
        assert inertia.mass == pytest.approx(sum(s.mass for s in link.solids))
        np.testing.assert_allclose(inertia.lever, props.com, atol=1e-12)
        np.testing.assert_allclose(inertia.inertia, props.inertia, rtol=1e-12, atol=1e-15)
    # Link 4 (quill, flange, gripper) by hand: masses 2.5, 0.4, 1.5 at z = -0.058, 0.144, 0.179.
    com_z = (2.5 * -0.058 + 0.4 * 0.144 + 1.5 * 0.179) / 4.4
    assert model.inertias[4].lever[2] == pytest.approx(com_z)


def test_inertia_rejects_bad_values() -> None:
    with pytest.raises(
        InvalidInputError, match=r"mass must be a finite number > 0 \[kg\]; got -1.0"
    ):
        box_inertia(-1.0, (1, 1, 1))
    with pytest.raises(InvalidInputError, match=r"radius must be a finite number > 0 \[m\]"):
        cylinder_inertia(1.0, 0.0, 1.0)
    with pytest.raises(InvalidInputError, match=r"size_y must be a finite number > 0 \[m\]"):
        box_inertia(1.0, (0.1, -0.2, 0.3))
    with pytest.raises(InputShapeError, match=r"size must have shape \(3,\)"):
        box_inertia(1.0, (0.1, 0.2))
    with pytest.raises(InvalidInputError, match="mass"):
        sphere_inertia(True, 0.1)  # a bool is not a mass
    with pytest.raises(InvalidInputError, match="at least one solid"):
        combine([])


def test_builder_errors_name_the_item(tmp_path: Path) -> None:
    text = TOML.read_text()
    cases = [
        ("effort = 400.0", "", r"joint 'joint1': building a URDF needs \['effort'\]"),
        (
            'parent = "link1"\nchild = "link2"',
            'parent = "link1"\nchild = "link9"',
            "unknown link 'link9'",
        ),
        (
            'shape = "cylinder"\nradius = 0.14',
            'shape = "cylinder"',
            r"case2\.toml: field 'link\[0\]\.solid\[0\]\.radius': missing; must be a finite "
            r"number > 0 \[m\] \(in link 'base_link', solid 'column'\)$",
        ),
        (
            "mass = 1.5",
            "mass = 0.0",
            r"case3\.toml: field 'link\[4\]\.solid\[\d\]\.mass': must be a finite number > 0 "
            r"\[kg\]; got 0\.0 \(in link 'link4', solid 'gripper'\)$",
        ),
        (
            'shape = "cylinder"\nradius = 0.14',
            'shape = "box"\nradius = 0.14',
            r"case4\.toml: field 'link\[0\]\.solid\[0\]\.radius': unknown field; allowed "
            r"fields: 'name', 'shape', 'xyz', 'rpy', 'mass', 'rgba', 'size' \(in link 'base_link'",
        ),
    ]
    for k, (old, new, pattern) in enumerate(cases):
        assert old in text
        path = tmp_path / f"case{k}.toml"
        path.write_text(text.replace(old, new, 1))
        with pytest.raises(RobotModelError, match=pattern):
            build_urdf(path)
