"""Numba kernel of the xi-network: a batched binary search (``np.searchsorted`` is 1-D only)."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def count_below(sorted_rows, thresholds):
    """For each row r and each k: the number of entries of ``sorted_rows[r]`` (ascending)
    strictly below ``thresholds[r, k]``, i.e. ``np.searchsorted(sorted_rows[r], thresholds[r, k],
    side="left")``. Shapes (R, C) and (R, K) float64; result (R, K) int64. A NaN threshold
    counts nothing."""
    n_rows, n_cols = sorted_rows.shape
    n_thr = thresholds.shape[1]
    out = np.empty((n_rows, n_thr), dtype=np.int64)
    for r in range(n_rows):
        for k in range(n_thr):
            t = thresholds[r, k]
            lo = 0
            hi = n_cols
            while lo < hi:
                mid = (lo + hi) // 2
                if sorted_rows[r, mid] < t:
                    lo = mid + 1
                else:
                    hi = mid
            out[r, k] = lo
    return out
