"""Narrow phase: contact points, normals, gaps and kinds against hand-computed configurations
and slow numpy oracles."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from grainview.contract.errors import ParameterError
from solver.broadphase import candidate_pairs, wall_candidates
from solver.narrowphase import ContactPoints, detect
from solver.shapes import Shapes

from . import naive_geometry as naive

NO_WALLS = (np.zeros((0, 2)), np.zeros((0, 2)))
BOX_NORMALS = np.array([[0.0, 1.0], [-1.0, 0.0], [0.0, -1.0], [1.0, 0.0]])


def box_walls(width, height):
    """Bottom, right, top, left walls of the box [0, width] x [0, height]."""
    point = np.array([[0.0, 0.0], [width, 0.0], [0.0, height], [0.0, 0.0]])
    return point, BOX_NORMALS.copy()


def pair_contact(pos, angle, radius, nvert, alert=0.0, i=0, j=1):
    """Contacts of the single pair (i, j)."""
    shapes = Shapes.regular(np.asarray(radius, float), np.asarray(nvert))
    return detect(np.asarray(pos, float), np.asarray(angle, float), shapes, *NO_WALLS, alert, [i], [j], [], [])


def wall_contact(pos, angle, radius, nvert, wall_point, wall_normal, alert=0.0):
    """Contacts of particle 0 with every wall."""
    w = len(wall_point)
    shapes = Shapes.regular(np.atleast_1d(radius).astype(float), np.atleast_1d(nvert))
    return detect(np.asarray(pos, float).reshape(-1, 2), np.atleast_1d(angle).astype(float), shapes, wall_point,
                  wall_normal, alert, [], [], np.zeros(w, int), np.arange(w))


def check_layout(c: ContactPoints):
    p = c.gap.size
    for name in ("body_i", "body_j", "pair"):
        assert getattr(c, name).dtype == np.int32 and getattr(c, name).shape == (p,)
    assert c.kind.dtype == np.int8 and c.normal.shape == (p, 2) and c.point.shape == (p, 2)
    assert np.all(np.isfinite(c.normal)) and np.all(np.isfinite(c.point)) and np.all(np.isfinite(c.gap))
    np.testing.assert_allclose(np.hypot(c.normal[:, 0], c.normal[:, 1]), 1.0, rtol=1e-12)
    if p:
        assert c.pair[0] == 0 and np.all(np.diff(c.pair) >= 0) and np.all(np.diff(c.pair) <= 1)
        assert c.n_pairs == c.pair[-1] + 1
    else:
        assert c.n_pairs == 0
    for q in range(c.n_pairs):
        sel = np.flatnonzero(c.pair == q)
        assert sel.size in (1, 2)
        assert np.all(c.kind[sel] == sel.size)
        assert len(set(c.body_i[sel])) == 1 and len(set(c.body_j[sel])) == 1
        np.testing.assert_array_equal(c.normal[sel], c.normal[sel[:1]].repeat(sel.size, 0))


# ---------------------------------------------------------------- disks

def test_two_disks_overlapping_by_known_amount():
    c = pair_contact([[0.0, 0.0], [1.5, 2.0]], [0, 0], [1.0, 1.6], [0, 0])
    check_layout(c)
    assert c.n_pairs == 1 and c.kind[0] == 1
    assert c.gap[0] == pytest.approx(2.5 - 2.6, abs=1e-15)
    np.testing.assert_allclose(c.normal[0], [0.6, 0.8], rtol=1e-15)
    # surfaces at 1.0 (disk 0) and 2.5 - 1.6 = 0.9 (disk 1) along n: point at 0.95
    np.testing.assert_allclose(c.point[0], [0.6 * 0.95, 0.8 * 0.95], rtol=1e-14)
    assert (c.body_i[0], c.body_j[0]) == (0, 1)


def test_disks_alert_filter_and_zero_gap():
    pos = [[0.0, 0.0], [2.0, 0.0]]
    c = pair_contact(pos, [0, 0], [1.0, 1.0], [0, 0], alert=0.0)
    assert c.n_pairs == 1 and c.gap[0] == 0.0
    np.testing.assert_array_equal(c.point[0], [1.0, 0.0])
    c = pair_contact([[0.0, 0.0], [2.1, 0.0]], [0, 0], [1.0, 1.0], [0, 0], alert=0.05)
    assert c.n_pairs == 0 and c.gap.size == 0
    c = pair_contact([[0.0, 0.0], [2.1, 0.0]], [0, 0], [1.0, 1.0], [0, 0], alert=0.1 + 1e-12)
    assert c.n_pairs == 1 and c.gap[0] == pytest.approx(0.1)


def test_coincident_disks_are_finite():
    c = pair_contact([[1.0, 1.0], [1.0, 1.0]], [0, 0], [1.0, 0.5], [0, 0])
    check_layout(c)
    assert c.gap[0] == -1.5


def test_disk_on_walls():
    wall_point, wall_normal = box_walls(4.0, 3.0)
    # disk of radius 0.5 at (0.3, 2.8): overlaps left wall by 0.2, top by 0.3, bottom far away
    c = wall_contact([0.3, 2.8], 0.0, 0.5, 0, wall_point, wall_normal, alert=0.0)
    check_layout(c)
    assert c.n_pairs == 2
    assert c.body_j.tolist() == [1 + 2, 1 + 3]  # N + w with N = 1
    np.testing.assert_allclose(c.gap, [-0.3, -0.2], atol=1e-15)
    np.testing.assert_allclose(c.normal, [[0, 1], [-1, 0]])
    # point midway between the disk's extreme point and the wall
    np.testing.assert_allclose(c.point, [[0.3, 3.15], [-0.1, 2.8]], atol=1e-15)


def test_disks_against_numpy_oracle():
    rng = np.random.default_rng(11)
    n = 150
    pos = rng.uniform(0, 1, (n, 2))
    radius = rng.uniform(0.02, 0.06, n)
    alert = 0.01
    pi, pj = candidate_pairs(pos, radius, alert)
    c = detect(pos, np.zeros(n), Shapes.regular(radius, np.zeros(n, int)), *NO_WALLS, alert, pi, pj, [], [])
    check_layout(c)
    d = np.linalg.norm(pos[:, None] - pos[None], axis=-1) - radius[:, None] - radius[None]
    ei, ej = np.nonzero(np.triu(d <= alert, 1))
    assert sorted(zip(c.body_i.tolist(), c.body_j.tolist())) == sorted(zip(ei.tolist(), ej.tolist()))
    np.testing.assert_allclose(c.gap, d[c.body_i, c.body_j], atol=1e-15)
    u = pos[c.body_j] - pos[c.body_i]
    np.testing.assert_allclose(c.normal, u / np.linalg.norm(u, axis=1)[:, None], atol=1e-15)
    # the point lies on the centre line, (r_i + g/2) from centre i and (r_j + g/2) from centre j
    np.testing.assert_allclose(((c.point - pos[c.body_i]) * c.normal).sum(1),
                               radius[c.body_i] + c.gap / 2, atol=1e-14)
    np.testing.assert_allclose(((pos[c.body_j] - c.point) * c.normal).sum(1),
                               radius[c.body_j] + c.gap / 2, atol=1e-14)
    cross = (c.point - pos[c.body_i])[:, 0] * c.normal[:, 1] - (c.point - pos[c.body_i])[:, 1] * c.normal[:, 0]
    np.testing.assert_allclose(cross, 0.0, atol=1e-14)


# ---------------------------------------------------------------- polygon-wall

def test_pentagon_resting_on_an_edge_on_the_bottom_wall():
    # pentagon with edge 2 (vertices 2, 3) at the bottom: that edge's normal points at
    # angle + pi (2*2+1)/5 = angle + pi -> with angle = -pi/2 ... choose angle so the normal
    # of edge 2 is -y: angle + pi = -pi/2 + 2 pi k -> angle = pi/2
    r = 1.0
    inr = r * np.cos(np.pi / 5)
    wall_point, wall_normal = box_walls(10.0, 10.0)
    pen = 0.01
    c = wall_contact([5.0, inr - pen], np.pi / 2, r, 5, wall_point, wall_normal, alert=0.0)
    check_layout(c)
    assert c.n_pairs == 1 and c.kind.tolist() == [2, 2]
    np.testing.assert_allclose(c.gap, [-pen, -pen], atol=1e-14)
    np.testing.assert_allclose(c.normal, [[0, -1], [0, -1]], atol=1e-15)
    half = r * np.sin(np.pi / 5)  # half the edge length
    # points at the two bottom vertices moved halfway to the wall; ordered along t = (1, 0)
    np.testing.assert_allclose(c.point, [[5.0 - half, -pen / 2], [5.0 + half, -pen / 2]], atol=1e-14)


def test_tilted_pentagon_on_wall_is_simple_unless_within_alert():
    r, tilt = 1.0, 0.05
    inr = r * np.cos(np.pi / 5)
    wall_point, wall_normal = box_walls(10.0, 10.0)
    angle = np.pi / 2 + tilt
    v = naive.polygon(5.0, 2.0, r, angle, 5)
    y = 2.0 - v[:, 1].min()  # lowest vertex exactly on the wall
    v = naive.polygon(5.0, y, r, angle, 5)
    low = np.sort(v[:, 1])
    c = wall_contact([5.0, y], angle, r, 5, wall_point, wall_normal, alert=0.0)
    check_layout(c)
    assert c.n_pairs == 1 and c.kind.tolist() == [1]
    assert c.gap[0] == pytest.approx(0.0, abs=1e-14)
    k = np.argmin(v[:, 1])
    np.testing.assert_allclose(c.point[0], v[k], atol=1e-14)
    c = wall_contact([5.0, y], angle, r, 5, wall_point, wall_normal, alert=low[1] + 1e-9)
    assert c.kind.tolist() == [2, 2]
    np.testing.assert_allclose(np.sort(c.gap), low[:2], atol=1e-14)
    assert inr > 0


def test_invalid_detect_inputs():
    pos, angle, radius, nvert = np.zeros((2, 2)), np.zeros(2), np.ones(2), np.zeros(2, int)
    with pytest.raises(ParameterError, match="pj"):
        detect(pos, angle, Shapes.regular(radius, nvert), *NO_WALLS, 0.0, [0], [5], [], [])
    with pytest.raises(ParameterError, match="itself"):
        detect(pos, angle, Shapes.regular(radius, nvert), *NO_WALLS, 0.0, [1], [1], [], [])
    with pytest.raises(ParameterError, match="ww"):
        detect(pos, angle, Shapes.regular(radius, nvert), *NO_WALLS, 0.0, [], [], [0], [0])
    with pytest.raises(ParameterError, match="alert"):
        detect(pos, angle, Shapes.regular(radius, nvert), *NO_WALLS, -1.0, [], [], [], [])
    with pytest.raises(ParameterError, match="threads"):
        detect(pos, angle, Shapes.regular(radius, nvert), *NO_WALLS, 0.0, [], [], [], [], threads=0)


# ---------------------------------------------------------------- polygon-polygon

C36, S36 = np.cos(np.pi / 5), np.sin(np.pi / 5)


def test_pentagon_vertex_poking_into_an_edge_is_simple():
    # A: edge 0 faces +x (angle -pi/5), inradius cos 36. B: vertex 0 points to -x (angle pi),
    # placed so that vertex sits 0.02 inside A's edge, 0.1 above the edge's middle.
    pen, y0 = 0.02, 0.1
    pos = [[0.0, 0.0], [C36 - pen + 1.0, y0]]
    c = pair_contact(pos, [-np.pi / 5, np.pi], [1.0, 1.0], [5, 5])
    check_layout(c)
    assert c.n_pairs == 1 and c.kind.tolist() == [1]
    assert c.gap[0] == pytest.approx(-pen, abs=1e-14)
    np.testing.assert_allclose(c.normal[0], [1.0, 0.0], atol=1e-14)
    # middle of the vertex (C36 - pen, y0) and its projection (C36, y0) onto the edge
    np.testing.assert_allclose(c.point[0], [C36 - pen / 2, y0], atol=1e-14)
    # same contact with the bodies swapped: normal flipped, everything else equal
    d = pair_contact(pos, [-np.pi / 5, np.pi], [1.0, 1.0], [5, 5], i=1, j=0)
    assert (d.body_i[0], d.body_j[0]) == (1, 0)
    np.testing.assert_allclose(d.normal, -c.normal, atol=0)
    np.testing.assert_allclose(d.point, c.point, atol=0)
    np.testing.assert_allclose(d.gap, c.gap, atol=0)


@pytest.mark.parametrize("y0", [0.0, 0.3, 0.9])
def test_two_pentagons_edge_to_edge_exactly_aligned_is_double(y0):
    # A's edge 0 faces +x; B (radius 0.8) has its edge 0 facing -x (angle 4 pi/5); overlap 0.01
    pen, rb = 0.01, 0.8
    pos = [[0.0, 0.0], [C36 + rb * C36 - pen, y0]]
    c = pair_contact(pos, [-np.pi / 5, 4 * np.pi / 5], [1.0, rb], [5, 5])
    check_layout(c)
    assert c.n_pairs == 1 and c.kind.tolist() == [2, 2]
    np.testing.assert_allclose(c.gap, [-pen, -pen], atol=1e-14)
    np.testing.assert_allclose(c.normal, [[1, 0], [1, 0]], atol=1e-14)
    # the common segment: y in [-S36, S36] (edge of A) and y0 + [-0.8 S36, 0.8 S36] (edge of B)
    lo, hi = max(-S36, y0 - rb * S36), min(S36, y0 + rb * S36)
    np.testing.assert_allclose(c.point, [[C36 - pen / 2, lo], [C36 - pen / 2, hi]], atol=1e-14)


def test_two_identical_pentagons_exactly_aligned_tie_is_symmetric():
    pos = [[0.0, 0.0], [2 * C36, 0.0]]  # touching, gap 0, equal separations from both sides
    c = pair_contact(pos, [-np.pi / 5, 4 * np.pi / 5], [1.0, 1.0], [5, 5])
    d = pair_contact(pos, [-np.pi / 5, 4 * np.pi / 5], [1.0, 1.0], [5, 5], i=1, j=0)
    check_layout(c)
    assert c.kind.tolist() == [2, 2]
    np.testing.assert_allclose(c.gap, 0.0, atol=1e-14)
    np.testing.assert_allclose(c.point, [[C36, -S36], [C36, S36]], atol=1e-14)
    np.testing.assert_allclose(d.point, c.point, atol=0)
    np.testing.assert_allclose(d.normal, -c.normal, atol=0)


def test_near_parallel_edges_double_with_mean_normal():
    # B tilted by delta from the aligned position: its edge normal is at pi + delta, the
    # reference normal at 0 -> mean normal at delta/2
    delta, pen = 0.01, 0.02
    pos = [[0.0, 0.0], [2 * C36 - pen, 0.0]]
    c = pair_contact(pos, [-np.pi / 5, 4 * np.pi / 5 + delta], [1.0, 1.0], [5, 5], alert=0.0)
    check_layout(c)
    assert c.kind.tolist() == [2, 2]
    np.testing.assert_allclose(c.normal[0], [np.cos(delta / 2), np.sin(delta / 2)], atol=1e-14)
    # both ends of the common segment inside A: gaps negative, the deeper one the SAT gap
    va = naive.polygon(*pos[0], 1.0, -np.pi / 5, 5)
    vb = naive.polygon(*pos[1], 1.0, 4 * np.pi / 5 + delta, 5)
    assert c.gap.min() == pytest.approx(naive.sat_separation(va, vb), abs=1e-14)
    assert np.all(c.gap < 0)
    # and a strongly tilted B (one vertex in, the other end of its edge far out) is simple
    c = pair_contact(pos, [-np.pi / 5, 4 * np.pi / 5 + 0.3], [1.0, 1.0], [5, 5], alert=0.0)
    assert c.kind.tolist() == [1]


def test_corner_on_corner_near_parallel_is_double_when_the_common_segment_is_within_alert():
    # B's facing edge tilted by delta and slid along A's right edge so that the two edges
    # overlap corner on corner: A's upper corner pokes into B's edge (the reference edge), and
    # the other end of A's edge (the incident edge), far below B's edge, is farther than the
    # alert distance from B's edge line; but the end of the common segment (A's edge clipped to
    # B's edge: at B's lower vertex) is within it -> double, both points on the common segment
    # (Box2D's clipping criterion)
    delta, pen, slide, alert = 0.06, 0.01, 0.6, 0.04
    length = 2 * np.sin(np.pi / 5)
    pos = [[0.0, 0.0], [2 * C36 - pen, slide * length]]
    angle = [-np.pi / 5, 4 * np.pi / 5 + delta]
    va = naive.polygon(*pos[0], 1.0, angle[0], 5)  # right edge vertical: x = C36, |y| <= sin 36
    vb = naive.polygon(*pos[1], 1.0, angle[1], 5)
    corner_y = np.sin(np.pi / 5)
    facing = vb[np.argsort(vb[:, 0])[:2]]  # B's two leftmost vertices: its facing edge
    lower, upper = facing[np.argsort(facing[:, 1])]
    b_normal = (upper - lower)[::-1] * [1, -1] / length  # B's facing edge, outward normal (to -x)
    b_normal *= np.sign(-b_normal[0])
    far_gap = (np.array([C36, -corner_y]) - lower) @ b_normal  # A's lower corner from B's edge line
    assert far_gap > alert  # the far vertex fails the vertex-based test
    c = pair_contact(pos, angle, [1.0, 1.0], [5, 5], alert=alert)
    check_layout(c)
    assert c.kind.tolist() == [2, 2]
    deep, shallow = np.argmin(c.gap), np.argmax(c.gap)
    # the deep point: A's upper corner, gap = its distance into B's edge = the SAT separation
    assert c.gap[deep] == pytest.approx(naive.sat_separation(va, vb), abs=1e-14)
    assert c.gap[deep] == pytest.approx((np.array([C36, corner_y]) - lower) @ b_normal, abs=1e-14)
    assert c.point[deep, 1] == pytest.approx(corner_y, abs=abs(c.gap[deep]))
    # the shallow point: A's edge facing B's lower vertex, gap = that vertex's distance to A's
    # edge line over cos(delta) (measured along B's normal)
    assert 0 < c.gap[shallow] <= alert
    assert c.gap[shallow] == pytest.approx((lower[0] - C36) / np.cos(delta), rel=1e-12)
    assert c.point[shallow, 1] == pytest.approx(lower[1], abs=c.gap[shallow])
    # a smaller alert than that gap: simple again
    c = pair_contact(pos, angle, [1.0, 1.0], [5, 5], alert=0.5 * c.gap.max())
    assert c.kind.tolist() == [1]
    # and edges 20 degrees apart overhanging the same way stay simple at any alert below the
    # far vertex's gap (the clipped test is for near-parallel edges only, within 10 degrees)
    c = pair_contact(pos, [angle[0], 4 * np.pi / 5 + 0.35], [1.0, 1.0], [5, 5], alert=alert)
    assert c.kind.tolist() == [1]


def test_vertex_on_vertex_and_corner_touching_are_finite_simple():
    # vertices pointing at each other, touching at (1, 0)
    c = pair_contact([[0.0, 0.0], [2.0, 0.0]], [0.0, np.pi], [1.0, 1.0], [5, 5], alert=1e-9)
    check_layout(c)
    assert c.kind.tolist() == [1] and c.gap[0] == pytest.approx(0.0, abs=1e-14)
    np.testing.assert_allclose(c.point[0], [1.0, 0.0], atol=1e-14)
    # two unit squares (R = sqrt(2)/2, angle pi/4 -> axis-aligned) touching at one corner,
    # with collinear edges
    r = np.sqrt(0.5)
    for offset in ([1.0, 1.0], [1.0, 0.0 + 1.0 - 1e-17], [1.0, -1.0]):
        c = pair_contact([[0.0, 0.0], offset], [np.pi / 4, np.pi / 4], [r, r], [4, 4], alert=1e-9)
        check_layout(c)
        assert c.n_pairs == 1 and c.gap.min() == pytest.approx(0.0, abs=1e-14)
    # squares side by side sharing a full edge: double
    c = pair_contact([[0.0, 0.0], [1.0, 0.0]], [np.pi / 4, np.pi / 4], [r, r], [4, 4])
    assert c.kind.tolist() == [2, 2]
    np.testing.assert_allclose(c.point, [[0.5, -0.5], [0.5, 0.5]], atol=1e-14)


def test_coincident_polygons_are_finite():
    c = pair_contact([[0.0, 0.0], [0.0, 0.0]], [0.0, 0.3], [1.0, 1.0], [5, 5])
    check_layout(c)
    assert c.gap.min() < -1.0


# ---------------------------------------------------------------- polygon-disk

def test_disk_on_pentagon_edge_and_vertex():
    # disk of radius 0.2 right of A's edge 0 (faces +x) overlapping by 0.05
    c = pair_contact([[0.0, 0.0], [C36 + 0.15, 0.1]], [-np.pi / 5, 0.0], [1.0, 0.2], [5, 0])
    check_layout(c)
    assert c.kind.tolist() == [1] and c.gap[0] == pytest.approx(-0.05, abs=1e-14)
    np.testing.assert_allclose(c.normal[0], [1, 0], atol=1e-14)
    np.testing.assert_allclose(c.point[0], [C36 - 0.025, 0.1], atol=1e-14)
    # disk facing vertex 0 of a pentagon of angle 0 (vertex at (1, 0)), gap 0.1, disk first
    c = pair_contact([[1.4, 0.0], [0.0, 0.0]], [0.0, 0.0], [0.3, 1.0], [0, 5], alert=0.2)
    assert c.gap[0] == pytest.approx(0.1, abs=1e-14)
    np.testing.assert_allclose(c.normal[0], [-1, 0], atol=1e-14)
    np.testing.assert_allclose(c.point[0], [1.05, 0.0], atol=1e-14)
    # disk centre inside the polygon
    c = pair_contact([[0.0, 0.0], [C36 - 0.1, 0.0]], [-np.pi / 5, 0.0], [1.0, 0.2], [5, 0])
    assert c.gap[0] == pytest.approx(-0.3, abs=1e-14)
    np.testing.assert_allclose(c.normal[0], [1, 0], atol=1e-14)
    # disk centre exactly on a vertex and exactly on an edge: finite
    for centre in ([1.0, 0.0], [C36, 0.0]):
        c = pair_contact([[0.0, 0.0], centre], [0.0 if centre[0] == 1.0 else -np.pi / 5, 0.0],
                         [1.0, 0.2], [5, 0])
        check_layout(c)
        assert c.gap[0] == pytest.approx(-0.2, abs=1e-14)


def _signed_distance_to_polygon(point, verts):
    nrm = naive.outward_normals(verts)
    s = ((point - verts) * nrm).sum(1)
    if s.max() <= 0:
        return s.max()
    return min(naive.point_segment_distance(point, verts[k], verts[(k + 1) % len(verts)])
               for k in range(len(verts)))


def random_scene(seed, n=60, box=1.0, disks=0.3):
    rng = np.random.default_rng(seed)
    pos = rng.uniform(0, box, (n, 2))
    radius = rng.uniform(0.04, 0.1, n)
    nvert = np.where(rng.uniform(size=n) < disks, 0, rng.choice([3, 4, 5, 6], n))
    angle = rng.uniform(0, 2 * np.pi, n)
    return pos, angle, radius, nvert


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_scene_against_numpy_oracle(seed):
    pos, angle, radius, nvert = random_scene(seed)
    alert = 0.01
    pi, pj = candidate_pairs(pos, radius, alert)
    c = detect(pos, angle, Shapes.regular(radius, nvert), *NO_WALLS, alert, pi, pj, [], [])
    check_layout(c)
    kept = {(int(a), int(b)) for a, b in zip(c.body_i, c.body_j)}
    checked = {"pp": 0, "pd": 0, "overlap": 0}
    for a, b in zip(pi.tolist(), pj.tolist()):
        sel = np.flatnonzero((c.body_i == a) & (c.body_j == b))
        if nvert[a] == 0 and nvert[b] == 0:
            expected = np.linalg.norm(pos[b] - pos[a]) - radius[a] - radius[b]
            assert ((a, b) in kept) == (expected <= alert)
            continue
        if nvert[a] == 0 or nvert[b] == 0:
            p, d = (a, b) if nvert[b] == 0 else (b, a)
            verts = naive.polygon(*pos[p], radius[p], angle[p], nvert[p])
            expected = _signed_distance_to_polygon(pos[d], verts) - radius[d]
            assert ((a, b) in kept) == (expected <= alert)
            if sel.size:
                assert c.gap[sel[0]] == pytest.approx(expected, abs=1e-13)
                checked["pd"] += 1
            continue
        va = naive.polygon(*pos[a], radius[a], angle[a], nvert[a])
        vb = naive.polygon(*pos[b], radius[b], angle[b], nvert[b])
        sat = naive.sat_separation(va, vb)
        assert ((a, b) in kept) == (sat <= alert)
        if not sel.size:
            continue
        checked["pp"] += 1
        # the deepest point is the SAT separation, except for the corner fall-back of nearly
        # parallel edges, which stays within the alert distance
        assert c.gap[sel].min() >= sat - 1e-13
        exact = abs(c.gap[sel].min() - sat) <= 1e-13
        assert exact or c.gap[sel].max() <= alert + 1e-13
        checked["exact"] = checked.get("exact", 0) + int(exact)
        if sat > 0:
            assert c.gap[sel].min() <= naive.polygon_distance(va, vb) + 1e-13
        elif sel.size == 1 and exact and naive.sat_margin(va, vb) > 1e-9:
            # -gap is the penetration depth: moving b by -gap along n separates them, half of
            # it does not
            checked["overlap"] += 1
            n = c.normal[sel[0]]
            g = c.gap[sel[0]]
            assert naive.overlap_area(va, vb + (-g + 1e-9) * n) < 1e-12
            assert naive.overlap_area(va, vb + (-0.5 * g) * n) > 0
    assert checked["pp"] > 5 and checked["pd"] > 2 and checked["overlap"] > 2, checked
    assert checked["exact"] >= 0.8 * checked["pp"], checked


@pytest.mark.parametrize("threads", [2, 3, 7])
def test_threads_give_the_same_points_bit_for_bit(threads):
    """The candidates split into blocks done at once (pairs and wall candidates, disks and
    polygons; more blocks than candidates, and no candidate at all) give exactly the serial
    kernel's points."""
    pos, angle, radius, nvert = random_scene(5, n=80)
    shapes = Shapes.regular(radius, nvert)
    walls = box_walls(1.0, 1.0)
    pi, pj = candidate_pairs(pos, radius, 0.02)
    wp, ww = np.repeat(np.arange(80), 4), np.tile(np.arange(4), 80)
    serial = detect(pos, angle, shapes, *walls, 0.02, pi, pj, wp, ww)
    assert serial.n_pairs > 20 and np.sum(serial.body_j >= 80) > 5
    for pairs, (a, b) in ((slice(None), (wp, ww)), (slice(0, 3), ([], [])), (slice(0, 0), ([], []))):
        one = detect(pos, angle, shapes, *walls, 0.02, pi[pairs], pj[pairs], a, b)
        many = detect(pos, angle, shapes, *walls, 0.02, pi[pairs], pj[pairs], a, b, threads=threads)
        for field in one._fields:
            np.testing.assert_array_equal(getattr(many, field), getattr(one, field), err_msg=field)


@pytest.mark.parametrize("seed", [3, 4])
def test_swapping_bodies_flips_only_the_normal(seed):
    pos, angle, radius, nvert = random_scene(seed)
    pi, pj = candidate_pairs(pos, radius, 0.02)
    c = detect(pos, angle, Shapes.regular(radius, nvert), *NO_WALLS, 0.02, pi, pj, [], [])
    d = detect(pos, angle, Shapes.regular(radius, nvert), *NO_WALLS, 0.02, pj, pi, [], [])
    assert c.n_pairs > 10
    np.testing.assert_array_equal(c.body_i, d.body_j)
    np.testing.assert_array_equal(c.body_j, d.body_i)
    np.testing.assert_array_equal(c.kind, d.kind)
    np.testing.assert_array_equal(c.point, d.point)
    np.testing.assert_array_equal(c.gap, d.gap)
    np.testing.assert_array_equal(c.normal, -d.normal)


# ---------------------------------------------------------------- invariance (hypothesis)


shape = st.sampled_from([0, 3, 4, 5, 6])
unit_angle = st.floats(0.0, 2 * np.pi, allow_nan=False)


def _rotation(phi):
    return np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])


def oracle_gap(pos, angle, radius, nvert):
    """Gap of two bodies from the numpy oracles: exact for disk-disk and polygon-disk, the SAT
    separation for two polygons."""
    (na, nb), (ra, rb), (ta, tb) = nvert, radius, angle
    if na == 0 and nb == 0:
        return np.linalg.norm(pos[1] - pos[0]) - ra - rb
    if na == 0 or nb == 0:
        p, d = (0, 1) if nb == 0 else (1, 0)
        verts = naive.polygon(*pos[p], radius[p], angle[p], nvert[p])
        return _signed_distance_to_polygon(pos[d], verts) - radius[d]
    return naive.sat_separation(naive.polygon(*pos[0], ra, ta, na), naive.polygon(*pos[1], rb, tb, nb))


def place_at_gap(direction, target, angle, radius, nvert):
    """Centres (0, 0) and d (cos, sin)(direction), d found by bisection so that the oracle gap
    equals ``target``."""
    u = np.array([np.cos(direction), np.sin(direction)])
    lo, hi = 0.0, radius[0] + radius[1] + abs(target) + 1.0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        pos = np.array([[0.0, 0.0], mid * u])
        if oracle_gap(pos, angle, radius, nvert) < target:
            lo = mid
        else:
            hi = mid
    return np.array([[0.0, 0.0], 0.5 * (lo + hi) * u])


@settings(max_examples=150, deadline=None)
@given(na=shape, nb=shape, ra=st.floats(0.5, 1.5), rb=st.floats(0.5, 1.5), ta=unit_angle,
       tb=unit_angle, direction=unit_angle, target=st.floats(-0.05, 0.05), phi=unit_angle,
       shift=st.tuples(st.floats(-3, 3), st.floats(-3, 3)), alert=st.sampled_from([0.0, 0.01, 0.1]))
def test_rigid_motion_moves_the_contact_with_it(na, nb, ra, rb, ta, tb, direction, target, phi, shift, alert):
    """Rotating and translating a configuration rotates and translates its contact points and
    normals and keeps its gaps (penetrations up to 5 % of the radius, the solver's regime)."""
    angle, radius, nvert = [ta, tb], [ra, rb], [na, nb]
    pos = place_at_gap(direction, target, angle, radius, nvert)
    if na and nb:
        va = naive.polygon(*pos[0], ra, ta, na)
        vb = naive.polygon(*pos[1], rb, tb, nb)
        assume(naive.sat_margin(va, vb) > 1e-7)  # unique reference edge
    c = pair_contact(pos, angle, radius, nvert, alert=alert)
    rot = _rotation(phi)
    moved = pos @ rot.T + np.array(shift)
    m = pair_contact(moved, [ta + phi, tb + phi], radius, nvert, alert=alert)
    check_layout(c)
    check_layout(m)
    assert c.n_pairs == int(target <= alert) or abs(target - alert) < 1e-9
    assume(c.n_pairs == m.n_pairs)  # differs only with the gap on the alert threshold
    if not np.array_equal(c.kind, m.kind):
        # only where the second vertex of a nearly parallel edge sits on the alert threshold
        assert np.max(c.gap) == pytest.approx(alert, abs=1e-9) or np.max(m.gap) == pytest.approx(alert, abs=1e-9)
        return
    np.testing.assert_allclose(m.gap, c.gap, atol=1e-9)
    np.testing.assert_allclose(m.normal, c.normal @ rot.T, atol=1e-9)
    np.testing.assert_allclose(m.point, c.point @ rot.T + np.array(shift), atol=1e-9)


# ---------------------------------------------------------------- more oracles

def test_polygon_wall_against_numpy_oracle():
    rng = np.random.default_rng(21)
    n = 200
    nvert = rng.choice([3, 4, 5, 6], n)
    radius = rng.uniform(0.5, 1.0, n)
    angle = rng.uniform(0, 2 * np.pi, n)
    tilt = 0.3
    wall_normal = np.array([[np.sin(tilt), np.cos(tilt)]])
    wall_point = np.array([[0.2, -0.1]])
    # centres at signed distance in [0.3 R, 1.1 R] from the wall
    along = rng.uniform(-5, 5, n)
    height = rng.uniform(0.3, 1.1, n) * radius
    tangent = np.array([wall_normal[0, 1], -wall_normal[0, 0]])
    pos = wall_point + along[:, None] * tangent + height[:, None] * wall_normal
    alert = 0.05
    c = detect(pos, angle, Shapes.regular(radius, nvert), wall_point, wall_normal, alert, [], [],
               np.arange(n), np.zeros(n, int))
    check_layout(c)
    assert np.all(c.body_j == n) and np.all(c.normal == -wall_normal)
    n_double = 0
    for p in range(n):
        v = naive.polygon(*pos[p], radius[p], angle[p], nvert[p])
        s = (v - wall_point[0]) @ wall_normal[0]
        k = int(np.argmin(s))
        after, before = (k + 1) % nvert[p], (k - 1) % nvert[p]
        other = after if s[after] <= s[before] else before
        sel = np.flatnonzero(c.body_i == p)
        assert (sel.size > 0) == (s[k] <= alert)
        if not sel.size:
            continue
        # double-contact criterion (solver.narrowphase): s1 <= max(s0, 0) + alert
        expected = [k] if s[other] > max(s[k], 0.0) + alert else [k, other]
        assert sel.size == len(expected)
        n_double += sel.size == 2
        got = sorted(zip(c.gap[sel].tolist(), map(tuple, c.point[sel])))
        want = sorted((s[q], tuple(v[q] - 0.5 * s[q] * wall_normal[0])) for q in expected)
        for (g1, p1), (g2, p2) in zip(got, want):
            assert g1 == pytest.approx(g2, abs=1e-14)
            np.testing.assert_allclose(p1, p2, atol=1e-14)
    assert n_double > 3 and c.n_pairs > 20


def test_walls_and_pairs_together_are_numbered_in_order():
    # two disks in contact resting on the bottom of a box: pairs first, then wall contacts
    wall_point, wall_normal = box_walls(4.0, 4.0)
    pos = np.array([[1.0, 0.5], [2.0, 0.5]])
    radius = np.array([0.5, 0.5])
    pi, pj = candidate_pairs(pos, radius, 0.01)
    wp, ww = wall_candidates(pos, radius, wall_point, wall_normal, 0.01)
    disks = Shapes.regular(radius, np.zeros(2, int))
    c = detect(pos, np.zeros(2), disks, wall_point, wall_normal, 0.01, pi, pj, wp, ww)
    check_layout(c)
    assert list(zip(c.body_i.tolist(), c.body_j.tolist())) == [(0, 1), (0, 2), (1, 2)]
    assert c.pair.tolist() == [0, 1, 2] and c.n_pairs == 3
    np.testing.assert_allclose(c.gap, 0.0, atol=1e-15)


def test_random_near_parallel_edges_give_double_contacts_on_the_common_segment():
    rng = np.random.default_rng(8)
    for _ in range(200):
        na, nb = rng.choice([3, 4, 5, 6], 2)
        ra, rb = rng.uniform(0.5, 1.5, 2)
        ta = rng.uniform(0, 2 * np.pi)
        ea = rng.integers(na)
        normal_angle = ta + np.pi * (2 * ea + 1) / na  # outward normal of edge ea of A
        eb = rng.integers(nb)
        delta = rng.uniform(-0.02, 0.02)
        tb = normal_angle + np.pi + delta - np.pi * (2 * eb + 1) / nb  # edge eb of B faces A
        slide = rng.uniform(-0.5, 0.5) * min(ra, rb)
        pen = rng.uniform(-0.01, 0.03)
        u = np.array([np.cos(normal_angle), np.sin(normal_angle)])
        t = np.array([-u[1], u[0]])
        pos = np.array([[0.0, 0.0], (ra * np.cos(np.pi / na) + rb * np.cos(np.pi / nb) - pen) * u + slide * t])
        alert = 0.05
        c = pair_contact(pos, [ta, tb], [ra, rb], [na, nb], alert=alert)
        check_layout(c)
        va = naive.polygon(*pos[0], ra, ta, na)
        vb = naive.polygon(*pos[1], rb, tb, nb)
        assert c.kind.tolist() == [2, 2]
        # normal: the mean of the two facing edges' outward normals (A's, and minus B's)
        nb_out = -np.array([np.cos(normal_angle + delta), np.sin(normal_angle + delta)])
        mean = u - nb_out
        np.testing.assert_allclose(c.normal[0], mean / np.linalg.norm(mean), atol=1e-12)
        # gaps within [SAT separation, alert]
        sat = naive.sat_separation(va, vb)
        assert np.all(c.gap >= sat - 1e-12) and np.all(c.gap <= alert + 1e-12)
        # both points lie within the extent of both facing edges (the common segment), up to
        # the half-gap shift towards the reference line
        for verts, e in ((va, ea), (vb, eb)):
            a0, a1 = verts[e], verts[(e + 1) % len(verts)]
            direction = (a1 - a0) / np.linalg.norm(a1 - a0)
            tau = (c.point - a0) @ direction
            assert np.all(tau >= -1e-3) and np.all(tau <= np.linalg.norm(a1 - a0) + 1e-3)
            # and midway between the edge lines: half its gap from each
            normal_e = np.array([direction[1], -direction[0]])
            assert np.all(np.abs((c.point - a0) @ normal_e) <= 0.5 * np.abs(c.gap) + 1e-12)


def test_extreme_configurations_stay_finite():
    # deep overlaps, one body inside another, size ratios of 1e3, coincident centres, bodies
    # through walls: every kept contact has a unit normal and finite point and gap
    rng = np.random.default_rng(99)
    n = 300
    pos = rng.uniform(0, 1, (n, 2))
    pos[::7] = pos[1::7][: len(pos[::7])]  # coincident centres
    radius = 10.0 ** rng.uniform(-3, -0.5, n)
    nvert = rng.choice([0, 3, 4, 5, 7], n)
    angle = rng.choice([0.0, np.pi / 4, np.pi / 5, np.pi], n) + rng.choice([0, 1e-15], n)
    wall_point, wall_normal = box_walls(0.8, 0.8)
    alert = 0.01
    pi, pj = candidate_pairs(pos, radius, alert)
    wp, ww = wall_candidates(pos, radius, wall_point, wall_normal, alert)
    c = detect(pos, angle, Shapes.regular(radius, nvert), wall_point, wall_normal, alert, pi, pj, wp, ww)
    check_layout(c)
    # the nearest point of each contact is within the alert distance; the second point of a
    # double within max(s0, 0) + alert <= 2 alert
    assert c.n_pairs > 100 and np.all(c.gap <= 2 * alert + 1e-9)
    first = np.r_[True, c.pair[1:] != c.pair[:-1]]
    nearest = np.minimum.reduceat(c.gap, np.flatnonzero(first))
    assert np.all(nearest <= alert + 1e-9)


def _random_convex(rng, size):
    """A random convex polygon (4-9 vertices, counter-clockwise) with its centroid at the origin,
    no more slender than the solver accepts (``solver.shapes.polygon_problem``)."""
    from scipy.spatial import ConvexHull

    from solver.shapes import polygon_problem

    while True:
        cloud = rng.normal(size=(rng.integers(5, 12), 2)) * size * rng.uniform(0.5, 1.5, 2)
        hull = cloud[ConvexHull(cloud).vertices]
        if len(hull) >= 4 and polygon_problem(hull) is None:
            break
    x, y = hull[:, 0], hull[:, 1]
    cross = x * np.roll(y, -1) - y * np.roll(x, -1)
    centroid = np.array([(cross * (x + np.roll(x, -1))).sum(), (cross * (y + np.roll(y, -1))).sum()])
    return hull - centroid / (3.0 * cross.sum())


@pytest.mark.parametrize("seed", [0, 1])
def test_irregular_polygons_from_the_shape_table_against_numpy_oracle(seed):
    """The kernels read the shape table's vertex lists of any length: irregular convex polygons
    give the separating-axis separation of the oracle, which rotates the body-frame vertices itself."""
    rng = np.random.default_rng(seed)
    n = 40
    local = [_random_convex(rng, 0.04) for _ in range(n)]
    shapes = Shapes.convex(local)
    pos, angle = rng.uniform(0, 0.8, (n, 2)), rng.uniform(0, 2 * np.pi, n)
    alert = 0.01
    pi, pj = candidate_pairs(pos, shapes.radius, alert)
    c = detect(pos, angle, shapes, *NO_WALLS, alert, pi, pj, [], [])
    check_layout(c)

    def world(b):
        rot = np.array([[np.cos(angle[b]), -np.sin(angle[b])], [np.sin(angle[b]), np.cos(angle[b])]])
        return pos[b] + local[b] @ rot.T

    checked = exact = 0
    for a, b in zip(pi.tolist(), pj.tolist()):
        sel = np.flatnonzero((c.body_i == a) & (c.body_j == b))
        sat = naive.sat_separation(world(a), world(b))
        assert (sel.size > 0) == (sat <= alert + 1e-13)
        if sel.size:
            checked += 1
            assert c.gap[sel].min() >= sat - 1e-12
            exact += abs(c.gap[sel].min() - sat) <= 1e-12
    assert checked >= 10 and exact >= 0.8 * checked, (checked, exact)


def test_detect_names_a_missing_shape_table():
    with pytest.raises(ParameterError, match="Shapes"):
        detect(np.zeros((2, 2)), np.zeros(2), np.ones(2), *NO_WALLS, 0.0, [0], [1], [], [])
