"""Which contact slots hold contacts, and which of them to use.

A snapshot's contacts occupy the first ``contact_count[time]`` slots of the ``contact``
dimension (docs/schema.md). Every analysis starts from :func:`selection`: the occupied slots,
optionally restricted to particle–particle contacts (``walls=False``), to one contact kind, or
to force-bearing contacts. All results are lazy when the dataset is.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from .errors import ParameterError
from .schema import KIND_DOUBLE, KIND_SIMPLE

KINDS = {"all": None, "simple": KIND_SIMPLE, "double": KIND_DOUBLE, "s": KIND_SIMPLE, "d": KIND_DOUBLE}


def n_particles(ds: xr.Dataset) -> int:
    """Number of particles N (walls are bodies N, N+1, ...)."""
    return ds.sizes["particle"]


def occupied(ds: xr.Dataset) -> xr.DataArray:
    """Boolean (time, contact): True in the slots that hold a contact."""
    slot = xr.DataArray(np.arange(ds.sizes["contact"], dtype="i4"), dims="contact")
    return slot < ds["contact_count"]


def is_wall_contact(ds: xr.Dataset) -> xr.DataArray:
    """Boolean (time, contact): True where body j is a wall (j >= N)."""
    return ds["j"] >= n_particles(ds)


def kind_code(kind) -> int | None:
    """Normalise a ``kind`` argument ("all", "simple", "double", 1, 2) to a code or None."""
    if kind in (None, "all"):
        return None
    if isinstance(kind, str):
        if kind not in KINDS:
            raise ParameterError(f"kind={kind!r}: expected 'all', 'simple' or 'double'")
        return KINDS[kind]
    if kind in (KIND_SIMPLE, KIND_DOUBLE):
        return int(kind)
    raise ParameterError(f"kind={kind!r}: expected 'all', 'simple' or 'double'")


def selection(ds: xr.Dataset, *, walls: bool = False, kind="all", force_bearing: bool = False) -> xr.DataArray:
    """Boolean (time, contact) mask of the contacts an analysis uses.

    Parameters
    ----------
    walls : include particle–wall contacts (default: particle–particle only).
    kind : "all", "simple" (vertex–edge and disk contacts) or "double" (edge–edge).
    force_bearing : keep only contacts with ``fn > 0``.
    """
    mask = occupied(ds)
    if not walls:
        mask = mask & ~is_wall_contact(ds)
    code = kind_code(kind)
    if code is not None:
        mask = mask & (ds["kind"] == code)
    if force_bearing:
        mask = mask & (ds["fn"] > 0)
    return mask


def force_vectors(fn, ft, normal):
    """Force f = fn n + ft t with t = (-n_y, n_x), as (..., 2) arrays (ERRATA conventions)."""
    nx, ny = normal[..., 0], normal[..., 1]
    return np.stack([fn * nx - ft * ny, fn * ny + ft * nx], axis=-1)


def angle_of(normal):
    """Orientation theta of each normal folded into [0, pi) (ERRATA conventions), rad."""
    return np.mod(np.arctan2(normal[..., 1], normal[..., 0]), np.pi)
