"""Coordination of the particles: contact numbers, z, P(c) and P(m_s, m_d)
(paper Sec. IV.A and Fig. 21; docs/conventions.md §7)."""

from __future__ import annotations

import numpy as np

from .binning import batched_bincount
from .signature import PARTICLE, CONTACT, SCALAR, core_dims


@core_dims(CONTACT, CONTACT, CONTACT, out=(PARTICLE,))
def contact_numbers(i, j, mask, n_particles):
    """Number of selected contacts of each particle (..., N); a double contact counts once.

    Each selected slot adds one to particle i and, when j is a particle (j < N), one to j.
    """
    mask = np.asarray(mask, bool)
    return (batched_bincount(i, mask, n_particles)
            + batched_bincount(j, mask & (np.asarray(j) < n_particles), n_particles))


@core_dims(PARTICLE, out=(SCALAR, SCALAR))
def coordination(counts, min_contacts=1):
    """z = sum_i c_i / N' over the N' particles with c_i >= ``min_contacts`` (the others are
    rattlers and left out; docs/conventions.md §7 uses min_contacts = 1). Returns (z, N')."""
    keep = counts >= min_contacts
    n_kept = keep.sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(keep, counts, 0).sum(axis=-1) / n_kept, n_kept


@core_dims(PARTICLE, out=(("c",),))
def connectivity_pdf(counts, max_c, min_contacts=1):
    """P(c), c = 0..max_c: fraction of the non-rattler particles with exactly c contacts."""
    keep = counts >= min_contacts
    hist = batched_bincount(counts, keep, max_c + 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return hist / keep.sum(axis=-1, keepdims=True)


@core_dims(PARTICLE, PARTICLE, out=(("m_s", "m_d"),))
def joint_connectivity_pdf(counts_s, counts_d, max_m, min_contacts=1):
    """P(m_s, m_d) (..., max_m+1, max_m+1): fraction of non-rattler particles with exactly m_s
    simple and m_d double contacts (paper Fig. 21)."""
    keep = (counts_s + counts_d) >= min_contacts
    inside = keep & (counts_s <= max_m) & (counts_d <= max_m)
    flat = counts_s * (max_m + 1) + counts_d
    hist = batched_bincount(flat, inside, (max_m + 1) ** 2)
    with np.errstate(invalid="ignore", divide="ignore"):
        hist = hist / keep.sum(axis=-1, keepdims=True)
    return hist.reshape(hist.shape[:-1] + (max_m + 1, max_m + 1))
