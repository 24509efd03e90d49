"""The warm start: last step's impulses carried over to the same contact points.

Every detected point has a key, the same for the same point in two steps
(:func:`solver.contact_points.point_keys`: the body pair and the point's rank in the pair).
A point of this step starts the NLGS from the impulse (p_n, p_t) that the point with its key
ended the last step with, and from (0, 0) when no such point existed (a new contact). This is
the usual warm start of contact dynamics codes (LMGC90 keeps the same "verlet" impulses): in a
slowly deforming packing most points persist, and their last impulses are close to the new
solution, so the sweeps start near it.

The match walks the new keys along last step's keys, sorted once. Detection gives the points
nearly in key order, so a stable (merge) sort sorts last step's keys in about one pass, and the
walk moves forward from one match to the next (searching the rest by halves when the next match
is far), with a binary search below the last match where a new key is smaller than the one
before it. The keys are unique, so any sort gives the same order and the
same match.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _first_not_below(sorted_keys, key, lo, hi):
    """The first position in ``lo .. hi`` of ``sorted_keys`` whose key is >= ``key`` (``hi``
    when none; binary search)."""
    while lo < hi:
        mid = (lo + hi) >> 1
        if sorted_keys[mid] < key:
            lo = mid + 1
        else:
            hi = mid
    return lo


WALK = 8
"""Steps the forward walk takes one by one before it searches the rest of the keys."""


@njit(cache=True)
def _match_sorted(last_keys, order, last_impulse, keys):
    """For each of ``keys``: the row of ``last_impulse`` (P_last, 2) whose key in ``last_keys``
    is the same (``order`` sorts ``last_keys``), or (0, 0). The position is the first sorted
    key not below the key. The keys come nearly in order, so it is found by walking forward from
    the last key's position, a binary search taking over after :data:`WALK` steps, and by a
    binary search below the last position where a key is smaller than the one before it."""
    m = keys.size
    last = order.size
    sorted_keys = np.empty(last, dtype=np.int64)
    for q in range(last):
        sorted_keys[q] = last_keys[order[q]]
    out = np.zeros((m, 2))
    position = 0
    for k in range(m):
        key = keys[k]
        if k > 0 and key < keys[k - 1]:
            position = _first_not_below(sorted_keys, key, 0, position)
        else:
            steps = 0
            while position < last and sorted_keys[position] < key and steps < WALK:
                position += 1
                steps += 1
            if steps == WALK:
                position = _first_not_below(sorted_keys, key, position, last)
        if position < last and sorted_keys[position] == key:
            j = order[position]
            out[k, 0] = last_impulse[j, 0]
            out[k, 1] = last_impulse[j, 1]
    return out


def match_impulses(last_keys, last_impulse, keys):
    """Warm-start impulses (P, 2) N s of the points with ``keys`` (P,) int64: for each, the row of
    ``last_impulse`` (P_last, 2) whose key in ``last_keys`` (P_last,) is the same, and (0, 0)
    for a key that is not there (module docstring)."""
    keys = np.asarray(keys, dtype=np.int64)
    last_keys = np.asarray(last_keys, dtype=np.int64)
    if last_keys.size == 0 or keys.size == 0:
        return np.zeros((keys.size, 2))
    order = np.argsort(last_keys, kind="stable")
    return _match_sorted(last_keys, order, np.ascontiguousarray(last_impulse, dtype=float), keys)


def match_impulses_reference(last_keys, last_impulse, keys):
    """:func:`match_impulses` with numpy's sort and search: the plain reference."""
    impulse = np.zeros((len(keys), 2))
    if len(last_keys) and len(keys):
        order = np.argsort(last_keys, kind="stable")
        sorted_keys = last_keys[order]
        where = np.minimum(np.searchsorted(sorted_keys, keys), len(sorted_keys) - 1)
        hit = sorted_keys[where] == keys
        impulse[hit] = last_impulse[order[where[hit]]]
    return impulse
