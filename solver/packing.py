"""Geometric deposition: a dense initial packing built by simple geometric rules, no dynamics.

The paper's samples were "first constructed following simple geometrical rules" (Taboada,
Chang, Radjai, Bouchette, PRL 2005) and then compacted isotropically. :func:`deposit` places
the particles one by one, in a random order of sizes, in the box [0, width] x [0, inf) with
walls at x = 0, x = width and y = 0; each particle goes to the LOWEST stable position where it
rests on two supports (two placed particles, a particle and a side wall, or the bottom) without
overlapping anything (the rule of Visscher & Bolsterli, Nature 1972, made deterministic and
global: the lowest of all the available "pockets" wins).

Pockets: a pocket for a particle of radius r is the upper intersection point of the circles of
radii r_p + r and r_q + r around two supports p and q (or the line x = r, x = width - r or
y = r for a wall); it is stable when its x lies between the supports' x. The pockets of every
size class are kept in a heap ordered by height; a placement adds the pockets it forms with its
neighbours, and a pocket found overlapping a later particle is dropped when it comes to the top
of its heap (particles never move, so it can never become free again). Neighbours come from a
cell list, so a placement costs O(1) and the whole deposition O(N log N).

Polygons: the CIRCUMSCRIBED disks are deposited and each polygon gets a random orientation in
[0, 2 pi / n). This guarantees that no two polygons (nor a polygon and a wall) overlap whatever
their orientation, at the price of a looser packing (the pentagons fill about 0.76 of their
circumscribed disks, so the pentagon solid fraction starts near 0.6 instead of 0.8): the
isotropic compaction that follows in the paper's protocol densifies it.

Sizes: ``fractions`` are NUMBER fractions (the paper: "50% of diameter 2.5 cm, 34% of 3.75 cm,
16% of 5 cm"), ``diameters`` circumscribed diameters (m); the counts are rounded so that they
sum to n, and shuffled with ``seed``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from grainview.contract.errors import ParameterError

__all__ = ["deposit", "box_width_for", "size_classes", "Packing", "DEPOSIT_SOLID_FRACTION",
           "PAPER_DIAMETERS", "PAPER_FRACTIONS"]

PAPER_DIAMETERS = (0.025, 0.0375, 0.05)
"""Circumscribed diameters of the paper's three size classes, m."""
PAPER_FRACTIONS = (0.5, 0.34, 0.16)
"""Number fractions of the paper's three size classes."""

DEPOSIT_SOLID_FRACTION = 0.82
"""Solid fraction of the deposited (circumscribed) disks in the bulk, measured on this
algorithm with the paper's size distribution (about 0.81-0.83 for a few thousand disks; lower
for small boxes where the walls weigh more). Used by :func:`box_width_for`."""

CLEARANCE = 1e-12
"""Each placed disk keeps this clearance (fraction of the largest radius) from its supports,
so that round-off can never produce an overlap."""


class Packing(NamedTuple):
    """Result of :func:`deposit`: unpacks as ``pos, angle, radius, nvert, height``.

    pos (N, 2) m, centres; angle (N,) rad; radius (N,) m, circumscribed radii; nvert (N,) int32;
    height m, top of the highest circumscribed disk (the top wall may be placed there).
    """

    pos: np.ndarray
    angle: np.ndarray
    radius: np.ndarray
    nvert: np.ndarray
    height: float


class CellGrid(NamedTuple):
    """The placed disks chained by the square cells of the box, a linked cell list (Allen &
    Tildesley, "Computer simulation of liquids", Sec. 5.3); cell (cx, cy), of corner
    (cx size, cy size), has the index cy * ncols + cx.

    head : int64 (ncols * nrows,) — the disk placed last in each cell, -1 for an empty cell.
    link : int64 (N,) — the disk placed before it in the same cell, -1 at the end of a chain.
    size : float — the side of a cell, m (at least the largest diameter).
    ncols, nrows : int — the number of cells along x and along y.
    """

    head: np.ndarray
    link: np.ndarray
    size: float
    ncols: int
    nrows: int


# -------------------------------------------------------------------- heap of pockets

@njit(cache=True)
def _less(hy, hx, s, a, b):
    return hy[s, a] < hy[s, b] or (hy[s, a] == hy[s, b] and hx[s, a] < hx[s, b])


@njit(cache=True)
def _swap(hy, hx, s, a, b):
    hy[s, a], hy[s, b] = hy[s, b], hy[s, a]
    hx[s, a], hx[s, b] = hx[s, b], hx[s, a]


@njit(cache=True)
def _push(hy, hx, hn, s, y, x):
    """Push pocket (y, x) on heap s; returns the (possibly reallocated) heap arrays."""
    if hn[s] == hy.shape[1]:
        cap = 2 * hy.shape[1]
        ny = np.empty((hy.shape[0], cap))
        nx = np.empty((hy.shape[0], cap))
        ny[:, :hy.shape[1]] = hy
        nx[:, :hx.shape[1]] = hx
        hy = ny
        hx = nx
    k = hn[s]
    hy[s, k] = y
    hx[s, k] = x
    hn[s] += 1
    while k > 0:
        parent = (k - 1) // 2
        if _less(hy, hx, s, k, parent):
            _swap(hy, hx, s, k, parent)
            k = parent
        else:
            break
    return hy, hx


@njit(cache=True)
def _pop(hy, hx, hn, s):
    """Remove and return the lowest pocket (y, x) of heap s (heap must not be empty)."""
    y = hy[s, 0]
    x = hx[s, 0]
    hn[s] -= 1
    last = hn[s]
    hy[s, 0] = hy[s, last]
    hx[s, 0] = hx[s, last]
    k = 0
    while True:
        left = 2 * k + 1
        if left >= last:
            break
        child = left
        if left + 1 < last and _less(hy, hx, s, left + 1, left):
            child = left + 1
        if _less(hy, hx, s, child, k):
            _swap(hy, hx, s, child, k)
            k = child
        else:
            break
    return y, x


# -------------------------------------------------------------------- deposition kernel

@njit(cache=True)
def _cell(x, y, grid):
    """The cell (cx, cy) of ``grid`` (:class:`CellGrid`) holding the point (x, y), m; a point
    outside the grid counts in the nearest cell."""
    cx = min(max(int(x / grid.size), 0), grid.ncols - 1)
    cy = min(max(int(y / grid.size), 0), grid.nrows - 1)
    return cx, cy


@njit(cache=True)
def _free(x, y, r, pos, radius, grid):
    """True if a disk (x, y, r) (m) overlaps none of the placed disks (centres ``pos``, radii
    ``radius``, m), its neighbours from ``grid`` (:class:`CellGrid`)."""
    head = grid.head
    nxt = grid.link
    ncols = grid.ncols
    nrows = grid.nrows
    cx, cy = _cell(x, y, grid)
    for j in range(max(cy - 1, 0), min(cy + 2, nrows)):
        for i in range(max(cx - 1, 0), min(cx + 2, ncols)):
            q = head[j * ncols + i]
            while q >= 0:
                dx = x - pos[q, 0]
                dy = y - pos[q, 1]
                reach = r + radius[q]
                if dx * dx + dy * dy < reach * reach:
                    return False
                q = nxt[q]
    return True


@njit(cache=True)
def _deposit_kernel(class_of, class_radius, width, cell, ncols, nrows, clearance):
    n = class_of.shape[0]
    n_class = class_radius.shape[0]
    pos = np.empty((n, 2))
    radius = np.empty(n)
    grid = CellGrid(np.full(ncols * nrows, -1, np.int64), np.full(n, -1, np.int64), cell, ncols, nrows)
    head = grid.head
    nxt = grid.link
    hy = np.empty((n_class, 64 + 16 * n))
    hx = np.empty((n_class, 64 + 16 * n))
    hn = np.zeros(n_class, np.int64)
    for s in range(n_class):  # the two bottom corners
        r = class_radius[s]
        lo_x = min(r + clearance, 0.5 * width)
        hi_x = max(width - r - clearance, 0.5 * width)
        if 2.0 * r <= width:
            hy, hx = _push(hy, hx, hn, s, r + clearance, lo_x)
            hy, hx = _push(hy, hx, hn, s, r + clearance, hi_x)
    for p in range(n):
        s = class_of[p]
        r = class_radius[s]
        found = False
        x = 0.0
        y = 0.0
        while hn[s] > 0:
            y, x = _pop(hy, hx, hn, s)
            if _free(x, y, r, pos, radius, grid):
                found = True
                break
        if not found:
            return pos, radius, p  # no room: the caller raises
        pos[p, 0] = x
        pos[p, 1] = y
        radius[p] = r
        cx, cy = _cell(x, y, grid)
        c = cy * ncols + cx
        nxt[p] = head[c]
        head[c] = p
        # pockets formed by p with the bottom, the side walls and its placed neighbours
        for s2 in range(n_class):
            r2 = class_radius[s2]
            a = r + r2 + clearance
            if 2.0 * r2 > width:
                continue
            # wall clearance, reduced in a box exactly one particle wide
            lo_x = min(r2 + clearance, 0.5 * width)
            hi_x = max(width - r2 - clearance, 0.5 * width)
            # bottom: y = r2 + clearance, touching p on either side
            yb = r2 + clearance
            dy = yb - y
            if abs(dy) <= a:
                dx = math.sqrt(a * a - dy * dy)
                for xb in (x - dx, x + dx):
                    if lo_x <= xb <= hi_x:
                        hy, hx = _push(hy, hx, hn, s2, yb, xb)
            # side walls: x = lo_x (stable if p is right of it) and x = hi_x
            for xw in (lo_x, hi_x):
                ddx = xw - x
                stable = (xw <= x) if xw == lo_x else (xw >= x)
                if stable and abs(ddx) <= a:
                    yw = y + math.sqrt(a * a - ddx * ddx)
                    if yw >= yb:
                        hy, hx = _push(hy, hx, hn, s2, yw, xw)
            # particle pairs (p, q): upper intersection of the circles r + r2, r_q + r2
            for j in range(max(cy - 2, 0), min(cy + 3, nrows)):
                for i in range(max(cx - 2, 0), min(cx + 3, ncols)):
                    q = head[j * ncols + i]
                    while q >= 0:
                        if q != p:
                            b = radius[q] + r2 + clearance
                            ux = pos[q, 0] - x
                            uy = pos[q, 1] - y
                            d = math.sqrt(ux * ux + uy * uy)
                            if d > 0.0 and d <= a + b and d >= abs(a - b):
                                l = (a * a - b * b + d * d) / (2.0 * d)
                                h = math.sqrt(max(a * a - l * l, 0.0))
                                mx = x + l * ux / d
                                my = y + l * uy / d
                                # the two intersections are m +- h (-uy, ux)/d; take the upper
                                px = -uy / d
                                py = ux / d
                                if py < 0.0 or (py == 0.0 and px < 0.0):
                                    px = -px
                                    py = -py
                                xq = mx + h * px
                                yq = my + h * py
                                if (min(x, pos[q, 0]) <= xq <= max(x, pos[q, 0])
                                        and lo_x <= xq <= hi_x and yq >= yb):
                                    hy, hx = _push(hy, hx, hn, s2, yq, xq)
                        q = nxt[q]
    return pos, radius, n


# -------------------------------------------------------------------- user API

def size_classes(n, diameters=PAPER_DIAMETERS, fractions=PAPER_FRACTIONS):
    """Number of particles of each size class: n * fractions rounded (largest remainders) so
    that the counts sum to n. Raises ParameterError on inconsistent inputs."""
    if not isinstance(n, (int, np.integer)) or n < 1:
        raise ParameterError(f"n={n!r}: expected a number of particles >= 1")
    diameters = np.asarray(diameters, dtype=np.float64).reshape(-1)
    fractions = np.asarray(fractions, dtype=np.float64).reshape(-1)
    if diameters.size == 0 or diameters.shape != fractions.shape:
        raise ParameterError(f"diameters ({diameters.size}) and fractions ({fractions.size}) must be "
                             "non-empty and of the same length")
    if not np.all(np.isfinite(diameters)) or np.any(diameters <= 0):
        raise ParameterError("diameters must be finite circumscribed diameters > 0 (m)")
    if not np.all(np.isfinite(fractions)) or np.any(fractions < 0) or abs(fractions.sum() - 1) > 1e-9:
        raise ParameterError(f"fractions must be >= 0 and sum to 1, got {fractions.tolist()}")
    exact = n * fractions
    counts = np.floor(exact).astype(np.int64)
    rest = int(n - counts.sum())
    order = np.argsort(-(exact - counts), kind="stable")
    counts[order[:rest]] += 1
    return counts


def _check_nvert(nvert):
    if not isinstance(nvert, (int, np.integer)) or (nvert != 0 and nvert < 3):
        raise ParameterError(f"nvert={nvert!r}: expected 0 (disks) or an integer >= 3 (regular polygons)")
    return int(nvert)


def box_width_for(n, diameters=PAPER_DIAMETERS, fractions=PAPER_FRACTIONS, aspect_ratio=2.0,
                  solid_fraction=DEPOSIT_SOLID_FRACTION):
    """Box width l (m) for which n deposited particles fill a height h ~ aspect_ratio * l.

    l = sqrt(A / (solid_fraction * aspect_ratio)) with A = sum of the circumscribed disks'
    areas (these are what :func:`deposit` packs, for disks and polygons alike) for the exact
    class counts of :func:`size_classes`.
    """
    counts = size_classes(n, diameters, fractions)
    if not (np.isfinite(aspect_ratio) and aspect_ratio > 0):
        raise ParameterError(f"aspect_ratio={aspect_ratio!r}: expected h/l > 0")
    if not (0 < solid_fraction <= 1):
        raise ParameterError(f"solid_fraction={solid_fraction!r}: expected a value in (0, 1]")
    area = float(np.sum(counts * np.pi * (0.5 * np.asarray(diameters, float)) ** 2))
    return math.sqrt(area / (solid_fraction * aspect_ratio))


def deposit(n, diameters=PAPER_DIAMETERS, fractions=PAPER_FRACTIONS, nvert=5, width=None, seed=0):
    """Deposit n particles by the lowest-stable-position rule (see the module docstring).

    Parameters
    ----------
    n : number of particles.
    diameters : circumscribed diameters of the size classes, m.
    fractions : number fractions of the classes (sum 1).
    nvert : 0 for disks, n >= 3 for regular n-gons (all particles alike).
    width : box width, m; default :func:`box_width_for` (n, diameters, fractions), which gives
        h/l ~ 2.
    seed : seed of the size order and of the polygon orientations (deterministic).

    Returns
    -------
    Packing (pos, angle, radius, nvert, height): centres in the box [0, width] x [0, height],
    every circumscribed disk inside the box and none overlapping another.
    """
    counts = size_classes(n, diameters, fractions)
    nvert = _check_nvert(nvert)
    diameters = np.asarray(diameters, dtype=np.float64).reshape(-1)
    if width is None:
        width = box_width_for(n, diameters, fractions)
    width = float(width)
    if not np.isfinite(width) or width < diameters[counts > 0].max():
        raise ParameterError(f"width={width!r}: expected a box width (m) of at least the largest diameter")
    rng = np.random.default_rng(seed)
    class_of = rng.permutation(np.repeat(np.arange(counts.size), counts)).astype(np.int64)
    class_radius = 0.5 * diameters
    r_max = class_radius[counts > 0].max()
    cell = 2.0 * r_max * (1.0 + 1e-9)
    ncols = max(int(width / cell), 1)
    cell = max(cell, width / ncols)
    # rows enough for a packing four times looser than the expected one; higher particles are
    # clamped into the last row (still correct, only slower)
    area = float(np.sum(counts * np.pi * class_radius**2))
    expected_height = area / (DEPOSIT_SOLID_FRACTION * width) + 4 * r_max
    nrows = max(int(4 * expected_height / cell) + 2, 1)
    pos, radius, placed = _deposit_kernel(class_of, class_radius, width, cell, ncols, nrows,
                                          CLEARANCE * r_max)
    if placed < n:
        raise ParameterError(f"no room left for particle {placed} in a box of width {width} m")
    angle = np.zeros(n) if nvert == 0 else rng.uniform(0.0, 2.0 * np.pi / nvert, n)
    height = float(np.max(pos[:, 1] + radius))
    return Packing(pos, angle, radius, np.full(n, nvert, np.int32), height)
