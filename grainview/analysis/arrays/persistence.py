"""Contacts matched across snapshots on plain arrays: a pair's key, which reference contacts a
snapshot still holds, the simple <-> double transitions between consecutive snapshots
(:mod:`grainview.analysis.persistence` streams the snapshots through them; the definitions are
there and in docs/conventions.md §8).

Rows are snapshots: ``keys`` (T, C) int64 pair keys (:func:`pair_keys`), ``present`` (T, C) bool
the slots that count, ``kind`` (T, C) the contract's kinds.
"""

from __future__ import annotations

import numpy as np

from ...contract.schema import KIND_DOUBLE, KIND_SIMPLE

__all__ = ["pair_keys", "reference_found", "pair_transitions", "pooled_counts"]

_MAX_KEY = np.iinfo(np.int64).max // 2


def pair_keys(i, j, n_bodies):
    """int64 key ``min(i, j) n_bodies + max(i, j)`` of each pair (unique for bodies < n_bodies).

        key = min(i, j) n_bodies + max(i, j)

    Parameters
    ----------
    i, j : array_like of int
        The bodies of each contact (same shape).
    n_bodies : int
        The stride, N + W (:func:`grainview.analysis.persistence.body_count`).

    Returns
    -------
    numpy.ndarray
        int64 keys, the shape of ``i`` and ``j``.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A (a contact as a pair of bodies); docs/conventions.md §8.
    """
    i = np.asarray(i, np.int64)
    j = np.asarray(j, np.int64)
    return np.minimum(i, j) * n_bodies + np.maximum(i, j)


def reference_found(ref_keys, keys, present):
    """found[t, r]: whether reference contact r (``ref_keys``, sorted, unique, not empty) is among
    the present slots of row t (``keys``, ``present`` (T, C)); (T, R) bool."""
    position = np.minimum(np.searchsorted(ref_keys, keys), ref_keys.size - 1)
    hit = present & (ref_keys[position] == keys)
    found = np.zeros((keys.shape[0], ref_keys.size), bool)
    rows, cols = np.nonzero(hit)
    found[rows, position[rows, cols]] = True
    return found


def pair_transitions(prev_keys, prev_kind, prev_present, keys, kind, present, stride):
    """Numbers of contacts present at t-1 and t that went simple -> double and double -> simple,
    and the number of contacts at t-1, for consecutive rows (prev row r matches row r).

    Rows are separated by adding ``r * stride**2`` to the keys (exact integer offsets), so a
    single sort and ``np.searchsorted`` match all pairs of a block.
    """
    n_rows = keys.shape[0]
    span = stride * stride
    rows_per_pass = max(1, _MAX_KEY // span - 1)
    s_to_d = np.zeros(n_rows, np.int64)
    d_to_s = np.zeros(n_rows, np.int64)
    for lo in range(0, n_rows, rows_per_pass):  # one pass unless keys would overflow int64
        hi = min(lo + rows_per_pass, n_rows)
        offset = np.arange(hi - lo, dtype=np.int64)[:, None] * span
        before = (prev_keys[lo:hi] + offset)[prev_present[lo:hi]]
        before_kind = prev_kind[lo:hi][prev_present[lo:hi]]
        order = np.argsort(before, kind="stable")
        before, before_kind = before[order], before_kind[order]
        row, col = np.nonzero(present[lo:hi])
        now = keys[lo:hi][row, col] + offset[row, 0]
        if before.size == 0 or now.size == 0:
            continue
        position = np.minimum(np.searchsorted(before, now), before.size - 1)
        matched = before[position] == now
        was, becomes = before_kind[position], kind[lo:hi][row, col]
        s_to_d[lo:hi] = np.bincount(row[matched & (was == KIND_SIMPLE) & (becomes == KIND_DOUBLE)],
                                    minlength=hi - lo)
        d_to_s[lo:hi] = np.bincount(row[matched & (was == KIND_DOUBLE) & (becomes == KIND_SIMPLE)],
                                    minlength=hi - lo)
    return s_to_d, d_to_s, prev_present.sum(axis=1)


def pooled_counts(keys, present):
    """How many different pairs the present slots of all rows hold, and how many a row holds on
    average: (int, float)."""
    return int(np.unique(keys[present]).size), float(present.sum(axis=1).mean())
