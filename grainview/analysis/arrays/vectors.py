"""Contact vectors in the conventions of docs/conventions.md §0: the force of i on j and the
orientation of a normal, on batched arrays (..., 2)."""

from __future__ import annotations

import numpy as np

from ...contract import portable_math


def force_vectors(fn, ft, normal):
    """Force f = fn n + ft t with t = (-n_y, n_x), as (..., 2) arrays (docs/conventions.md §0)."""
    nx, ny = normal[..., 0], normal[..., 1]
    return np.stack([fn * nx - ft * ny, fn * ny + ft * nx], axis=-1)


def angle_of(normal):
    """Orientation theta of each normal folded into [0, pi) (docs/conventions.md §0), rad."""
    return np.mod(portable_math.arctan2(normal[..., 1], normal[..., 0]), np.pi)
