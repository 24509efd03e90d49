"""Narrow phase of contact detection: contact points, normals and gaps of candidate pairs.

Conventions (``grainview.contract.schema``, docs/conventions.md §0): the unit normal ``n`` of a
contact points from body i to body j; for a wall contact i is the particle and j = N + w, so
n = -n_w (n_w: the wall's unit normal, pointing into the sample). ``gap`` is the signed
distance between the two bodies along n at the contact point (m; negative = interpenetration).
A contact (body pair) is kept when its smallest gap is <= alert, so that the solver also sees
closing gaps. Each contact gives one point (``simple``) or two (``double``, paper Fig. 1).

Contact geometry per kind of pair (paper Sec. II, "Contact dynamics for polygons"):

* disk-disk: n along the centre line, gap = |x_j - x_i| - r_i - r_j, point midway between the
  two surfaces on the centre line.
* disk-wall: gap = (x - p_w).n_w - r, point midway between the disk's extreme point and the wall.
* polygon-wall: the vertex nearest to the wall gives a simple contact. When the other end of
  the edge most parallel to the wall passes the double-contact criterion below, the edge gives a
  DOUBLE contact with one point per vertex. Each point is the middle of the vertex and its
  orthogonal projection onto the wall, with the vertex's own gap.
* polygon-polygon (Moreau's "shadow overlap", written as separating axes on the edge
  normals): for each edge e of either polygon, s_e = min over the partner's vertices of their
  signed distance to e's line; the REFERENCE edge has the largest s_e (least penetration or
  largest separation); its outward normal is n and s_e the gap. The partner's vertex reaching
  that minimum is the intruding vertex: a SIMPLE contact, its point the middle of the vertex
  and its orthogonal projection onto the reference edge (paper: "the nominal contact point is
  chosen at the center of this distance").
  When the other end of the partner's edge most anti-parallel to the reference edge (the
  INCIDENT edge) passes the double-contact criterion below (its distance to the reference
  line), the two edges
  overlap: a DOUBLE contact. Its normal is the mean of the reference normal and minus the
  incident normal (the common tangent is the mean direction of the two edges). The incident
  edge is clipped to the reference edge's extent (the clipping of Box2D: E. Catto, "Contact
  manifolds", GDC 2007); each end of this common segment, moved to the middle of itself and
  its projection onto the reference line, is a point, with its own gap (separation from the
  reference line; it differs from the distance along the mean normal by a factor
  1/cos(delta/2), delta the angle between the edges, i.e. by O(delta^2)).
  A common segment shorter than :data:`DOUBLE_MIN_OVERLAP` of the reference edge (edges meeting
  at one corner) gives a simple contact; if the intruding vertex then lies beyond the ends of
  the reference edge, that simple contact is taken at the point of the incident edge facing
  the nearest end of the reference edge (vertex on vertex: the common corner), with its own
  separation as gap.
* polygon-disk: closest feature. Centre outside the polygon: the nearest point q of the
  boundary (on an edge or at a vertex), n along q -> centre, gap = |centre - q| - r. Centre
  inside: the edge with the largest signed distance s, n its outward normal, gap = s - r.

Double-contact criterion: the second vertex (s1, the other end of the incident edge or of
the edge facing the wall) is taken when s1 <= max(s0, 0) + double_alert (+
:data:`DOUBLE_GAP_TOLERANCE` for round-off), s0 the gap of the nearest vertex and
``double_alert`` the alert distance unless the caller sets it. Two edges at an angle delta
therefore form a double contact when L sin(delta) <~ double_alert (L the edge length), an
angular tolerance of about asin(double_alert / L), whether they touch or are still apart;
overlapping edges (s0 < 0) need s1 <= double_alert. For edges within 10 degrees of
anti-parallel (:data:`DOUBLE_CLIP_COS`) the test is also made at the end of the common segment
instead of at s1: when the incident edge overhangs the reference edge (corner on corner), its
far vertex may be far from the reference line while the common segment lies within
double_alert of it, and a single point would leave the second corner free to turn into the
partner (the fast friction-0 compaction of benchmarks/RESULTS.md §f). Each point is a unilateral constraint of its own
in the solver, so a point that is within the alert distance but not touching carries no force;
an analysis that wants "double" to mean "two force-bearing points" should check the forces.

Tie-breaking and symmetry: every pair is computed in the canonical order (lower body id first)
and the normal flipped when the caller passed the higher id first; at equal separations (to
1e-12 of the radii) the lower id's edge is the reference. Swapping i and j therefore gives the
same points and gaps with the opposite normal. The two points of a double contact are ordered
along the tangent t = (-n_y, n_x) of the canonical normal (from the lower id to the higher).

Known approximations and limits:

* as in every separating-axis detector, for two SEPARATED polygons whose nearest features are
  two vertices the gap is the largest edge-normal separation, a lower bound of the true
  distance; it is exact for vertex-edge nearest features and for any overlap, where -gap is
  the penetration depth (the shortest translation separating the two polygons);
* with alert = 0, bodies exactly touching may be dropped by round-off (gap ~ +1e-16): use a
  small positive alert;
* for penetrations deeper than a good fraction of an edge (far outside the solver's regime),
  the choice between the two edges at the intruding vertex can be a tie decided by round-off.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit, prange

from grainview.contract.errors import ParameterError
from grainview.contract.schema import KIND_DOUBLE, KIND_SIMPLE

from .broadphase import check_walls
from .shapes import Shapes

__all__ = ["ContactPoints", "detect", "KIND_SIMPLE", "KIND_DOUBLE", "DOUBLE_MIN_OVERLAP",
           "DOUBLE_GAP_TOLERANCE"]


DOUBLE_MIN_OVERLAP = 1e-9
"""A double contact needs a common segment longer than this fraction of the reference edge
length; shorter ones (edges meeting at a single corner) give a simple contact."""

DOUBLE_CLIP_COS = math.cos(math.radians(10.0))
"""Edges within 10 degrees of anti-parallel are also tested at the clipped end of the incident
edge (corner on corner: the incident edge overhangs the reference edge), see the module doc."""

DOUBLE_GAP_TOLERANCE = 1e-10
"""Round-off allowance of the double-contact test: the second vertex is taken when its gap is
<= max(s0, 0) + double_alert + DOUBLE_GAP_TOLERANCE * (sum of the circumscribed radii), so that exactly parallel
edges touching with alert = 0 give a double contact whatever the last bits of the vertices."""


class ContactPoints(NamedTuple):
    """Contact points found by :func:`detect`, one entry per point (length P).

    body_i, body_j : int32 (P,) — the two bodies (j = N + w for wall w).
    normal : float64 (P, 2) — unit normal from i to j.
    point : float64 (P, 2) — contact point, m.
    gap : float64 (P,) — signed distance along the normal, m (negative = interpenetration).
    kind : int8 (P,) — 1 simple, 2 double (``grainview.contract.schema.KIND_SIMPLE``/``KIND_DOUBLE``).
    pair : int32 (P,) — index of the contact (body pair), 0 .. n_pairs-1; the two points of a
        double contact are adjacent and share it.
    n_pairs : int — number of contacts (pairs) kept.
    """

    body_i: np.ndarray
    body_j: np.ndarray
    normal: np.ndarray
    point: np.ndarray
    gap: np.ndarray
    kind: np.ndarray
    pair: np.ndarray
    n_pairs: int


# ----------------------------------------------------------------------------------------
# the records the kernels pass: one per concept, each a named tuple of arrays. A kernel that
# calls another (not inlined) one takes a reference to every array of the records it receives,
# on entry, and drops them at each return (atomic counts that LLVM keeps): the per-pair kernels
# therefore receive only what they read (Outlines, Slots), the bookkeeping stays in Tally, and
# _best_edge is inlined so that _polygon_polygon calls nothing and keeps no counts.
# ----------------------------------------------------------------------------------------

class PlacedShapes(NamedTuple):
    """The bodies where they stand: centres, rotations and the shape table
    (:class:`solver.shapes.Shapes`), N bodies owning V vertices in all.

    pos : float64 (N, 2) — centres, m.
    angle : float64 (N,) — rotations, rad.
    radius : float64 (N,) — circumscribed radii, m (a disk's radius).
    n_vertices : int32 (N,) — 0 for a disk, n >= 3 for a polygon.
    first_vertex : int64 (N + 1,) — body b owns the vertices first_vertex[b]:first_vertex[b + 1].
    vertex_radius : float64 (V,) — distance of each vertex from its body's centre, m.
    vertex_angle : float64 (V,) — polar angle of each vertex from its body's rotation, rad.
    normal_angle : float64 (V,) — polar angle of the outward unit normal of edge k (vertex
        k -> k + 1) from its body's rotation, rad.
    """

    pos: np.ndarray
    angle: np.ndarray
    radius: np.ndarray
    n_vertices: np.ndarray
    first_vertex: np.ndarray
    vertex_radius: np.ndarray
    vertex_angle: np.ndarray
    normal_angle: np.ndarray


class Outlines(NamedTuple):
    """What the pair kernels read of each body: centre, size and outline in the world frame
    (:func:`_polygon_geometry`), maxn the largest vertex count (at least 1).

    pos : float64 (N, 2) — centres, m.
    radius : float64 (N,) — circumscribed radii, m.
    nvert : int32 (N,) — vertex count, 0 for a disk.
    verts : float64 (N, maxn, 2) — world vertices of each polygon, counter-clockwise, m
        (rows from nvert on are unused).
    norms : float64 (N, maxn, 2) — outward unit normal of edge k (vertex k -> k + 1).
    """

    pos: np.ndarray
    radius: np.ndarray
    nvert: np.ndarray
    verts: np.ndarray
    norms: np.ndarray


class WallLines(NamedTuple):
    """The walls as detection sees them, W lines.

    point : float64 (W, 2) — a point of each wall line, m.
    normal : float64 (W, 2) — each wall's unit normal, pointing into the sample.
    """

    point: np.ndarray
    normal: np.ndarray


class Candidates(NamedTuple):
    """The broad phase's candidates (:mod:`solver.broadphase`): M particle pairs and K
    particle-wall pairs; candidate c < M is the pair c, candidate M + k the wall pair k.

    pi, pj : int32 (M,) — the two particles of each pair (any order, pi != pj).
    wp, ww : int32 (K,) — the particle and the wall of each wall pair.
    """

    pi: np.ndarray
    pj: np.ndarray
    wp: np.ndarray
    ww: np.ndarray


class Alerts(NamedTuple):
    """The distances of :func:`detect`, m.

    alert : float — a contact is kept when its nearest point's gap is <= alert (>= 0).
    double_alert : float — the tolerance of the double-contact criterion (module doc, >= 0).
    """

    alert: float
    double_alert: float


class Slots(NamedTuple):
    """Scratch of :func:`_detect_kernel`, what the geometry of a pair writes: one slot per
    candidate c (M + K of them), written only by c in pass 1 and read in pass 2.

    normal : float64 (M + K, 2) — unit normal of c, from its first body to its second.
    point : float64 (M + K, 2, 2) — its one or two points, m.
    gap : float64 (M + K, 2) — their gaps, m (negative = interpenetration).
    """

    normal: np.ndarray
    point: np.ndarray
    gap: np.ndarray


class Tally(NamedTuple):
    """Scratch of :func:`_detect_kernel`, which slots are kept and where their points go
    (M + K candidates).

    count : int64 (M + K,) — the points kept of c: 1 or 2, 0 when its nearest gap exceeds alert.
    kind : int8 (M + K,) — KIND_SIMPLE or KIND_DOUBLE.
    offsets : int64 (M + K + 1,) — the output row of c's first point (prefix sum of count).
    pair_offsets : int64 (M + K + 1,) — the contact index of c (prefix sum of count > 0).
    """

    count: np.ndarray
    kind: np.ndarray
    offsets: np.ndarray
    pair_offsets: np.ndarray


# ----------------------------------------------------------------------------------------
# geometry of one pair; each writes up to two points into slot c of the scratch ``slots``
# and returns how many. Normal: from the first body (a) to the second (b).
# ----------------------------------------------------------------------------------------

@njit(cache=True)
def _disk_disk(a, b, bodies, c, slots):
    """Contact of disks a and b (module doc); normal from a to b."""
    pos = bodies.pos
    radius = bodies.radius
    xa = pos[a, 0]
    ya = pos[a, 1]
    ra = radius[a]
    xb = pos[b, 0]
    yb = pos[b, 1]
    rb = radius[b]
    normal = slots.normal
    point = slots.point
    gap = slots.gap
    dx = xb - xa
    dy = yb - ya
    dist = math.sqrt(dx * dx + dy * dy)
    if dist > 0.0:
        nx = dx / dist
        ny = dy / dist
    else:  # coincident centres: any direction is a normal; take +x
        nx = 1.0
        ny = 0.0
    g = dist - ra - rb
    normal[c, 0] = nx
    normal[c, 1] = ny
    gap[c, 0] = g
    point[c, 0, 0] = xa + nx * (ra + 0.5 * g)
    point[c, 0, 1] = ya + ny * (ra + 0.5 * g)
    return 1


@njit(cache=True)
def _disk_wall(p, w, bodies, walls, c, slots):
    """Contact of disk p with wall w (module doc); normal from the disk to the wall."""
    pos = bodies.pos
    wall_point = walls.point
    wall_normal = walls.normal
    x = pos[p, 0]
    y = pos[p, 1]
    r = bodies.radius[p]
    px = wall_point[w, 0]
    py = wall_point[w, 1]
    wnx = wall_normal[w, 0]
    wny = wall_normal[w, 1]
    normal = slots.normal
    point = slots.point
    gap = slots.gap
    s = (x - px) * wnx + (y - py) * wny  # signed distance of the centre to the wall line
    g = s - r
    normal[c, 0] = -wnx
    normal[c, 1] = -wny
    gap[c, 0] = g
    point[c, 0, 0] = x - wnx * (r + 0.5 * g)
    point[c, 0, 1] = y - wny * (r + 0.5 * g)
    return 1


@njit(cache=True)
def _polygon_block(lo, hi, placed, verts, norms):
    """The world vertices and edge normals of particles lo..hi-1 (:func:`_polygon_geometry`)."""
    pos = placed.pos
    angle = placed.angle
    nvert = placed.n_vertices
    first_vertex = placed.first_vertex
    vertex_radius = placed.vertex_radius
    vertex_angle = placed.vertex_angle
    normal_angle = placed.normal_angle
    for p in range(lo, hi):
        s = first_vertex[p]
        for k in range(nvert[p]):
            phi = angle[p] + vertex_angle[s + k]
            verts[p, k, 0] = pos[p, 0] + vertex_radius[s + k] * math.cos(phi)
            verts[p, k, 1] = pos[p, 1] + vertex_radius[s + k] * math.sin(phi)
            psi = angle[p] + normal_angle[s + k]
            norms[p, k, 0] = math.cos(psi)
            norms[p, k, 1] = math.sin(psi)


@njit(cache=True, parallel=True)
def _polygon_blocks(chunks, placed, verts, norms):
    """:func:`_polygon_block` over ``chunks`` consecutive blocks of particles at once (a thread each)."""
    n = placed.pos.shape[0]
    for d in prange(chunks):
        _polygon_block(n * d // chunks, n * (d + 1) // chunks, placed, verts, norms)


@njit(cache=True)
def _polygon_geometry(placed, chunks=1):
    """The :class:`Outlines` of the bodies ``placed`` (:class:`PlacedShapes`): world vertices
    (N, maxn, 2) and outward unit edge normals (N, maxn, 2) of every polygon from the shape
    table, vertex k at the polar angle angle + vertex_angle[k] and distance vertex_radius[k],
    the normal of edge k (vertex k -> k+1) at angle + normal_angle[k]. With ``chunks`` > 1 the
    particles are split into that many consecutive blocks computed at once (a thread each; each
    particle's entries are its own); with 1 no second thread is woken."""
    n = placed.pos.shape[0]
    nvert = placed.n_vertices
    maxn = 1
    for p in range(n):
        maxn = max(maxn, nvert[p])
    verts = np.zeros((n, maxn, 2))
    norms = np.zeros((n, maxn, 2))
    if chunks == 1:
        _polygon_block(0, n, placed, verts, norms)
    else:
        _polygon_blocks(chunks, placed, verts, norms)
    return Outlines(placed.pos, placed.radius, nvert, verts, norms)


@njit(cache=True, inline="always")
def _best_edge(p, q, bodies):
    """Separating-axis search over the edges of polygon p: returns (s, e, k) with
    s = max_e min_k (v_q,k - v_p,e) . n_p,e, e the maximising edge, k the vertex of q
    reaching the minimum (the deepest vertex against edge e)."""
    verts = bodies.verts
    norms = bodies.norms
    nvert = bodies.nvert
    best = -math.inf
    best_e = 0
    best_k = 0
    for e in range(nvert[p]):
        ax = verts[p, e, 0]
        ay = verts[p, e, 1]
        nx = norms[p, e, 0]
        ny = norms[p, e, 1]
        smin = math.inf
        kmin = 0
        for k in range(nvert[q]):
            s = (verts[q, k, 0] - ax) * nx + (verts[q, k, 1] - ay) * ny
            if s < smin:
                smin = s
                kmin = k
        if smin > best:
            best = smin
            best_e = e
            best_k = kmin
    return best, best_e, best_k


@njit(cache=True)
def _polygon_polygon(a, b, bodies, double_alert, c, slots):
    """Shadow-overlap contact of polygons a and b; normal from a to b. See the module doc."""
    verts = bodies.verts
    norms = bodies.norms
    nvert = bodies.nvert
    radius = bodies.radius
    normal = slots.normal
    point = slots.point
    gap = slots.gap
    sa, ea, ka = _best_edge(a, b, bodies)
    sb, eb, kb = _best_edge(b, a, bodies)
    # reference polygon: the one with the larger separation; at a tie (within round-off) a
    if sb > sa + 1e-12 * (radius[a] + radius[b]):
        ref, inc, e, k0, s0, sign = b, a, eb, kb, sb, -1.0
    else:
        ref, inc, e, k0, s0, sign = a, b, ea, ka, sa, 1.0
    nrx = norms[ref, e, 0]
    nry = norms[ref, e, 1]
    m_ref = nvert[ref]
    m_inc = nvert[inc]
    r0x = verts[ref, e, 0]
    r0y = verts[ref, e, 1]
    r1x = verts[ref, (e + 1) % m_ref, 0]
    r1y = verts[ref, (e + 1) % m_ref, 1]
    v0x = verts[inc, k0, 0]
    v0y = verts[inc, k0, 1]
    # incident edge: the edge at k0 most anti-parallel to the reference edge
    e_next = k0
    e_prev = (k0 - 1 + m_inc) % m_inc
    d_next = norms[inc, e_next, 0] * nrx + norms[inc, e_next, 1] * nry
    d_prev = norms[inc, e_prev, 0] * nrx + norms[inc, e_prev, 1] * nry
    if d_next <= d_prev:
        e_inc = e_next
        k1 = (k0 + 1) % m_inc
    else:
        e_inc = e_prev
        k1 = e_prev
    v1x = verts[inc, k1, 0]
    v1y = verts[inc, k1, 1]
    s1 = (v1x - r0x) * nrx + (v1y - r0y) * nry
    n_points = 1
    threshold = max(s0, 0.0) + double_alert + DOUBLE_GAP_TOLERANCE * (radius[a] + radius[b])
    far_ok = s1 <= threshold
    # near-parallel edges: the criterion is also tested at the clipped end of the incident edge
    # (a long incident edge against a short reference edge, corner on corner)
    near_parallel = min(d_next, d_prev) <= -DOUBLE_CLIP_COS
    if far_ok or near_parallel:
        # clip the incident edge v0 -> v1 to the extent [0, L] of the reference edge
        length = math.sqrt((r1x - r0x) ** 2 + (r1y - r0y) ** 2)
        ux = (r1x - r0x) / length
        uy = (r1y - r0y) / length
        t0 = (v0x - r0x) * ux + (v0y - r0y) * uy
        t1 = (v1x - r0x) * ux + (v1y - r0y) * uy
        dt = t1 - t0  # never 0: the two edges are within 90 degrees of anti-parallel
        lam_a = (0.0 - t0) / dt
        lam_b = (length - t0) / dt
        lo = max(0.0, min(lam_a, lam_b))
        hi = min(1.0, max(lam_a, lam_b))
        clip_ok = far_ok or (s0 + hi * (s1 - s0) <= threshold)
        if clip_ok and (hi - lo) * abs(dt) > DOUBLE_MIN_OVERLAP * length:
            n_points = 2
        elif far_ok and (t0 < 0.0 or t0 > length):
            # near-parallel edges meeting at (or missing by) one corner, the deepest vertex
            # beyond the reference edge: take the point of the incident edge facing the
            # nearest end of the reference edge (e.g. vertex on vertex)
            if t0 < 0.0:
                lam = min(1.0, max(0.0, lam_a))
            else:
                lam = min(1.0, max(0.0, lam_b))
            v0x = v0x + lam * (v1x - v0x)
            v0y = v0y + lam * (v1y - v0y)
            s0 = (v0x - r0x) * nrx + (v0y - r0y) * nry
    if n_points == 1:
        normal[c, 0] = sign * nrx
        normal[c, 1] = sign * nry
        gap[c, 0] = s0
        point[c, 0, 0] = v0x - 0.5 * s0 * nrx
        point[c, 0, 1] = v0y - 0.5 * s0 * nry
        return 1
    # double: mean normal of the two edges (common tangent = mean edge direction)
    mx = nrx - norms[inc, e_inc, 0]
    my = nry - norms[inc, e_inc, 1]
    mn = math.sqrt(mx * mx + my * my)
    mx = sign * mx / mn
    my = sign * my / mn
    normal[c, 0] = mx
    normal[c, 1] = my
    qax = v0x + lo * (v1x - v0x)
    qay = v0y + lo * (v1y - v0y)
    qbx = v0x + hi * (v1x - v0x)
    qby = v0y + hi * (v1y - v0y)
    sa_ = (qax - r0x) * nrx + (qay - r0y) * nry
    sb_ = (qbx - r0x) * nrx + (qby - r0y) * nry
    pax = qax - 0.5 * sa_ * nrx
    pay = qay - 0.5 * sa_ * nry
    pbx = qbx - 0.5 * sb_ * nrx
    pby = qby - 0.5 * sb_ * nry
    # order along the tangent t = (-n_y, n_x) of the normal from a to b
    if pax * (-my) + pay * mx > pbx * (-my) + pby * mx:
        pax, pay, pbx, pby, sa_, sb_ = pbx, pby, pax, pay, sb_, sa_
    gap[c, 0] = sa_
    gap[c, 1] = sb_
    point[c, 0, 0] = pax
    point[c, 0, 1] = pay
    point[c, 1, 0] = pbx
    point[c, 1, 1] = pby
    return 2


@njit(cache=True)
def _polygon_disk(p, d, bodies, sign, c, slots):
    """Contact of polygon p and disk d by the closest feature; the normal points from the
    polygon to the disk, multiplied by ``sign``."""
    pos = bodies.pos
    verts = bodies.verts
    norms = bodies.norms
    nvert = bodies.nvert
    radius = bodies.radius
    normal = slots.normal
    point = slots.point
    gap = slots.gap
    cx = pos[d, 0]
    cy = pos[d, 1]
    rd = radius[d]
    m = nvert[p]
    smax = -math.inf
    emax = 0
    for e in range(m):
        s = (cx - verts[p, e, 0]) * norms[p, e, 0] + (cy - verts[p, e, 1]) * norms[p, e, 1]
        if s > smax:
            smax = s
            emax = e
    nx = norms[p, emax, 0]
    ny = norms[p, emax, 1]
    if smax <= 0.0:  # centre inside: nearest edge
        dist = smax
        qx = cx - smax * nx
        qy = cy - smax * ny
    else:  # centre outside: nearest point of the boundary (an edge or a vertex)
        dist = math.inf
        qx = 0.0
        qy = 0.0
        for e in range(m):
            ax = verts[p, e, 0]
            ay = verts[p, e, 1]
            bx = verts[p, (e + 1) % m, 0]
            by = verts[p, (e + 1) % m, 1]
            ex = bx - ax
            ey = by - ay
            lam = ((cx - ax) * ex + (cy - ay) * ey) / (ex * ex + ey * ey)
            lam = min(1.0, max(0.0, lam))
            px = ax + lam * ex
            py = ay + lam * ey
            dd = math.sqrt((cx - px) ** 2 + (cy - py) ** 2)
            if dd < dist:
                dist = dd
                qx = px
                qy = py
        if dist > 1e-14 * radius[p]:
            nx = (cx - qx) / dist
            ny = (cy - qy) / dist
    g = dist - rd
    normal[c, 0] = sign * nx
    normal[c, 1] = sign * ny
    gap[c, 0] = g
    point[c, 0, 0] = qx + 0.5 * g * nx
    point[c, 0, 1] = qy + 0.5 * g * ny
    return 1


@njit(cache=True)
def _polygon_wall(p, w, bodies, walls, double_alert, c, slots):
    """Contact of polygon p with wall w, the line through (px, py) of inward unit normal
    (wnx, wny)."""
    verts = bodies.verts
    nvert = bodies.nvert
    radius = bodies.radius
    wall_point = walls.point
    wall_normal = walls.normal
    px = wall_point[w, 0]
    py = wall_point[w, 1]
    wnx = wall_normal[w, 0]
    wny = wall_normal[w, 1]
    normal = slots.normal
    point = slots.point
    gap = slots.gap
    n = nvert[p]
    # signed distance of every vertex to the wall line; lowest vertex k0
    k0 = 0
    s0 = math.inf
    for k in range(n):
        s = (verts[p, k, 0] - px) * wnx + (verts[p, k, 1] - py) * wny
        if s < s0:
            s0 = s
            k0 = k
    # lower neighbour of k0: the other end of the edge most parallel to the wall
    kp = (k0 + 1) % n
    km = (k0 - 1 + n) % n
    sp = (verts[p, kp, 0] - px) * wnx + (verts[p, kp, 1] - py) * wny
    sm = (verts[p, km, 0] - px) * wnx + (verts[p, km, 1] - py) * wny
    if sp <= sm:
        k1 = kp
        s1 = sp
    else:
        k1 = km
        s1 = sm
    normal[c, 0] = -wnx
    normal[c, 1] = -wny
    v0x = verts[p, k0, 0]
    v0y = verts[p, k0, 1]
    if s1 > max(s0, 0.0) + double_alert + DOUBLE_GAP_TOLERANCE * radius[p]:
        gap[c, 0] = s0
        point[c, 0, 0] = v0x - 0.5 * s0 * wnx
        point[c, 0, 1] = v0y - 0.5 * s0 * wny
        return 1
    v1x = verts[p, k1, 0]
    v1y = verts[p, k1, 1]
    # order the two points along t = (-n_y, n_x) with n = -n_w: t = (n_w,y, -n_w,x)
    tx = wny
    ty = -wnx
    if v0x * tx + v0y * ty > v1x * tx + v1y * ty:
        v0x, v0y, v1x, v1y = v1x, v1y, v0x, v0y
        s0, s1 = s1, s0
    gap[c, 0] = s0
    gap[c, 1] = s1
    point[c, 0, 0] = v0x - 0.5 * s0 * wnx
    point[c, 0, 1] = v0y - 0.5 * s0 * wny
    point[c, 1, 0] = v1x - 0.5 * s1 * wnx
    point[c, 1, 1] = v1y - 0.5 * s1 * wny
    return 2


@njit(cache=True)
def _pair_points(a, b, bodies, double_alert, c, slots):
    """Contact points between particles a < b, normal from a to b. Returns the count (1 or 2)."""
    nvert = bodies.nvert
    na = nvert[a]
    nb = nvert[b]
    if na == 0 and nb == 0:
        return _disk_disk(a, b, bodies, c, slots)
    if na == 0:
        return _polygon_disk(b, a, bodies, -1.0, c, slots)
    if nb == 0:
        return _polygon_disk(a, b, bodies, 1.0, c, slots)
    return _polygon_polygon(a, b, bodies, double_alert, c, slots)


@njit(cache=True)
def _candidate_block(lo, hi, bodies, walls, candidates, alerts, slots, tally):
    """Pass 1 for candidates lo..hi-1: up to two points of candidate c into its own slot
    (slots.normal[c], .point[c], .gap[c]), tally.kind[c] and tally.count[c] = their number if
    the nearest is within ``alerts.alert``, else 0."""
    alert = alerts.alert
    double_alert = alerts.double_alert
    pi = candidates.pi
    pj = candidates.pj
    wp = candidates.wp
    ww = candidates.ww
    m_pairs = pi.shape[0]
    nvert = bodies.nvert
    count = tally.count
    normal = slots.normal
    gap = slots.gap
    kind = tally.kind
    for c in range(lo, hi):
        if c < m_pairs:
            i = pi[c]
            j = pj[c]
            a = min(i, j)
            b = max(i, j)
            cnt = _pair_points(a, b, bodies, double_alert, c, slots)
            if i > j:
                normal[c, 0] = -normal[c, 0]
                normal[c, 1] = -normal[c, 1]
        else:
            p = wp[c - m_pairs]
            w = ww[c - m_pairs]
            if nvert[p] == 0:
                cnt = _disk_wall(p, w, bodies, walls, c, slots)
            else:
                cnt = _polygon_wall(p, w, bodies, walls, double_alert, c, slots)
        kind[c] = KIND_DOUBLE if cnt == 2 else KIND_SIMPLE
        # keep the contact if its nearest point is within the alert distance
        gmin = gap[c, 0]
        if cnt == 2 and gap[c, 1] < gmin:
            gmin = gap[c, 1]
        count[c] = cnt if (cnt > 0 and gmin <= alert) else 0


@njit(cache=True)
def _compact_block(lo, hi, n_particles, candidates, slots, tally, out):
    """Pass 2 for candidates lo..hi-1: the kept points of candidate c to rows
    tally.offsets[c]... of ``out`` (:class:`ContactPoints`), wall w as body n_particles + w."""
    pi = candidates.pi
    pj = candidates.pj
    wp = candidates.wp
    ww = candidates.ww
    m_pairs = pi.shape[0]
    count = tally.count
    offsets = tally.offsets
    pair_offsets = tally.pair_offsets
    normal = slots.normal
    point = slots.point
    gap = slots.gap
    kind = tally.kind
    o_i = out.body_i
    o_j = out.body_j
    o_normal = out.normal
    o_point = out.point
    o_gap = out.gap
    o_kind = out.kind
    o_pair = out.pair
    for c in range(lo, hi):
        if c < m_pairs:
            bi = pi[c]
            bj = pj[c]
        else:
            bi = wp[c - m_pairs]
            bj = n_particles + ww[c - m_pairs]
        for k in range(count[c]):
            q = offsets[c] + k
            o_i[q] = bi
            o_j[q] = bj
            o_normal[q, 0] = normal[c, 0]
            o_normal[q, 1] = normal[c, 1]
            o_point[q, 0] = point[c, k, 0]
            o_point[q, 1] = point[c, k, 1]
            o_gap[q] = gap[c, k]
            o_kind[q] = kind[c]
            o_pair[q] = pair_offsets[c]


@njit(cache=True, parallel=True)
def _candidate_blocks(chunks, bodies, walls, candidates, alerts, slots, tally):
    """:func:`_candidate_block` over ``chunks`` consecutive blocks of candidates at once (a thread each)."""
    m = tally.count.size
    for d in prange(chunks):
        _candidate_block(m * d // chunks, m * (d + 1) // chunks, bodies, walls, candidates, alerts, slots, tally)


@njit(cache=True, parallel=True)
def _compact_blocks(chunks, n_particles, candidates, slots, tally, out):
    """:func:`_compact_block` over ``chunks`` consecutive blocks of candidates at once (a thread each)."""
    m = tally.count.size
    for d in prange(chunks):
        _compact_block(m * d // chunks, m * (d + 1) // chunks, n_particles, candidates, slots, tally, out)


@njit(cache=True)
def _detect_kernel(placed, walls, candidates, alerts, chunks):
    """Pass 1: up to two points per candidate into fixed slots (each candidate writes only its
    own slot); pass 2: compaction of the kept ones at prefix-sum offsets. With ``chunks`` > 1
    both passes split the candidates into that many consecutive blocks done at once (a thread
    each); as no slot is shared, the result does not depend on ``chunks``. With 1 no second
    thread is woken (a woken thread waits for a busy core), and the allocations stay out of
    the parallel functions (numba would make each one a parallel region).

    ``placed`` : :class:`PlacedShapes`; ``walls`` : :class:`WallLines`; ``candidates`` :
    :class:`Candidates`; ``alerts`` : :class:`Alerts`. Returns the :class:`ContactPoints`."""
    n_particles = placed.pos.shape[0]
    m = candidates.pi.shape[0] + candidates.wp.shape[0]
    slots = Slots(np.empty((m, 2)), np.empty((m, 2, 2)), np.empty((m, 2)))
    tally = Tally(np.zeros(m, np.int64), np.empty(m, np.int8), np.zeros(m + 1, np.int64), np.zeros(m + 1, np.int64))
    bodies = _polygon_geometry(placed, chunks)
    if chunks == 1:
        _candidate_block(0, m, bodies, walls, candidates, alerts, slots, tally)
    else:
        _candidate_blocks(chunks, bodies, walls, candidates, alerts, slots, tally)
    count = tally.count
    offsets = tally.offsets
    pair_offsets = tally.pair_offsets
    for c in range(m):
        offsets[c + 1] = offsets[c] + count[c]
        pair_offsets[c + 1] = pair_offsets[c] + (1 if count[c] > 0 else 0)
    total = offsets[m]
    out = ContactPoints(np.empty(total, np.int32), np.empty(total, np.int32), np.empty((total, 2)),
                        np.empty((total, 2)), np.empty(total), np.empty(total, np.int8), np.empty(total, np.int32),
                        pair_offsets[m])
    if chunks == 1:
        _compact_block(0, m, n_particles, candidates, slots, tally, out)
    else:
        _compact_blocks(chunks, n_particles, candidates, slots, tally, out)
    return out


def _index_array(name, value, upper):
    arr = np.ascontiguousarray(value).reshape(-1)
    if arr.size and arr.dtype.kind not in "iu":
        raise ParameterError(f"{name} must hold integer indices")
    arr = arr.astype(np.int32)
    if arr.size and (arr.min() < 0 or arr.max() >= upper):
        raise ParameterError(f"{name} holds indices outside 0..{upper - 1}")
    return arr


def detect(pos, angle, shapes, wall_point, wall_normal, alert, pi, pj, wp, ww, double_alert=None, threads=1):
    """Contact points of the candidate particle pairs (pi, pj) and particle-wall candidates
    (wp, ww) (from :mod:`solver.broadphase`), keeping the contacts with gap <= alert.

    Parameters
    ----------
    pos : (N, 2) m; angle : (N,) rad;
    shapes : :class:`solver.shapes.Shapes`, the bodies' shapes (e.g. ``Shapes.regular(radius,
    n_vertices)``: circumscribed radii in m, 0 vertices for a disk);
    wall_point : (W, 2) m, a point of each wall line; wall_normal : (W, 2) unit, into the sample;
    alert : m, >= 0; pi, pj : particle pairs (any order, pi != pj);
    wp, ww : particle and wall index of each wall candidate;
    double_alert : m, >= 0, the tolerance of the double-contact criterion (module doc);
    default ``alert``. The stepper widens ``alert`` for fast steps but keeps this one fixed,
    so that a fast approach does not turn edges far from parallel into double contacts.
    threads : int >= 1, the candidates are split into this many blocks computed at once (a
    thread each, as the NLGS's domains); the result is the same for any number.

    Returns
    -------
    ContactPoints (see its docstring): particle pairs first, in candidate order, then wall
    contacts; body ids are as passed (i = pi, j = pj; wall contacts i = particle, j = N + w).
    """
    if not isinstance(shapes, Shapes):
        raise ParameterError(f"shapes must be a solver.shapes.Shapes (e.g. Shapes.regular(radius, n_vertices)), "
                             f"got {type(shapes).__name__}")
    n = len(shapes)
    pos = np.ascontiguousarray(pos, dtype=np.float64)
    if pos.shape != (n, 2):
        raise ParameterError(f"pos must have shape ({n}, 2), got {pos.shape}")
    angle = np.ascontiguousarray(np.broadcast_to(np.asarray(angle, dtype=np.float64), (n,)))
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(angle))):
        raise ParameterError("pos and angle must be finite")
    wall_point, wall_normal = check_walls(wall_point, wall_normal)
    alert = float(alert)
    if not np.isfinite(alert) or alert < 0:
        raise ParameterError(f"alert={alert!r}: expected a finite alert distance >= 0 (m)")
    double_alert = alert if double_alert is None else float(double_alert)
    if not np.isfinite(double_alert) or double_alert < 0:
        raise ParameterError(f"double_alert={double_alert!r}: expected a finite distance >= 0 (m)")
    pi = _index_array("pi", pi, n)
    pj = _index_array("pj", pj, n)
    if pi.shape != pj.shape:
        raise ParameterError(f"pi and pj must have the same length, got {pi.size} and {pj.size}")
    if np.any(pi == pj):
        raise ParameterError("pi and pj must not pair a particle with itself")
    wp = _index_array("wp", wp, n)
    ww = _index_array("ww", ww, wall_point.shape[0])
    if wp.shape != ww.shape:
        raise ParameterError(f"wp and ww must have the same length, got {wp.size} and {ww.size}")
    if not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ParameterError(f"threads={threads!r}: expected an integer >= 1")
    placed = PlacedShapes(pos, angle, shapes.radius, shapes.n_vertices, shapes.first_vertex, shapes.vertex_radius,
                          shapes.vertex_angle, shapes.normal_angle)
    return _detect_kernel(placed, WallLines(wall_point, wall_normal), Candidates(pi, pj, wp, ww),
                          Alerts(alert, double_alert), int(threads))
