"""Per-snapshot counting with one ``np.bincount``: the batched histogram used by the angular
averages, the coordination numbers and the pdfs. Leading axes are flattened into an offset,
so there is no Python loop over snapshots or contacts."""

from __future__ import annotations

import numpy as np


def batched_bincount(index, mask, n_bins, weights=None):
    """Sum ``weights`` (or count) into ``n_bins`` bins per leading index.

    ``index`` (..., C) integer bin of each entry, used where ``mask`` is True and
    ``0 <= index < n_bins``. Returns (..., n_bins).
    """
    index = np.asarray(index)
    lead = index.shape[:-1]
    n_lead = int(np.prod(lead)) if lead else 1
    flat_index = index.reshape(n_lead, -1)
    keep = np.asarray(mask, bool).reshape(n_lead, -1) & (flat_index >= 0) & (flat_index < n_bins)
    offset = np.arange(n_lead)[:, None] * n_bins
    key = (flat_index + offset)[keep]
    w = None if weights is None else np.broadcast_to(weights, index.shape).reshape(n_lead, -1)[keep]
    out = np.bincount(key, weights=w, minlength=n_lead * n_bins)
    return out.reshape(lead + (n_bins,)).astype(float if weights is not None else np.int64)
