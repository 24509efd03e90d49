"""Contacts in a periodic cell on plain arrays: which boundaries each contact crosses
(docs/schema.md, "The periodic cell"; docs/analysis.md, "Periodic cells")."""

from __future__ import annotations

import numpy as np

from ...contract.cell import image_shift
from .signature import CONTACT, CONTACT_XY, PARTICLE, core_dims

PARTICLE_XY = PARTICLE + ("xy",)
CELL = ("cell_vector", "xy")
"""Core dimensions of a cell's lattice vectors (rows a, b)."""

__all__ = ["CELL", "contact_image_shifts", "unwrapped_trajectory"]


@core_dims(CONTACT, CONTACT, CONTACT_XY, PARTICLE_XY, CELL, out=(CONTACT_XY,))
def contact_image_shifts(i, j, branch, position, cell, periodic):
    """The whole cells (m, n) between each contact's branch and its stored centres:

        x_i + branch = x_j + m a + n b,

    i.e. the contact touches the image of j that is (m, n) cells from its stored centre
    (:func:`grainview.contract.cell.image_shift` of ``branch - (x_j - x_i)``). (0, 0) for a
    contact inside the cell, for a wall contact (j outside the particles) and an empty slot.

    Parameters
    ----------
    i, j : array_like of int, (..., C)
        The contacts' bodies.
    branch : array_like, (..., C, 2)
        Minimum-image branch vectors, m.
    position : array_like, (..., P, 2)
        Centres, m (wrapped or unwrapped).
    cell : array_like, (..., 2, 2)
        Lattice vectors, m.
    periodic : array_like of bool, (2,)
        Along which vectors the sample repeats.

    Returns
    -------
    numpy.ndarray of int64, (..., C, 2)
    """
    position = np.asarray(position, float)
    branch = np.asarray(branch, float)
    n_part = position.shape[-2]
    i, j = np.broadcast_to(i, branch.shape[:-1]), np.broadcast_to(j, branch.shape[:-1])
    pair = (i >= 0) & (i < n_part) & (j >= 0) & (j < n_part) & np.isfinite(branch).all(-1)
    xi = np.take_along_axis(position, np.clip(i, 0, n_part - 1)[..., None], axis=-2)
    xj = np.take_along_axis(position, np.clip(j, 0, n_part - 1)[..., None], axis=-2)
    d = np.where(pair[..., None], np.nan_to_num(branch - (xj - xi)), 0.0)
    shift = image_shift(d, np.asarray(cell, float)[..., None, :, :], periodic)
    return np.where(pair[..., None], shift, 0)


def unwrapped_trajectory(position, cell, periodic):
    """Centres followed across a periodic cell's boundary, snapshot after snapshot:

        u_0 = x_0,    u_k = u_(k-1) + minimum_image(x_k - u_(k-1); a_k, b~_k),

    so that ``u_k = x_k + m a_k + n b~_k`` with the whole cells (m, n) the particle has crossed,
    counted in the cell of snapshot k with its tilt made continuous across flips
    (``b~_k``, :func:`grainview.contract.cell.unwrap_tilt`). In a sheared cell an image across
    the top or bottom edge moves with the tilt: a particle that crossed it n times is ``n b~_k``
    away from its stored centre at every later snapshot, not ``n b`` of the snapshot it crossed
    at. Exact as long as no particle moves more than half a cell between two snapshots.

    Parameters
    ----------
    position : array_like, (T, N, 2)
        Centres wrapped into the cell, m.
    cell : array_like, (T, 2, 2)
        Lattice vectors, m.
    periodic : array_like of bool, (2,)
        Along which vectors the sample repeats.

    Returns
    -------
    numpy.ndarray
        (T, N, 2), m.
    """
    from ...contract.cell import minimum_image, unwrap_tilt

    position = np.asarray(position, float)
    cell = np.array(cell, float)
    cell[:, 1, 0] = unwrap_tilt(cell[:, 1, 0], cell[:, 0, 0])
    out = np.empty_like(position)
    if position.shape[0]:
        out[0] = position[0]
    for k in range(1, position.shape[0]):  # a loop over snapshots; each is vectorised over particles
        out[k] = out[k - 1] + minimum_image(position[k] - out[k - 1], cell[k], periodic)
    return out
