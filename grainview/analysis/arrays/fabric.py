"""Fabric of the contact network: tensor, anisotropy and the distribution of contact
orientations (paper Eqs. F and a'; docs/conventions.md §2)."""

from __future__ import annotations

import numpy as np

from .vectors import angle_of
from .binning import batched_bincount
from .signature import CONTACT, CONTACT_XY, TENSOR, core_dims


@core_dims(CONTACT_XY, CONTACT, CONTACT, out=(TENSOR,))
def fabric_tensor(normal, mask, count_mask=None):
    """F_ab = (1/N_c) sum_c n_a n_b over the contacts of ``mask`` (paper Eq. F).

    ``count_mask`` (default ``mask``) defines N_c: summing over a subset while dividing by the
    count of all contacts gives the partial tensors F_s, F_d with F = F_s + F_d
    (paper Eq. fabricsd). Shapes: normal (..., C, 2), masks (..., C); result (..., 2, 2);
    NaN where N_c = 0.
    """
    mask = np.asarray(mask, bool)
    count_mask = mask if count_mask is None else np.asarray(count_mask, bool)
    n = np.where(mask[..., None], normal, 0.0)
    total = np.einsum("...ca,...cb->...ab", n, n)
    count = count_mask.sum(axis=-1).astype(float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return total / count[..., None, None]


def orientation_bins(normal, n_bins):
    """Index k of the angular sector of each normal.

    Sector k is centred on theta_k = k pi/n_bins: [theta_k - dtheta/2, theta_k + dtheta/2)
    folded into [0, pi), as the paper's S(theta) (Sec. V.A). Entries with a NaN normal (empty
    slots) get sector 0 and must be masked out by the caller.
    """
    theta = angle_of(normal)
    theta = np.where(np.isfinite(theta), theta, 0.0)
    return np.floor(theta * (n_bins / np.pi) + 0.5).astype(np.int64) % n_bins


@core_dims(CONTACT_XY, CONTACT, out=(("theta",),))
def orientation_pdf(normal, mask, n_bins):
    """P(theta) (..., n_bins): density of contact orientations on [0, pi), rad^-1, so that
    sum P dtheta = 1 (paper Fig. 8; harmonic model P = (1/pi)[1 + a cos 2(theta - theta_a)])."""
    counts = batched_bincount(orientation_bins(normal, n_bins), mask, n_bins)
    total = counts.sum(axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return counts / total / (np.pi / n_bins)
