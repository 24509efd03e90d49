"""Numba kernel of the force chains: the connected sets of linked particles of each snapshot
(union-find with union by size and path halving), labelled in the order of their smallest
member."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _root(parent, p):
    while parent[p] != p:
        parent[p] = parent[parent[p]]
        p = parent[p]
    return p


@njit(cache=True, nogil=True)
def label_components(i, j, link, n_particles, min_size):
    """Chain id of every particle of every row: the connected sets of the graph whose edges are
    the linked contacts, those of at least ``min_size`` particles numbered 0, 1, ... in the
    order of their smallest particle index, -1 for every other particle.

    ``i``, ``j`` (R, C) int64 bodies of each contact slot, ``link`` (R, C) bool; a linked slot
    must have both bodies in [0, n_particles) (checked by the caller). Result (R, n_particles)
    int64.
    """
    n_rows, n_slots = i.shape
    out = np.full((n_rows, n_particles), -1, dtype=np.int64)
    parent = np.empty(n_particles, dtype=np.int64)
    size = np.empty(n_particles, dtype=np.int64)
    label = np.empty(n_particles, dtype=np.int64)
    for r in range(n_rows):
        for p in range(n_particles):
            parent[p] = p
            size[p] = 1
            label[p] = -1
        for c in range(n_slots):
            if not link[r, c]:
                continue
            a = _root(parent, i[r, c])
            b = _root(parent, j[r, c])
            if a == b:
                continue
            if size[a] < size[b]:
                a, b = b, a
            parent[b] = a
            size[a] += size[b]
        following = 0
        for p in range(n_particles):
            root = _root(parent, p)
            if size[root] >= min_size:
                if label[root] < 0:
                    label[root] = following
                    following += 1
                out[r, p] = label[root]
    return out


@njit(cache=True, nogil=True)
def accumulate_moments(slots, force, point, centre):
    """Sum over each particle's contacts of s f (x) (x^c - x_p), one row per snapshot.

    Records of :mod:`grainview.analysis._kernels.records`, all (R, C) but the centres (R, P):
    ``slots`` the bodies ``i``, ``j`` (int64) and ``mask`` (bool), ``force`` the force
    components (N), ``point`` the application point (m), ``centre`` the particles' centres (m).
    s = +1 for body i and -1 for body j; a body outside [0, P) (a wall, an empty slot) gets
    nothing. Result (R, P, 2, 2), N m, [a, b] = f_a (x^c - x_p)_b.
    """
    i, j, mask = slots.i, slots.j, slots.mask
    fx, fy, px, py, x, y = force.x, force.y, point.x, point.y, centre.x, centre.y
    n_rows, n_slots = i.shape
    n_part = x.shape[1]
    out = np.zeros((n_rows, n_part, 2, 2))
    for r in range(n_rows):
        for c in range(n_slots):
            if not mask[r, c]:
                continue
            f0 = fx[r, c]
            f1 = fy[r, c]
            for side in range(2):
                p = i[r, c] if side == 0 else j[r, c]
                if p < 0 or p >= n_part:
                    continue
                s = 1.0 if side == 0 else -1.0
                a0 = px[r, c] - x[r, p]
                a1 = py[r, c] - y[r, p]
                out[r, p, 0, 0] += s * f0 * a0
                out[r, p, 0, 1] += s * f0 * a1
                out[r, p, 1, 0] += s * f1 * a0
                out[r, p, 1, 1] += s * f1 * a1
    return out


@njit(cache=True, nogil=True)
def aligned_links(slots, branch, candidate, direction, cos_limit):
    """Boolean (R, C): the slots of ``slots.mask`` between two particles of ``candidate`` (R, P)
    whose ``branch`` vector (R, C) makes |cos| >= ``cos_limit`` with both particles' unit major
    ``direction`` (R, P); ``slots``, ``branch`` and ``direction`` records of
    :mod:`grainview.analysis._kernels.records`."""
    i, j, mask = slots.i, slots.j, slots.mask
    bx, by, dx, dy = branch.x, branch.y, direction.x, direction.y
    n_rows, n_slots = i.shape
    n_part = candidate.shape[1]
    out = np.zeros((n_rows, n_slots), dtype=np.bool_)
    for r in range(n_rows):
        for c in range(n_slots):
            if not mask[r, c]:
                continue
            a = i[r, c]
            b = j[r, c]
            if a < 0 or b < 0 or a >= n_part or b >= n_part or not candidate[r, a] or not candidate[r, b]:
                continue
            length = np.sqrt(bx[r, c] ** 2 + by[r, c] ** 2)
            if length == 0.0:
                continue
            ux = bx[r, c] / length
            uy = by[r, c] / length
            if abs(ux * dx[r, a] + uy * dy[r, a]) >= cos_limit and abs(ux * dx[r, b] + uy * dy[r, b]) >= cos_limit:
                out[r, c] = True
    return out


@njit(cache=True, nogil=True)
def follow_tracks(chain):
    """Tracks of the chains of consecutive rows (snapshots) of ``chain`` (T, P) int64 (chain ids
    0 .. K_t - 1, -1 outside chains): chain a of row t-1 and chain b of row t are one track when
    they share particles and each is the other's best match (most shared particles, ties to the
    smaller id); every other chain starts a new track, numbered in the order they start.

    Returns ``track`` (T, P) int64 (-1 outside chains) and, per track, ``first``, ``last`` (row
    indices) and ``total`` (particles summed over its rows), each (K,) int64.
    """
    n_time, n_part = chain.shape
    track = np.full((n_time, n_part), -1, dtype=np.int64)
    capacity = 0
    for t in range(n_time):
        capacity += chain[t].max() + 1 if n_part > 0 else 0
    first = np.empty(max(capacity, 0), dtype=np.int64)
    last = np.empty(max(capacity, 0), dtype=np.int64)
    total = np.zeros(max(capacity, 0), dtype=np.int64)
    previous = np.empty(0, dtype=np.int64)
    n_tracks = 0
    codes = np.empty(n_part, dtype=np.int64)
    for t in range(n_time):
        n_here = chain[t].max() + 1 if n_part > 0 else 0
        mapping = np.full(n_here, -1, dtype=np.int64)
        n_prev = previous.shape[0]
        if t > 0 and n_here > 0 and n_prev > 0:
            m = 0
            for p in range(n_part):
                if chain[t - 1, p] >= 0 and chain[t, p] >= 0:
                    codes[m] = chain[t - 1, p] * n_here + chain[t, p]
                    m += 1
            pairs = np.sort(codes[:m])
            best_b = np.full(n_prev, -1, dtype=np.int64)
            count_b = np.zeros(n_prev, dtype=np.int64)
            best_a = np.full(n_here, -1, dtype=np.int64)
            count_a = np.zeros(n_here, dtype=np.int64)
            k = 0
            while k < m:  # runs of equal codes, in increasing (a, b)
                end = k
                while end < m and pairs[end] == pairs[k]:
                    end += 1
                a = pairs[k] // n_here
                b = pairs[k] % n_here
                shared = end - k
                if shared > count_b[a]:
                    count_b[a] = shared
                    best_b[a] = b
                if shared > count_a[b]:
                    count_a[b] = shared
                    best_a[b] = a
                k = end
            for b in range(n_here):
                a = best_a[b]
                if a >= 0 and best_b[a] == b:
                    mapping[b] = previous[a]
        for b in range(n_here):
            if mapping[b] < 0:
                mapping[b] = n_tracks
                first[n_tracks] = t
                n_tracks += 1
        for p in range(n_part):
            c = chain[t, p]
            if c >= 0:
                track[t, p] = mapping[c]
                total[mapping[c]] += 1
        for b in range(n_here):
            last[mapping[b]] = t
        previous = mapping
    return track, first[:n_tracks], last[:n_tracks], total[:n_tracks]
