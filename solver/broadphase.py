"""Broad phase of contact detection: candidate pairs from cell lists, candidate wall contacts.

Two particles i, j are a candidate pair when their circumscribed disks come within the alert
distance of each other,

    |x_i - x_j| <= r_i + r_j + alert,

and a particle is a wall candidate when its centre is within r_i + alert of the wall line on
the sample's side (signed distance (x_i - p_w) . n_w <= r_i + alert, n_w the wall's unit normal
pointing into the sample; a particle that went through a wall is a candidate too).

Cell lists (Allen & Tildesley, "Computer simulation of liquids", Sec. 5.3): the bounding box of
the centres is cut into square cells of side at least 2 r_max + alert, so that every candidate
partner of a particle lies in its own cell or in one of the 8 neighbouring cells; the pairs are
found in O(N) for a packing of bounded polydispersity. The kernel works in two passes (count the
partners of each particle, then fill at offsets from a prefix sum) so that each particle writes
only its own slice of the output.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from grainview.contract.errors import ParameterError

__all__ = ["candidate_pairs", "wall_candidates"]

MAX_CELLS_PER_PARTICLE = 4
"""The grid never has more than this many cells per particle (cells are enlarged if needed),
so memory stays O(N) even for a sparse or strongly spread-out set of particles."""


class CellList(NamedTuple):
    """The particles sorted by the square cells of a grid over their centres
    (:func:`_cell_lists`); cell (cx, cy) has the index c = cy * nx + cx.

    cell_of : int64 (N,) — the cell of each particle.
    start : int64 (nx * ny + 1,) — the particles of cell c are members[start[c]:start[c + 1]].
    members : int64 (N,) — the particles by cell, in increasing order within a cell.
    nx, ny : int — the number of cells along x and along y.
    """

    cell_of: np.ndarray
    start: np.ndarray
    members: np.ndarray
    nx: int
    ny: int


@njit(cache=True)
def _cell_lists(pos, cell_size, nx, ny, xmin, ymin):
    """Cell index of each particle and the particles sorted by cell (counting sort): the
    :class:`CellList` of the grid of nx by ny cells of side ``cell_size`` (m) from the corner
    (xmin, ymin) (m); a centre outside the grid counts in the nearest cell."""
    n = pos.shape[0]
    cell_of = np.empty(n, np.int64)
    counts = np.zeros(nx * ny + 1, np.int64)
    for p in range(n):
        cx = int((pos[p, 0] - xmin) / cell_size)
        cy = int((pos[p, 1] - ymin) / cell_size)
        cx = min(max(cx, 0), nx - 1)
        cy = min(max(cy, 0), ny - 1)
        c = cy * nx + cx
        cell_of[p] = c
        counts[c + 1] += 1
    start = np.cumsum(counts)
    fill = start[:-1].copy()
    members = np.empty(n, np.int64)
    for p in range(n):
        c = cell_of[p]
        members[fill[c]] = p
        fill[c] += 1
    return CellList(cell_of, start, members, nx, ny)


@njit(cache=True)
def _partners(p, pos, radius, alert, cells, out, offset):
    """Partners j > p of particle p within r_p + r_j + alert (m), found in the 3 x 3 cells of
    ``cells`` (:class:`CellList`) around p's; written to ``out[offset:]`` when ``out`` is
    large enough, counted in any case. Returns the count."""
    start = cells.start
    members = cells.members
    nx = cells.nx
    ny = cells.ny
    c = cells.cell_of[p]
    cx = c % nx
    cy = c // nx
    count = 0
    for dy in range(-1, 2):
        y = cy + dy
        if y < 0 or y >= ny:
            continue
        for dx in range(-1, 2):
            x = cx + dx
            if x < 0 or x >= nx:
                continue
            cell = y * nx + x
            for k in range(start[cell], start[cell + 1]):
                q = members[k]
                if q <= p:
                    continue
                ddx = pos[q, 0] - pos[p, 0]
                ddy = pos[q, 1] - pos[p, 1]
                reach = radius[p] + radius[q] + alert
                if ddx * ddx + ddy * ddy <= reach * reach:
                    if out.shape[0] > 0:
                        out[offset + count] = q
                    count += 1
    return count


@njit(cache=True)
def _candidate_pairs_kernel(pos, radius, alert, cell_size, nx, ny, xmin, ymin):
    n = pos.shape[0]
    cells = _cell_lists(pos, cell_size, nx, ny, xmin, ymin)
    empty = np.empty(0, np.int64)
    counts = np.empty(n, np.int64)
    for p in range(n):  # pass 1: count
        counts[p] = _partners(p, pos, radius, alert, cells, empty, 0)
    offsets = np.zeros(n + 1, np.int64)
    for p in range(n):
        offsets[p + 1] = offsets[p] + counts[p]
    total = offsets[n]
    partner = np.empty(max(total, 1), np.int64)
    for p in range(n):  # pass 2: fill, each particle its own slice, sorted
        _partners(p, pos, radius, alert, cells, partner, offsets[p])
        partner[offsets[p]:offsets[p + 1]] = np.sort(partner[offsets[p]:offsets[p + 1]])
    pi = np.empty(total, np.int32)
    pj = np.empty(total, np.int32)
    for p in range(n):
        for k in range(offsets[p], offsets[p + 1]):
            pi[k] = p
            pj[k] = partner[k]
    return pi, pj


def _check_alert(alert):
    alert = float(alert)
    if not np.isfinite(alert) or alert < 0:
        raise ParameterError(f"alert={alert!r}: expected a finite alert distance >= 0 (m)")
    return alert


def _check_particles(pos, radius):
    pos = np.ascontiguousarray(pos, dtype=np.float64)
    radius = np.ascontiguousarray(radius, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 2:
        raise ParameterError(f"pos must have shape (N, 2) (m), got {pos.shape}")
    if radius.shape != (pos.shape[0],):
        raise ParameterError(f"radius must have shape ({pos.shape[0]},) like pos, got {radius.shape}")
    if not np.all(np.isfinite(pos)):
        raise ParameterError("pos holds non-finite coordinates")
    if not np.all(np.isfinite(radius)) or np.any(radius <= 0):
        raise ParameterError("radius must hold finite radii > 0 (m)")
    return pos, radius


def candidate_pairs(pos, radius, alert):
    """All particle pairs (pi, pj), pi < pj, with |x_i - x_j| <= r_i + r_j + alert.

    Parameters
    ----------
    pos : (N, 2) float array, m — particle centres.
    radius : (N,) float array, m — circumscribed radii.
    alert : float, m — alert distance (>= 0).

    Returns
    -------
    pi, pj : int32 arrays of equal length, sorted by pi then pj.
    """
    pos, radius = _check_particles(pos, radius)
    alert = _check_alert(alert)
    n = pos.shape[0]
    if n < 2:
        return np.empty(0, np.int32), np.empty(0, np.int32)
    lo = pos.min(axis=0)
    hi = pos.max(axis=0)
    cell = 2.0 * radius.max() + alert
    extent = np.maximum(hi - lo, 0.0)
    # enlarge the cells if the grid would hold too many of them
    max_cells = MAX_CELLS_PER_PARTICLE * n
    while (np.floor(extent[0] / cell) + 1) * (np.floor(extent[1] / cell) + 1) > max_cells:
        cell *= 1.5
    nx = int(np.floor(extent[0] / cell)) + 1
    ny = int(np.floor(extent[1] / cell)) + 1
    return _candidate_pairs_kernel(pos, radius, alert, cell, nx, ny, float(lo[0]), float(lo[1]))


@njit(cache=True)
def _wall_candidates_kernel(pos, radius, wall_point, wall_normal, alert):
    n = pos.shape[0]
    w = wall_point.shape[0]
    count = 0
    for p in range(n):
        for k in range(w):
            d = (pos[p, 0] - wall_point[k, 0]) * wall_normal[k, 0] + (pos[p, 1] - wall_point[k, 1]) * wall_normal[k, 1]
            if d <= radius[p] + alert:
                count += 1
    particle = np.empty(count, np.int32)
    wall = np.empty(count, np.int32)
    m = 0
    for p in range(n):
        for k in range(w):
            d = (pos[p, 0] - wall_point[k, 0]) * wall_normal[k, 0] + (pos[p, 1] - wall_point[k, 1]) * wall_normal[k, 1]
            if d <= radius[p] + alert:
                particle[m] = p
                wall[m] = k
                m += 1
    return particle, wall


def check_walls(wall_point, wall_normal):
    """Validate wall arrays: (W, 2) points (m) and (W, 2) unit normals pointing into the sample."""
    wall_point = np.ascontiguousarray(wall_point, dtype=np.float64).reshape(-1, 2)
    wall_normal = np.ascontiguousarray(wall_normal, dtype=np.float64).reshape(-1, 2)
    if wall_point.shape != wall_normal.shape:
        raise ParameterError(f"wall_point {wall_point.shape} and wall_normal {wall_normal.shape} "
                             "must both have shape (W, 2)")
    if not (np.all(np.isfinite(wall_point)) and np.all(np.isfinite(wall_normal))):
        raise ParameterError("wall_point and wall_normal must be finite")
    if wall_normal.size and np.any(np.abs(np.hypot(wall_normal[:, 0], wall_normal[:, 1]) - 1.0) > 1e-9):
        raise ParameterError("wall_normal must hold unit vectors (pointing into the sample)")
    return wall_point, wall_normal


def wall_candidates(pos, radius, wall_point, wall_normal, alert):
    """Particle-wall candidates (particle, wall): the signed distance of the centre to the wall
    line, (x_i - p_w) . n_w, is <= r_i + alert (n_w unit, into the sample).

    Returns int32 arrays sorted by particle then wall.
    """
    pos, radius = _check_particles(pos, radius)
    wall_point, wall_normal = check_walls(wall_point, wall_normal)
    alert = _check_alert(alert)
    return _wall_candidates_kernel(pos, radius, wall_point, wall_normal, alert)
