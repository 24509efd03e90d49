"""Connectivity of the force-bearing network: z, P(c), P(m_s, m_d) (paper Sec. IV.A, Figs.
6a, 7, 21; docs/conventions.md §7).

Rattler rule: only force-bearing contacts (f_n > 0) count; a double contact counts once; a
particle with fewer than ``min_contacts`` such contacts (default 1: none at all) is a rattler
and is left out of z, P(c) and P(m_s, m_d). Wall contacts are not counted unless
``walls=True``.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import apply, with_attrs
from .arrays import connectivity as _conn
from .contacts import selection
from .errors import ParameterError


def contact_numbers(ds: xr.Dataset, kind="all", walls: bool = False, near=None) -> xr.DataArray:
    """c_i (time, particle): number of contacts of each particle, force-bearing ones by default
    (``near``: :func:`grainview.contacts.in_network`)."""
    return with_attrs(counts_of(ds, selection(ds, walls=walls, kind=kind, near=near)), "contact_number", "1",
                      "number of force-bearing contacts per particle")


def counts_of(ds: xr.Dataset, mask: xr.DataArray) -> xr.DataArray:
    """(time, particle): how many of the slots selected by the boolean ``mask`` (time, contact)
    touch each particle (a double contact once), lazily."""
    return apply(_conn.contact_numbers, ds["i"], ds["j"], mask, output_sizes={"particle": ds.sizes["particle"]},
                 kwargs={"n_particles": ds.sizes["particle"]}, output_dtypes=[np.int64])


def _check_min(min_contacts):
    if not isinstance(min_contacts, (int, np.integer)) or min_contacts < 1:
        raise ParameterError(f"min_contacts={min_contacts!r}: expected an integer >= 1")


def coordination(ds: xr.Dataset, walls: bool = False, min_contacts: int = 1, near=None) -> xr.Dataset:
    """z = sum_i c_i / N' (time) over the N' non-rattler particles, and N'."""
    _check_min(min_contacts)
    z, kept = apply(_conn.coordination, contact_numbers(ds, walls=walls, near=near), kwargs={"min_contacts": min_contacts},
                    output_dtypes=[float, np.int64])
    return xr.Dataset({
        "z": with_attrs(z, "z", "1", "coordination number z (rattlers excluded)"),
        "n_active": with_attrs(kept, "n_active", "1", "number of non-rattler particles"),
    })


def connectivity_pdf(ds: xr.Dataset, max_c: int = 10, walls: bool = False, min_contacts: int = 1,
                     near=None) -> xr.DataArray:
    """P(c) (time, c): fraction of non-rattler particles with exactly c contacts (Fig. 7)."""
    _check_min(min_contacts)
    da = apply(_conn.connectivity_pdf, contact_numbers(ds, walls=walls, near=near), output_sizes={"c": max_c + 1},
               kwargs={"max_c": max_c, "min_contacts": min_contacts})
    da = da.assign_coords(c=np.arange(max_c + 1))
    return with_attrs(da, "P_c", "1", "fraction of particles with exactly c contacts P(c)")


def joint_connectivity_pdf(ds: xr.Dataset, max_m: int = 8, walls: bool = False, min_contacts: int = 1,
                           near=None) -> xr.DataArray:
    """P(m_s, m_d) (time, m_s, m_d): fraction of non-rattler particles with exactly m_s simple
    and m_d double force-bearing contacts (paper Fig. 21)."""
    _check_min(min_contacts)
    da = apply(_conn.joint_connectivity_pdf, contact_numbers(ds, "simple", walls, near),
               contact_numbers(ds, "double", walls, near), output_sizes={"m_s": max_m + 1, "m_d": max_m + 1},
               kwargs={"max_m": max_m, "min_contacts": min_contacts})
    da = da.assign_coords(m_s=np.arange(max_m + 1), m_d=np.arange(max_m + 1))
    return with_attrs(da, "P_ms_md", "1", "fraction of particles with m_s simple and m_d double contacts")
