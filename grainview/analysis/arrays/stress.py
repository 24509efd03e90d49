"""Stress tensor of a packing from its contact forces (paper Eq. M; docs/conventions.md §1)."""

from __future__ import annotations

import numpy as np

from .vectors import force_vectors
from .signature import CONTACT, CONTACT_XY, SCALAR, TENSOR, core_dims


@core_dims(CONTACT, CONTACT, CONTACT_XY, CONTACT_XY, CONTACT, SCALAR, out=(TENSOR,))
def stress_tensor(fn, ft, normal, branch, mask, volume):
    """sigma_ab = (1/V) sum_c f_a^c l_b^c over the contacts selected by ``mask``.

    ``f = fn n + ft t`` (t = (-n_y, n_x)) is the force exerted by i on j, ``l`` the branch
    vector (centre of i to centre of j; particle centre to contact point for walls), so that
    compression is positive. Equivalent to ``(1/V) sum_i M^i`` with the tensorial moments
    ``M^i = sum_{c in i} f^c (x) (r^c - x^i)`` of the paper (Eq. M), docs/conventions.md §1.

    Shapes: fn, ft, mask (..., C); normal, branch (..., C, 2); volume (...) in m^3 (box area
    times slab thickness). Forces in N, result (..., 2, 2) in Pa. Summing over disjoint masks
    adds up exactly: sigma = sigma_s + sigma_d (paper Eq. sigmasd).
    """
    mask = np.asarray(mask, dtype=bool)
    force = np.where(mask[..., None], force_vectors(fn, ft, normal), 0.0)
    arm = np.where(mask[..., None], branch, 0.0)
    total = np.einsum("...ca,...cb->...ab", force, arm)
    return total / np.asarray(volume, dtype=float)[..., None, None]
