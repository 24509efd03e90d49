"""Numba kernels of the coarse-grained fields: a truncated Gaussian spread from points (the
particles' centres) and along segments (the contacts' branch vectors) onto a grid.

Structure of arrays: coordinates and weights come as separate contiguous float64 arrays, one
row per snapshot, in the records of :mod:`grainview.analysis._kernels.records` (the sources, the
grid); the caller (:mod:`grainview.analysis.arrays.coarse_graining`) validates them. Every kernel
adds into ``out`` (B, ny, nx, K), ``K`` the number of quantities carried by each source.

The kernel is the Gaussian of standard deviation w cut at radius c and renormalised,

    phi(r) = exp(-|r|^2 / (2 w^2)) / (2 pi w^2 (1 - exp(-c^2 / (2 w^2))))    for |r| < c,

so that its integral over the plane is exactly 1 (m^-2). Along a segment from s to s + l the
kernel is integrated exactly (the contact stress of Weinhart, Thornton, Luding & Bokhove,
Granular Matter 14, 289 (2012)), with
d = r - s, s0 = d.l/|l|^2, the distance h^2 = |d|^2 - (d.l)^2/|l|^2 of r from the line, and
[a, b] = [0, 1] cut to the part of the line within c of r:

    psi(r) = int_0^1 phi(r - s - u l) du
           = exp(-h^2/(2 w^2)) w sqrt(pi/2)/|l| [erf((b - s0)|l|/(sqrt 2 w)) - erf((a - s0)|l|/(sqrt 2 w))] / norm.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True, inline="always")
def _norm(width, cutoff):
    """2 pi w^2 (1 - exp(-c^2/(2 w^2))): the truncated Gaussian's integral over the plane."""
    return 2.0 * math.pi * width * width * (1.0 - math.exp(-0.5 * (cutoff / width) ** 2))


@njit(cache=True, nogil=True)
def spread_points(points, grid, out):
    """out[b, iy, ix, k] += weights[b, p, k] phi((x[ix], y[iy]) - (px[b, p], py[b, p])) over the
    points with ``active[b, p]``.

    ``points`` (:class:`~grainview.analysis._kernels.records.Points`): px, py (B, P) m, active
    (B, P) bool, weights (B, P, K); ``grid`` (:class:`~grainview.analysis._kernels.records.Grid`):
    x (nx,), y (ny,) ascending, m, width w and cutoff radius c in m; out (B, ny, nx, K), weights'
    units per m^2.
    """
    px, py, active, weights = points.x, points.y, points.active, points.weights
    x, y, width, cutoff = grid.x, grid.y, grid.width, grid.cutoff
    n_batch, n_points = px.shape
    n_k = weights.shape[2]
    norm = _norm(width, cutoff)
    c2 = cutoff * cutoff
    inv2w2 = 0.5 / (width * width)
    for b in range(n_batch):
        for p in range(n_points):
            if not active[b, p]:
                continue
            cx = px[b, p]
            cy = py[b, p]
            x0 = np.searchsorted(x, cx - cutoff)
            x1 = np.searchsorted(x, cx + cutoff, side="right")
            y0 = np.searchsorted(y, cy - cutoff)
            y1 = np.searchsorted(y, cy + cutoff, side="right")
            for iy in range(y0, y1):
                dy2 = (y[iy] - cy) ** 2
                if dy2 >= c2:
                    continue
                for ix in range(x0, x1):
                    r2 = (x[ix] - cx) ** 2 + dy2
                    if r2 >= c2:
                        continue
                    phi = math.exp(-r2 * inv2w2) / norm
                    for k in range(n_k):
                        out[b, iy, ix, k] += phi * weights[b, p, k]


@njit(cache=True, nogil=True)
def spread_segments(segments, grid, out):
    """out[b, iy, ix, k] += weights[b, c, k] psi_c(x[ix], y[iy]) over the segments with
    ``active[b, c]``, psi_c the kernel integrated along segment c from (sx, sy) to
    (sx + lx, sy + ly) (the module's formula; a segment shorter than 1e-12 w is a point).

    ``segments`` (:class:`~grainview.analysis._kernels.records.Segments`): sx, sy, lx, ly (B, C)
    m, active (B, C) bool, weights (B, C, K); ``grid``
    (:class:`~grainview.analysis._kernels.records.Grid`): x (nx,), y (ny,) ascending, m, width w
    and cutoff radius c in m; out (B, ny, nx, K).
    """
    sx, sy, lx, ly = segments.start_x, segments.start_y, segments.length_x, segments.length_y
    active, weights = segments.active, segments.weights
    x, y, width, cutoff = grid.x, grid.y, grid.width, grid.cutoff
    n_batch, n_seg = sx.shape
    n_k = weights.shape[2]
    norm = _norm(width, cutoff)
    c2 = cutoff * cutoff
    inv2w2 = 0.5 / (width * width)
    root2w = math.sqrt(2.0) * width
    for b in range(n_batch):
        for c in range(n_seg):
            if not active[b, c]:
                continue
            ax = sx[b, c]
            ay = sy[b, c]
            ux = lx[b, c]
            uy = ly[b, c]
            length2 = ux * ux + uy * uy
            length = math.sqrt(length2)
            point = length < 1e-12 * width
            x0 = np.searchsorted(x, min(ax, ax + ux) - cutoff)
            x1 = np.searchsorted(x, max(ax, ax + ux) + cutoff, side="right")
            y0 = np.searchsorted(y, min(ay, ay + uy) - cutoff)
            y1 = np.searchsorted(y, max(ay, ay + uy) + cutoff, side="right")
            for iy in range(y0, y1):
                dy = y[iy] - ay
                for ix in range(x0, x1):
                    dx = x[ix] - ax
                    d2 = dx * dx + dy * dy
                    if point:
                        if d2 >= c2:
                            continue
                        psi = math.exp(-d2 * inv2w2) / norm
                    else:
                        along = dx * ux + dy * uy
                        s0 = along / length2
                        h2 = max(d2 - along * s0, 0.0)
                        if h2 >= c2:
                            continue
                        half = math.sqrt(c2 - h2) / length
                        lo = max(0.0, s0 - half)
                        hi = min(1.0, s0 + half)
                        if hi <= lo:
                            continue
                        scale = length / root2w
                        psi = (math.exp(-h2 * inv2w2) * width * math.sqrt(0.5 * math.pi) / length
                               * (math.erf((hi - s0) * scale) - math.erf((lo - s0) * scale)) / norm)
                    for k in range(n_k):
                        out[b, iy, ix, k] += psi * weights[b, c, k]
