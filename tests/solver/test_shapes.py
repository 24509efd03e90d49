"""Shapes: area, inertia, mass, inradius and vertices of disks and regular polygons."""

from __future__ import annotations

import numpy as np
import pytest

from grainview.errors import ParameterError
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
