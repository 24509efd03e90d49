"""Which contact slots hold contacts, and which of them to use.

A snapshot's contacts occupy the first ``contact_count[time]`` slots of the ``contact``
dimension (docs/schema.md). Every analysis starts from :func:`selection`: the occupied slots
that are contacts of the packing — force-bearing ones by default, or also the near (open)
pairs within a gap threshold (``near=``) when the file holds them — optionally restricted to
particle–particle contacts (``walls=False``) or to one contact kind. All results are lazy when
the dataset is.
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


def snapshot_index(ds: xr.Dataset, value, name: str = "time") -> int:
    """``value`` as a snapshot index in [0, T) (negative counts from the end); one clear line
    naming the argument ``name`` when it is not an integer in [-T, T)."""
    n = ds.sizes["time"]
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not -n <= value < n:
        raise ParameterError(f"{name}={value!r}: expected a snapshot index in [{-n}, {n})")
    return int(value) % n


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


def check_near(ds: xr.Dataset, near) -> float | None:
    """Validate the ``near`` argument of the analyses (see :func:`in_network`); returns it as
    a float, or None."""
    if near is None:
        return None
    if isinstance(near, bool) or not isinstance(near, (int, float, np.integer, np.floating)) or np.isnan(near) \
            or near < 0:
        raise ParameterError(f"near={near!r}: expected None (force-bearing contacts only) or a gap "
                             "threshold >= 0 in m (np.inf: every pair the file holds)")
    near = float(near)
    if np.isinf(near):
        return near
    if "gap" not in ds:
        raise ParameterError(f"near={near!r}: the dataset has no 'gap' variable, so open pairs cannot be told "
                             "apart; write the run with near contacts (solver: near_contacts=True, "
                             "grainview run --near-contacts)")
    held = ds.attrs.get("near_contacts_m")
    if held is None or (isinstance(held, str) and held == "none"):
        raise ParameterError(f"near={near!r}: this file holds force-bearing contacts only (no open pairs); "
                             "write the run with near contacts (solver: near_contacts=True, "
                             "grainview run --near-contacts)")
    if near > float(held) * (1 + 1e-9):
        raise ParameterError(f"near={near!r} m exceeds the gap up to which this file holds open pairs "
                             f"(near_contacts_m = {float(held):g} m)")
    return near


def in_network(ds: xr.Dataset, near=None) -> xr.DataArray:
    """Boolean (time, contact): the slots counted as contacts of the packing.

    ``near=None`` (default): the force-bearing contacts, f_n > 0 — the paper's contact network
    (Sec. IV: "the force-bearing network"). ``near=g`` (m): also the open or unloaded pairs
    whose gap (variable ``gap``, the smallest separation of the pair's points, negative when
    they overlap) is <= g, as a code that keeps every pair within its alert distance as a
    contact counts them (docs/analysis.md, "Near contacts"); ``near=np.inf``: every pair the
    file holds. Combine with :func:`occupied`.
    """
    near = check_near(ds, near)
    loaded = ds["fn"] > 0
    if near is None:
        return loaded
    if np.isinf(near):
        return xr.ones_like(loaded)
    return loaded | (ds["gap"] <= near)


def near_attr(near) -> str | float:
    """The ``near`` argument as a netCDF-friendly attribute value ("none" or the gap in m)."""
    return "none" if near is None else float(near)


def selection(ds: xr.Dataset, *, walls: bool = False, kind="all", near=None) -> xr.DataArray:
    """Boolean (time, contact) mask of the contacts an analysis uses.

    Parameters
    ----------
    walls : include particle–wall contacts (default: particle–particle only).
    kind : "all", "simple" (vertex–edge and disk contacts) or "double" (edge–edge).
    near : None (default) for the force-bearing contacts (f_n > 0); a gap threshold in m to
        count also the pairs with gap <= near (:func:`in_network`).
    """
    mask = occupied(ds) & in_network(ds, near)
    if not walls:
        mask = mask & ~is_wall_contact(ds)
    code = kind_code(kind)
    if code is not None:
        mask = mask & (ds["kind"] == code)
    return mask
