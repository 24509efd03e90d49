"""Numba kernel of the force chains: the connected sets of linked particles of each snapshot
(union-find with union by size and path halving), labelled in the order of their smallest
member."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _root(parent, p):
    while parent[p] != p:
        parent[p] = parent[parent[p]]
        p = parent[p]
    return p


@njit(cache=True)
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
