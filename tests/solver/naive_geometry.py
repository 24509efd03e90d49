"""Slow, obviously-correct numpy oracles for the geometry kernels of the solver.

Nothing here shares code with ``solver``: vertices, edges and normals are rebuilt from the
definitions (vertex k at angle + 2 pi k / n, counter-clockwise).
"""

from __future__ import annotations

import numpy as np


def all_pairs(pos, radius, alert):
    """Every pair i < j with |x_i - x_j| <= r_i + r_j + alert, as a sorted list of tuples."""
    pos = np.asarray(pos, float)
    d = np.sqrt(((pos[:, None, :] - pos[None, :, :]) ** 2).sum(-1))
    reach = radius[:, None] + radius[None, :] + alert
    i, j = np.nonzero(np.triu(d <= reach, k=1))
    return sorted(zip(i.tolist(), j.tolist()))


def polygon(x, y, r, theta, n):
    """(n, 2) vertices of a regular n-gon, counter-clockwise (the contract's convention): vertex
    k at (x, y) + r (cos(theta + 2 pi k/n), sin(theta + 2 pi k/n)), the polar form the solver's
    shape table evaluates, so that a vertex placed exactly on a wall here is exactly on it for
    the narrow phase too (the contract's p + Rot(theta) v_k agrees to round-off only)."""
    phase = theta + 2.0 * np.pi * np.arange(n) / n
    return np.stack([x + r * np.cos(phase), y + r * np.sin(phase)], -1)


def outward_normals(verts):
    """Outward unit normals of the edges k -> k+1 of a counter-clockwise convex polygon."""
    e = np.roll(verts, -1, axis=0) - verts
    nrm = np.column_stack([e[:, 1], -e[:, 0]])
    return nrm / np.linalg.norm(nrm, axis=1)[:, None]


def sat_separation(va, vb):
    """Largest edge-normal separation between convex polygons va, vb (separating axes on the
    edges of both): max over edges e of min over the partner's vertices of their signed
    distance to e's line. Negative = overlap, and then minus the penetration depth."""
    best = -np.inf
    for p, q in ((va, vb), (vb, va)):
        nrm = outward_normals(p)
        s = ((q[None, :, :] - p[:, None, :]) * nrm[:, None, :]).sum(-1)  # (edges, vertices)
        best = max(best, s.min(axis=1).max())
    return best


def sat_margin(va, vb):
    """Gap between the best and the second-best edge separation over both polygons: small
    values flag configurations where the choice of the reference edge is ambiguous."""
    vals = []
    for p, q in ((va, vb), (vb, va)):
        nrm = outward_normals(p)
        s = ((q[None, :, :] - p[:, None, :]) * nrm[:, None, :]).sum(-1)
        vals.extend(s.min(axis=1).tolist())
    vals = np.sort(vals)[::-1]
    return vals[0] - vals[1]


def point_segment_distance(p, a, b):
    """Euclidean distance from point p to segment ab."""
    ab = b - a
    t = np.clip(np.dot(p - a, ab) / np.dot(ab, ab), 0.0, 1.0)
    return np.linalg.norm(p - (a + t * ab))


def polygon_distance(va, vb):
    """Euclidean distance between two disjoint convex polygons (min vertex-to-edge distance
    both ways); meaningless if they overlap."""
    best = np.inf
    for p, q in ((va, vb), (vb, va)):
        for v in q:
            for k in range(len(p)):
                best = min(best, point_segment_distance(v, p[k], p[(k + 1) % len(p)]))
    return best


def clip_polygon(subject, clipper):
    """Sutherland-Hodgman clipping of convex polygon ``subject`` by convex ``clipper`` (both
    counter-clockwise); returns the intersection polygon's vertices (possibly empty)."""
    out = [tuple(v) for v in subject]
    nrm = outward_normals(clipper)
    for k in range(len(clipper)):
        a = clipper[k]
        inp, out = out, []
        if not inp:
            break
        for m in range(len(inp)):
            cur = np.array(inp[m])
            prev = np.array(inp[m - 1])
            dc = np.dot(cur - a, nrm[k])
            dp = np.dot(prev - a, nrm[k])
            if dc <= 0:
                if dp > 0:
                    out.append(tuple(prev + (cur - prev) * dp / (dp - dc)))
                out.append(tuple(cur))
            elif dp <= 0:
                out.append(tuple(prev + (cur - prev) * dp / (dp - dc)))
    return np.array(out).reshape(-1, 2)


def area(verts):
    """Shoelace area of a polygon (0 for fewer than 3 vertices)."""
    if len(verts) < 3:
        return 0.0
    x, y = verts[:, 0], verts[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def overlap_area(va, vb):
    """Area of the intersection of two convex polygons."""
    return area(clip_polygon(va, vb))


def fan_area_and_polar_moment(verts):
    """Area and polar moment of area about the centroid of a convex polygon, by numerical
    integration over a fan of triangles from vertex 0, with the 3-point edge-midpoint rule
    (exact for polynomials of degree 2, so for x, y and x^2 + y^2; no closed form used)."""
    total_a = 0.0
    first = np.zeros(2)
    second = 0.0
    for k in range(1, len(verts) - 1):
        p0, p1, p2 = verts[0], verts[k], verts[k + 1]
        e1, e2 = p1 - p0, p2 - p0
        a = 0.5 * abs(e1[0] * e2[1] - e1[1] * e2[0])
        for q in (0.5 * (p0 + p1), 0.5 * (p1 + p2), 0.5 * (p2 + p0)):
            total_a += a / 3.0
            first += a / 3.0 * q
            second += a / 3.0 * np.dot(q, q)
    centroid = first / total_a
    return total_a, second - total_a * np.dot(centroid, centroid)
