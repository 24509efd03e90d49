"""Geometric deposition: the lowest-stable-position rule against a brute-force oracle, no
overlap (checked with the narrow phase), size counts, box aspect ratio, determinism."""

from __future__ import annotations

import math

import numpy as np
import pytest

from grainview.contract.errors import ParameterError
from solver.broadphase import candidate_pairs, wall_candidates
from solver.narrowphase import detect
from solver.packing import CLEARANCE, box_width_for, deposit, size_classes
from solver.shapes import Shapes


def naive_deposit(class_of, class_radius, width, clearance):
    """Brute force: before each placement list every pocket (bottom corners, bottom next to a
    particle, side wall next to a particle, upper intersection of two particles' circles),
    keep the stable ones that overlap nothing, and take the lowest (then leftmost)."""
    pos = []
    radii = []
    for s in class_of:
        r = class_radius[s]
        lo_x, hi_x, yb = r + clearance, width - r - clearance, r + clearance
        cands = [(yb, lo_x), (yb, hi_x)]
        for p, (x, y) in enumerate(pos):
            a = radii[p] + r + clearance
            if abs(yb - y) <= a:
                dx = math.sqrt(a * a - (yb - y) ** 2)
                cands += [(yb, x - dx), (yb, x + dx)]
            for xw, stable in ((lo_x, lo_x <= x), (hi_x, hi_x >= x)):
                if stable and abs(xw - x) <= a:
                    cands.append((y + math.sqrt(a * a - (xw - x) ** 2), xw))
            for q in range(p):
                b = radii[q] + r + clearance
                u = np.array(pos[q]) - np.array([x, y])
                d = np.linalg.norm(u)
                if d == 0 or d > a + b or d < abs(a - b):
                    continue
                l = (a * a - b * b + d * d) / (2 * d)
                h = math.sqrt(max(a * a - l * l, 0.0))
                perp = np.array([-u[1], u[0]]) / d
                if perp[1] < 0 or (perp[1] == 0 and perp[0] < 0):
                    perp = -perp
                c = np.array([x, y]) + l * u / d + h * perp
                if min(x, pos[q][0]) <= c[0] <= max(x, pos[q][0]):
                    cands.append((c[1], c[0]))
        best = None
        for y, x in cands:
            if not (lo_x <= x <= hi_x and y >= yb):
                continue
            if any((x - px) ** 2 + (y - py) ** 2 < (r + pr) ** 2 for (px, py), pr in zip(pos, radii)):
                continue
            if best is None or (y, x) < best:
                best = (y, x)
        pos.append((best[1], best[0]))
        radii.append(r)
    return np.array(pos), np.array(radii)


@pytest.mark.parametrize("seed", [0, 1])
def test_matches_brute_force_lowest_position(seed):
    n = 40
    diameters, fractions = (0.02, 0.03, 0.05), (0.5, 0.3, 0.2)
    width = 0.2
    pk = deposit(n, diameters, fractions, nvert=0, width=width, seed=seed)
    class_of = np.random.default_rng(seed).permutation(np.repeat(np.arange(3), size_classes(n, diameters, fractions)))
    pos, radius = naive_deposit(class_of, 0.5 * np.array(diameters), width, CLEARANCE * 0.025)
    np.testing.assert_allclose(pk.radius, radius, rtol=0)
    np.testing.assert_allclose(pk.pos, pos, atol=1e-12)


def _box(width, height):
    point = np.array([[0.0, 0.0], [width, 0.0], [0.0, height], [0.0, 0.0]])
    normal = np.array([[0.0, 1.0], [-1.0, 0.0], [0.0, -1.0], [1.0, 0.0]])
    return point, normal


@pytest.mark.parametrize("nvert", [0, 5, 3])
def test_no_interpenetration_and_inside_the_box(nvert):
    n = 400
    pk = deposit(n, nvert=nvert, seed=2)
    width = box_width_for(n)
    assert pk.pos.shape == (n, 2) and pk.nvert.dtype == np.int32 and np.all(pk.nvert == nvert)
    assert np.all(pk.pos[:, 0] - pk.radius >= 0) and np.all(pk.pos[:, 0] + pk.radius <= width)
    assert np.all(pk.pos[:, 1] - pk.radius >= 0)
    assert pk.height == pytest.approx(np.max(pk.pos[:, 1] + pk.radius), rel=1e-15)
    wall_point, wall_normal = _box(width, pk.height)
    alert = 0.001
    pi, pj = candidate_pairs(pk.pos, pk.radius, alert)
    wp, ww = wall_candidates(pk.pos, pk.radius, wall_point, wall_normal, alert)
    c = detect(pk.pos, pk.angle, Shapes.regular(pk.radius, pk.nvert), wall_point, wall_normal, alert, pi, pj, wp, ww)
    assert c.n_pairs > (n if nvert == 0 else 10)
    assert c.gap.min() >= -1e-12
    if nvert:
        assert np.all((pk.angle >= 0) & (pk.angle < 2 * np.pi / nvert))


def test_every_disk_rests_on_two_supports_or_the_bottom():
    n = 300
    pk = deposit(n, nvert=0, seed=4)
    width = box_width_for(n)
    tol = 1e-9
    d = np.linalg.norm(pk.pos[:, None] - pk.pos[None], axis=-1) - pk.radius[:, None] - pk.radius[None]
    np.fill_diagonal(d, np.inf)
    assert d.min() >= 0
    touching = (d < tol).sum(1)
    touching += (pk.pos[:, 0] - pk.radius < tol) + (width - pk.pos[:, 0] - pk.radius < tol)
    on_bottom = pk.pos[:, 1] - pk.radius < tol
    assert np.all(on_bottom | (touching >= 2))
    assert on_bottom.sum() >= 5


def test_size_counts_and_aspect_ratio():
    n = 2000
    counts = size_classes(n)
    assert counts.tolist() == [1000, 680, 320]
    assert size_classes(7, (1.0, 2.0), (0.5, 0.5)).sum() == 7
    pk = deposit(n, nvert=5, seed=5)
    values, got = np.unique(pk.radius, return_counts=True)
    np.testing.assert_allclose(values, [0.0125, 0.01875, 0.025])
    assert got.tolist() == counts.tolist()
    width = box_width_for(n)
    assert 1.8 < pk.height / width < 2.2
    # bulk solid fraction of the deposited circumscribed disks
    phi = np.sum(np.pi * pk.radius**2) / (width * pk.height)
    assert 0.75 < phi < 0.86


def test_deterministic_for_a_seed():
    a = deposit(200, nvert=5, seed=9)
    b = deposit(200, nvert=5, seed=9)
    c = deposit(200, nvert=5, seed=10)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)
    assert not np.array_equal(a.pos, c.pos)


def test_large_packing_is_feasible():
    n = 14400
    pk = deposit(n, nvert=5, seed=0)
    assert np.all(np.isfinite(pk.pos)) and pk.pos.shape == (n, 2)
    pi, pj = candidate_pairs(pk.pos, pk.radius, 1e-9)
    gap = np.linalg.norm(pk.pos[pi] - pk.pos[pj], axis=1) - pk.radius[pi] - pk.radius[pj]
    assert pi.size > 1.5 * n and gap.min() >= 0
    assert 1.9 < pk.height / box_width_for(n) < 2.1


@pytest.mark.parametrize("kwargs, match", [
    (dict(n=0), "n="),
    (dict(n=10, nvert=2), "nvert"),
    (dict(n=10, fractions=(0.5, 0.5, 0.5)), "fractions"),
    (dict(n=10, diameters=(0.01, -0.02, 0.03)), "diameters"),
    (dict(n=10, width=0.01), "width"),
    (dict(n=10, diameters=(0.01, 0.02), fractions=(1.0,)), "same length"),
])
def test_invalid_parameters(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        deposit(**kwargs)


def test_narrow_box_runs_out_of_room_not_into_an_error():
    # a box exactly one large particle wide: every particle stacks, still no overlap
    pk = deposit(30, diameters=(0.05,), fractions=(1.0,), nvert=0, width=0.05, seed=0)
    np.testing.assert_allclose(pk.pos[:, 0], 0.025, atol=1e-12)
    np.testing.assert_allclose(np.diff(np.sort(pk.pos[:, 1])), 0.05, atol=1e-12)
