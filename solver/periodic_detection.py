"""Contact detection in a periodic cell: candidate pairs across the boundary, and their contact
points computed between a particle and the image of the other.

The cell (:mod:`solver.periodic_cell`) is ``origin + s a + t b`` with a = (l, 0), b = (tilt, h).
A pair's image is the one given by rounding its fractional separation,

    d = x_j - x_i,   n = rint(d_y / h),   m = rint((d_x - (d_y / h) tilt) / l),
    branch = d - m a - n b,

which is the only image within reach when the cell is more than twice the reach across
(:meth:`PeriodicCell.check_reach`): a vector shorter than half the cell's widths has fractional
coordinates below 1/2. It depends on the current positions alone, so the contacts found do not
depend on when the broad phase last ran, nor on how the centres were wrapped.

Broad phase: cell lists in fractional coordinates, nx x ny parallelogram cells, each at least
``2 r_max + alert`` across (the distance between opposite sides), their neighbours found by index
modulo nx and ny (the Lees–Edwards offset across the top is in the fractional coordinates
already); with fewer than three cells along a vector each distinct neighbour is visited once.
Pairs (i, j), i < j, sorted, as :func:`solver.broadphase.candidate_pairs` gives them.

Narrow phase: the pair's geometry is that of :mod:`solver.narrowphase` (the same kernels) between
particle i where it stands and a copy of j moved by the image's shift ``m a + n b`` (its world
vertices those of j plus the shift): the normal, gap and points are those of the same pair
moved inside the cell, up to the round-off of the shift. The lower id stays the lower body, so
the tie-breaking and the points' order are the walled detection's. Each point also gets the
image numbers (m, n) of body j seen from body i (0 for a wall contact).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from grainview.contract.errors import ParameterError
from grainview.contract.schema import KIND_DOUBLE, KIND_SIMPLE

from .broadphase import MAX_CELLS_PER_PARTICLE, check_walls
from .narrowphase import (Alerts, Candidates, ContactPoints, Outlines, PlacedShapes, Slots, Tally, WallLines,
                          _disk_wall, _pair_points, _polygon_block, _polygon_wall)
from .shapes import Shapes

__all__ = ["Lattice", "lattice", "candidate_pairs", "detect", "pair_image"]


class Lattice(NamedTuple):
    """The cell as the kernels read it (m): the origin, l, h and tilt; nx, ny the broad phase's
    grid (cells along a and along b)."""

    x0: float
    y0: float
    length: float
    height: float
    tilt: float
    nx: int
    ny: int


def lattice(cell, cut=None, n=1) -> Lattice:
    """The :class:`Lattice` of a :class:`solver.periodic_cell.PeriodicCell`, with a grid of
    cells at least ``cut`` (m) across and at most MAX_CELLS_PER_PARTICLE * ``n`` of them."""
    nx = ny = 1
    if cut is not None and cut > 0:
        across_a = cell.length * cell.height / math.hypot(cell.tilt, cell.height)
        nx = max(1, int(across_a // cut))
        ny = max(1, int(cell.height // cut))
        while nx * ny > MAX_CELLS_PER_PARTICLE * max(n, 1) and nx * ny > 1:
            nx, ny = max(1, nx * 2 // 3), max(1, ny * 2 // 3)
    return Lattice(float(cell.origin[0]), float(cell.origin[1]), float(cell.length), float(cell.height),
                   float(cell.tilt), int(nx), int(ny))


@njit(cache=True, inline="always")
def _image(dx, dy, cell):
    """The image numbers (m, n) of a separation (dx, dy) (module doc)."""
    t = dy / cell.height
    n = math.floor(t + 0.5)
    m = math.floor((dx - t * cell.tilt) / cell.length + 0.5)
    return m, n


@njit(cache=True)
def pair_image(dx, dy, cell):
    """(m, n, bx, by): the image numbers of the separation (dx, dy) and the branch d - m a - n b."""
    m, n = _image(dx, dy, cell)
    return m, n, dx - m * cell.length - n * cell.tilt, dy - n * cell.height


@njit(cache=True)
def _grid_cell(x, y, cell):
    t = (y - cell.y0) / cell.height
    s = (x - cell.x0 - t * cell.tilt) / cell.length
    cx = int(math.floor(s * cell.nx)) % cell.nx
    cy = int(math.floor(t * cell.ny)) % cell.ny
    return cy * cell.nx + cx


@njit(cache=True)
def _offsets(count):
    """The distinct neighbour offsets along a vector of ``count`` cells (periodic)."""
    if count == 1:
        return np.zeros(1, np.int64)
    if count == 2:
        return np.arange(0, 2)
    return np.arange(-1, 2)


@njit(cache=True)
def _partners(p, pos, radius, alert, cell, grid, out, offset):
    """Partners q > p of p within r_p + r_q + alert through their image (module doc), in the
    distinct neighbouring cells of p's; written to out[offset:] when out is long enough,
    counted in any case."""
    start, members, cell_of = grid
    nx, ny = cell.nx, cell.ny
    c = cell_of[p]
    cx = c % nx
    cy = c // nx
    count = 0
    for dy in _offsets(ny):
        y = (cy + dy) % ny
        for dx in _offsets(nx):
            x = (cx + dx) % nx
            k_cell = y * nx + x
            for k in range(start[k_cell], start[k_cell + 1]):
                q = members[k]
                if q <= p:
                    continue
                m, n, bx, by = pair_image(pos[q, 0] - pos[p, 0], pos[q, 1] - pos[p, 1], cell)
                reach = radius[p] + radius[q] + alert
                if bx * bx + by * by <= reach * reach:
                    if out.shape[0] > 0:
                        out[offset + count] = q
                    count += 1
    return count


@njit(cache=True)
def _candidates_kernel(pos, radius, alert, cell):
    n = pos.shape[0]
    cells = cell.nx * cell.ny
    cell_of = np.empty(n, np.int64)
    counts = np.zeros(cells + 1, np.int64)
    for p in range(n):
        c = _grid_cell(pos[p, 0], pos[p, 1], cell)
        cell_of[p] = c
        counts[c + 1] += 1
    start = np.cumsum(counts)
    fill = start[:-1].copy()
    members = np.empty(n, np.int64)
    for p in range(n):
        members[fill[cell_of[p]]] = p
        fill[cell_of[p]] += 1
    grid = (start, members, cell_of)
    empty = np.empty(0, np.int64)
    offsets = np.zeros(n + 1, np.int64)
    for p in range(n):
        offsets[p + 1] = offsets[p] + _partners(p, pos, radius, alert, cell, grid, empty, 0)
    total = offsets[n]
    partner = np.empty(max(total, 1), np.int64)
    for p in range(n):
        _partners(p, pos, radius, alert, cell, grid, partner, offsets[p])
        partner[offsets[p]:offsets[p + 1]] = np.sort(partner[offsets[p]:offsets[p + 1]])
    pi = np.empty(total, np.int32)
    pj = np.empty(total, np.int32)
    for p in range(n):
        for k in range(offsets[p], offsets[p + 1]):
            pi[k] = p
            pj[k] = partner[k]
    return pi, pj


def _particles(pos, radius):
    pos = np.ascontiguousarray(pos, dtype=np.float64)
    radius = np.ascontiguousarray(radius, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 2 or radius.shape != (pos.shape[0],):
        raise ParameterError(f"pos (N, 2) and radius (N,) expected, got {pos.shape} and {radius.shape}")
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(radius)) and np.all(radius > 0)):
        raise ParameterError("pos must be finite and radius finite and > 0 (m)")
    return pos, radius


def candidate_pairs(pos, radius, alert, cell):
    """All pairs (pi, pj), pi < pj, whose image (module doc) comes within r_i + r_j + alert:
    int32 arrays sorted by pi then pj. ``cell``: a :class:`solver.periodic_cell.PeriodicCell`,
    more than twice 2 r_max + alert across (checked)."""
    pos, radius = _particles(pos, radius)
    alert = float(alert)
    if not (np.isfinite(alert) and alert >= 0):
        raise ParameterError(f"alert={alert!r}: expected a finite alert distance >= 0 (m)")
    if pos.shape[0] < 2:
        return np.empty(0, np.int32), np.empty(0, np.int32)
    cut = 2.0 * float(radius.max()) + alert
    cell.check_reach(cut)
    return _candidates_kernel(pos, radius, alert, lattice(cell, cut, pos.shape[0]))


# ----------------------------------------------------------------------------------------
# narrow phase
# ----------------------------------------------------------------------------------------

@njit(cache=True)
def _with_images(placed, candidates, cell, ghost):
    """The :class:`Outlines` of the bodies and, after them, a copy of body max(i, j) of every
    candidate pair that meets the other through an image, moved by the image's shift;
    ``ghost[c]`` (M,) is set to the copy's index (or -1) and ``image`` (M, 2) returned holds
    the pair's image numbers (body max seen from body min)."""
    n = placed.pos.shape[0]
    pos = placed.pos
    pi, pj = candidates.pi, candidates.pj
    m_pairs = pi.shape[0]
    image = np.zeros((m_pairs, 2), np.int64)
    extra = 0
    for c in range(m_pairs):
        a = min(pi[c], pj[c])
        b = max(pi[c], pj[c])
        m, k = _image(pos[b, 0] - pos[a, 0], pos[b, 1] - pos[a, 1], cell)
        image[c, 0] = -m
        image[c, 1] = -k
        if m != 0 or k != 0:
            ghost[c] = n + extra
            extra += 1
        else:
            ghost[c] = -1
    nvert = placed.n_vertices
    maxn = 1
    for p in range(n):
        maxn = max(maxn, nvert[p])
    total = n + extra
    verts = np.zeros((total, maxn, 2))
    norms = np.zeros((total, maxn, 2))
    _polygon_block(0, n, placed, verts, norms)
    ext_pos = np.empty((total, 2))
    ext_radius = np.empty(total)
    ext_nvert = np.empty(total, nvert.dtype)
    ext_pos[:n] = pos
    ext_radius[:n] = placed.radius
    ext_nvert[:n] = nvert
    for c in range(m_pairs):
        g = ghost[c]
        if g < 0:
            continue
        b = max(pi[c], pj[c])
        sx = image[c, 0] * cell.length + image[c, 1] * cell.tilt
        sy = image[c, 1] * cell.height
        ext_pos[g, 0] = pos[b, 0] + sx
        ext_pos[g, 1] = pos[b, 1] + sy
        ext_radius[g] = placed.radius[b]
        ext_nvert[g] = nvert[b]
        for v in range(nvert[b]):
            verts[g, v, 0] = verts[b, v, 0] + sx
            verts[g, v, 1] = verts[b, v, 1] + sy
            norms[g, v, 0] = norms[b, v, 0]
            norms[g, v, 1] = norms[b, v, 1]
    return Outlines(ext_pos, ext_radius, ext_nvert, verts, norms), image


@njit(cache=True)
def _detect_kernel(placed, walls, candidates, alerts, cell):
    """The walled detection's two passes (:func:`solver.narrowphase._detect_kernel`, one
    thread) on the bodies and the images of :func:`_with_images`. Returns the
    :class:`ContactPoints` and the (P, 2) image numbers of body j seen from body i."""
    n_particles = placed.pos.shape[0]
    pi, pj, wp, ww = candidates
    m_pairs = pi.shape[0]
    m = m_pairs + wp.shape[0]
    ghost = np.empty(m_pairs, np.int64)
    bodies, image = _with_images(placed, candidates, cell, ghost)
    slots = Slots(np.empty((m, 2)), np.empty((m, 2, 2)), np.empty((m, 2)))
    tally = Tally(np.zeros(m, np.int64), np.empty(m, np.int8), np.zeros(m + 1, np.int64), np.zeros(m + 1, np.int64))
    double_alert = alerts.double_alert
    for c in range(m):
        if c < m_pairs:
            i = pi[c]
            j = pj[c]
            a = min(i, j)
            b = max(i, j) if ghost[c] < 0 else ghost[c]
            cnt = _pair_points(a, b, bodies, double_alert, c, slots)
            if i > j:
                slots.normal[c, 0] = -slots.normal[c, 0]
                slots.normal[c, 1] = -slots.normal[c, 1]
        else:
            p = wp[c - m_pairs]
            w = ww[c - m_pairs]
            if placed.n_vertices[p] == 0:
                cnt = _disk_wall(p, w, bodies, walls, c, slots)
            else:
                cnt = _polygon_wall(p, w, bodies, walls, double_alert, c, slots)
        tally.kind[c] = KIND_DOUBLE if cnt == 2 else KIND_SIMPLE
        gmin = slots.gap[c, 0]
        if cnt == 2 and slots.gap[c, 1] < gmin:
            gmin = slots.gap[c, 1]
        tally.count[c] = cnt if gmin <= alerts.alert else 0
    for c in range(m):
        tally.offsets[c + 1] = tally.offsets[c] + tally.count[c]
        tally.pair_offsets[c + 1] = tally.pair_offsets[c] + (1 if tally.count[c] > 0 else 0)
    total = tally.offsets[m]
    out = ContactPoints(np.empty(total, np.int32), np.empty(total, np.int32), np.empty((total, 2)),
                        np.empty((total, 2)), np.empty(total), np.empty(total, np.int8), np.empty(total, np.int32),
                        tally.pair_offsets[m])
    out_image = np.zeros((total, 2), np.int64)
    for c in range(m):
        for k in range(tally.count[c]):
            q = tally.offsets[c] + k
            if c < m_pairs:
                out.body_i[q] = pi[c]
                out.body_j[q] = pj[c]
                sign = 1 if pi[c] < pj[c] else -1
                out_image[q, 0] = sign * image[c, 0]
                out_image[q, 1] = sign * image[c, 1]
            else:
                out.body_i[q] = wp[c - m_pairs]
                out.body_j[q] = n_particles + ww[c - m_pairs]
            out.normal[q, 0] = slots.normal[c, 0]
            out.normal[q, 1] = slots.normal[c, 1]
            out.point[q, 0] = slots.point[c, k, 0]
            out.point[q, 1] = slots.point[c, k, 1]
            out.gap[q] = slots.gap[c, k]
            out.kind[q] = tally.kind[c]
            out.pair[q] = tally.pair_offsets[c]
    return out, out_image


def detect(pos, angle, shapes, alert, pi, pj, cell, wall_point=None, wall_normal=None, wp=None, ww=None,
           double_alert=None):
    """Contact points of the candidate pairs (pi, pj) in the periodic ``cell`` (and of the
    wall candidates (wp, ww), if any), as :func:`solver.narrowphase.detect` gives them (the
    points of a pair across the boundary lie beside body i; body ids as passed), and the
    (P, 2) int64 image numbers (m, n) of body j seen from body i at each point: the branch is
    x_j + m a + n b - x_i."""
    if not isinstance(shapes, Shapes):
        raise ParameterError("shapes must be a solver.shapes.Shapes")
    n = len(shapes)
    pos = np.ascontiguousarray(pos, dtype=np.float64)
    angle = np.ascontiguousarray(np.broadcast_to(np.asarray(angle, dtype=np.float64), (n,)))
    if pos.shape != (n, 2) or not (np.all(np.isfinite(pos)) and np.all(np.isfinite(angle))):
        raise ParameterError(f"pos must be finite of shape ({n}, 2) and angle finite")
    alert = float(alert)
    double_alert = alert if double_alert is None else float(double_alert)
    if not (np.isfinite(alert) and alert >= 0 and np.isfinite(double_alert) and double_alert >= 0):
        raise ParameterError(f"alert={alert!r}, double_alert={double_alert!r}: expected finite distances >= 0 (m)")
    pi = np.ascontiguousarray(pi, dtype=np.int32).reshape(-1)
    pj = np.ascontiguousarray(pj, dtype=np.int32).reshape(-1)
    if pi.shape != pj.shape or (pi.size and (min(pi.min(), pj.min()) < 0 or max(pi.max(), pj.max()) >= n
                                             or np.any(pi == pj))):
        raise ParameterError("pi, pj: expected pairs of distinct particle indices of equal length")
    wall_point, wall_normal = check_walls(np.empty((0, 2)) if wall_point is None else wall_point,
                                          np.empty((0, 2)) if wall_normal is None else wall_normal)
    wp = np.empty(0, np.int32) if wp is None else np.ascontiguousarray(wp, dtype=np.int32).reshape(-1)
    ww = np.empty(0, np.int32) if ww is None else np.ascontiguousarray(ww, dtype=np.int32).reshape(-1)
    placed = PlacedShapes(pos, angle, shapes.radius, shapes.n_vertices, shapes.first_vertex, shapes.vertex_radius,
                          shapes.vertex_angle, shapes.normal_angle)
    return _detect_kernel(placed, WallLines(wall_point, wall_normal), Candidates(pi, pj, wp, ww),
                          Alerts(alert, double_alert), lattice(cell))
