"""Shapes: area, inertia, mass, inradius and vertices of disks and regular polygons."""

from __future__ import annotations

import numpy as np
import pytest

from grainview.contract.errors import ParameterError
from solver import shapes

from . import naive_geometry as naive


def test_known_areas():
    # unit square of circumscribed radius sqrt(2)/2 (side 1): area 1; triangle of R = 1:
    # side sqrt(3), area 3 sqrt(3)/4; pentagon of R = 1: (5/2) sin 72 deg; disk: pi
    r = np.array([np.sqrt(0.5), 1.0, 1.0, 2.0])
    n = np.array([4, 3, 5, 0])
    expected = [1.0, 3 * np.sqrt(3) / 4, 2.5 * np.sin(np.radians(72)), 4 * np.pi]
    np.testing.assert_allclose(shapes.polygon_area(r, n), expected, rtol=1e-14)


def test_known_inertia_per_mass():
    # square side s: I/m = s^2/6; equilateral triangle side a: I/m = a^2/12; disk R^2/2
    r = np.array([np.sqrt(0.5), 1.0, 3.0])
    n = np.array([4, 3, 0])
    expected = [1.0 / 6.0, 3.0 / 12.0, 4.5]
    np.testing.assert_allclose(shapes.polygon_inertia_per_mass(r, n), expected, rtol=1e-14)


def test_large_n_tends_to_disk():
    r = np.array([1.0])
    np.testing.assert_allclose(shapes.polygon_area(r, [4000]), np.pi, rtol=1e-6)
    np.testing.assert_allclose(shapes.polygon_inertia_per_mass(r, [4000]), 0.5, rtol=1e-6)


@pytest.mark.parametrize("n", [3, 5, 6, 8])
def test_area_and_inertia_against_numerical_integration(n):
    r, theta = 0.7, 0.3
    verts = naive.polygon(1.5, -2.0, r, theta, n)
    area, polar = naive.fan_area_and_polar_moment(verts)
    np.testing.assert_allclose(shapes.polygon_area([r], [n])[0], area, rtol=1e-10)
    np.testing.assert_allclose(shapes.polygon_inertia_per_mass([r], [n])[0], polar / area, rtol=1e-12)


def test_mass_and_inertia_slab():
    r = np.array([0.0125, 0.025, 0.02])
    n = np.array([5, 5, 0])
    mass, inertia = shapes.mass_and_inertia(r, n, density=2600.0, thickness=0.5)
    expected_mass = 2600.0 * 0.5 * np.array([2.5 * np.sin(np.radians(72)) * r[0] ** 2,
                                              2.5 * np.sin(np.radians(72)) * r[1] ** 2,
                                              np.pi * r[2] ** 2])
    np.testing.assert_allclose(mass, expected_mass, rtol=1e-14)
    cos72 = np.cos(np.radians(72))
    np.testing.assert_allclose(inertia, expected_mass * np.array([r[0] ** 2 * (2 + cos72) / 6,
                                                                    r[1] ** 2 * (2 + cos72) / 6,
                                                                    r[2] ** 2 / 2]), rtol=1e-14)
    assert mass.dtype == np.float64 and inertia.dtype == np.float64


def test_inradius():
    np.testing.assert_allclose(shapes.inradius([2.0, 2.0, 1.0], [4, 6, 0]),
                               [np.sqrt(2.0), np.sqrt(3.0), 1.0], rtol=1e-14)


def test_vertices_layout_and_padding():
    pos = np.array([[1.0, 2.0], [0.0, 0.0], [5.0, 5.0]])
    v = shapes.vertices(pos, [np.pi / 2, 0.0, 0.0], [2.0, 1.0, 1.0], [4, 3, 0])
    assert v.shape == (3, 4, 2)
    np.testing.assert_allclose(v[0], [[1, 4], [-1, 2], [1, 0], [3, 2]], atol=1e-14)
    np.testing.assert_allclose(v[1, :3], naive.polygon(0, 0, 1, 0, 3), atol=1e-15)
    assert np.isnan(v[1, 3]).all() and np.isnan(v[2]).all()
    # counter-clockwise: positive shoelace area equal to the polygon's area
    x, y = v[0, :, 0], v[0, :, 1]
    signed = 0.5 * (np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    assert signed == pytest.approx(shapes.polygon_area([2.0], [4])[0], rel=1e-14)


@pytest.mark.parametrize("radius, nvert", [([1.0], [2]), ([1.0], [-1]), ([0.0], [5]),
                                           ([np.nan], [5]), ([1.0, 2.0], [5, 5, 5]),
                                           ([1.0], [4.5])])
def test_invalid_shapes_raise(radius, nvert):
    with pytest.raises(ParameterError):
        shapes.polygon_area(radius, nvert)


def test_invalid_density_and_thickness():
    with pytest.raises(ParameterError, match="density"):
        shapes.mass_and_inertia([1.0], [5], density=-1.0)
    with pytest.raises(ParameterError, match="thickness"):
        shapes.mass_and_inertia([1.0], [5], density=1.0, thickness=0.0)


# ---------------------------------------------------------------- the shape table


def test_table_reproduces_the_contract_vertices():
    """The solver's polar form (pos + r_k (cos(angle + phi_k), sin(angle + phi_k))) and the
    contract's rotation of the own-frame vertices (pos + Rot(angle) v_k) agree to round-off."""
    rng = np.random.default_rng(4)
    radius = rng.uniform(0.01, 0.03, 9)
    nvert = np.array([5, 0, 3, 5, 6, 0, 4, 5, 3])
    pos, angle = rng.uniform(-1, 1, (9, 2)), rng.uniform(-7, 7, 9)
    table = shapes.Shapes.regular(radius, nvert)
    assert table.first_vertex.tolist() == [0, 5, 5, 8, 13, 19, 19, 23, 28, 31]
    world = table.world_vertices(pos, angle)
    assert world.shape == (9, 6, 2)
    for b in range(9):
        n = nvert[b]
        assert np.isnan(world[b, n:]).all()
        if n:
            expected = naive.polygon(*pos[b], radius[b], angle[b], n)
            np.testing.assert_allclose(world[b, :n], expected, rtol=0, atol=1e-15)


@pytest.mark.parametrize("n", [3, 4, 5, 8])
def test_table_normals_and_inradius_from_the_vertices(n):
    table = shapes.Shapes.regular([0.02], [n])
    local = table.local_vertices(0)
    normals = naive.outward_normals(local)
    angle = np.arctan2(normals[:, 1], normals[:, 0])
    np.testing.assert_allclose(np.cos(angle - table.normal_angle), 1.0, atol=1e-15)
    distance = (normals * local).sum(1)  # every edge line's distance from the centre
    np.testing.assert_allclose(distance, table.inradius[0], rtol=1e-14)


def test_convex_constructor_agrees_with_the_regular_closed_forms():
    regular = shapes.Shapes.regular([0.7, 1.3, 0.02], [5, 3, 6])
    general = shapes.Shapes.convex([regular.local_vertices(b) for b in range(3)])
    for name in ("radius", "inradius", "area", "inertia_per_mass", "vertex_radius"):
        np.testing.assert_allclose(getattr(general, name), getattr(regular, name), rtol=1e-14, err_msg=name)
    for name in ("vertex_angle", "normal_angle"):
        np.testing.assert_allclose(np.cos(getattr(general, name) - getattr(regular, name)), 1.0, atol=1e-15)


def test_convex_constructor_on_a_rectangle():
    # a 2 x 1 rectangle: area 2, I/m = (a^2 + b^2)/12 = 5/12, circumradius sqrt(5)/2, inradius 1/2
    rect = shapes.Shapes.convex([[[1.0, -0.5], [1.0, 0.5], [-1.0, 0.5], [-1.0, -0.5]]])
    assert rect.area[0] == pytest.approx(2.0, rel=1e-15)
    assert rect.inertia_per_mass[0] == pytest.approx(5.0 / 12.0, rel=1e-15)
    assert rect.radius[0] == pytest.approx(np.sqrt(5) / 2, rel=1e-15)
    assert rect.inradius[0] == pytest.approx(0.5, rel=1e-15)
    mass, inertia = rect.mass_and_inertia(density=3.0, thickness=0.5)
    assert mass[0] == pytest.approx(3.0, rel=1e-15) and inertia[0] == pytest.approx(1.25, rel=1e-15)


@pytest.mark.parametrize("vertices, match", [
    ([[1.0, 0.0], [0.0, 1.0]], "2 vertices, expected at least 3"),
    ([[1.0, -0.5], [-1.0, -0.5], [-1.0, 0.5], [1.0, 0.5]], "counter-clockwise"),
    ([[2.0, 0.0], [3.0, 0.0], [3.0, 1.0], [2.0, 1.0]], "centroid"),
])
def test_convex_constructor_rejects_bad_polygons(vertices, match):
    with pytest.raises(ParameterError, match=match):
        shapes.Shapes.convex([vertices])
