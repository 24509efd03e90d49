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
from ._docs import fill_doc
from ..contract.errors import ParameterError

__all__ = ["contact_numbers", "counts_of", "coordination", "connectivity_pdf",
           "joint_connectivity_pdf"]


@fill_doc
def contact_numbers(ds: xr.Dataset, kind="all", walls: bool = False, near=None) -> xr.DataArray:
    """c_i (time, particle): number of contacts of each particle, force-bearing ones by default.

    A double contact counts once (docs/conventions.md §7). ``near``:
    :func:`grainview.analysis.contacts.in_network`.

    Parameters
    ----------
    {ds}
    {kind}
    {walls}
    {near}

    Returns
    -------
    xarray.DataArray
        ``contact_number`` (time, particle), integer counts; lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A; docs/conventions.md §7.
    """
    which = "force-bearing contacts" if near is None else f"contacts and pairs within {float(near):g} m"
    return with_attrs(counts_of(ds, selection(ds, walls=walls, kind=kind, near=near)), "contact_number", "1",
                      f"number of {which} per particle")


@fill_doc
def counts_of(ds: xr.Dataset, mask: xr.DataArray) -> xr.DataArray:
    """Per particle, how many of the slots selected by ``mask`` touch it (time, particle).

    (time, particle): how many of the slots selected by the boolean ``mask`` (time, contact)
    touch each particle (a double contact once), lazily.

    Parameters
    ----------
    {ds}
    mask : xarray.DataArray
        Boolean (time, contact), e.g. :func:`grainview.analysis.contacts.selection`.

    Returns
    -------
    xarray.DataArray
        (time, particle), int64 counts.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A; docs/conventions.md §7.
    """
    return apply(_conn.contact_numbers, ds["i"], ds["j"], mask, output_sizes={"particle": ds.sizes["particle"]},
                 kwargs={"n_particles": ds.sizes["particle"]}, output_dtypes=[np.int64])


def _check_min(min_contacts):
    if not isinstance(min_contacts, (int, np.integer)) or min_contacts < 1:
        raise ParameterError(f"min_contacts={min_contacts!r}: expected an integer >= 1")


@fill_doc
def coordination(ds: xr.Dataset, walls: bool = False, min_contacts: int = 1, near=None) -> xr.Dataset:
    """Coordination number z (time) over the N' non-rattler particles, and N'.

        z = sum_i c_i / N'

    the sum over the N' particles with c_i >= ``min_contacts`` force-bearing contacts (a double
    contact counts once); the others are rattlers, left out (docs/conventions.md §7). Wall
    contacts are not counted unless ``walls=True``.

    Parameters
    ----------
    {ds}
    {walls}
    min_contacts : int, default 1
        A particle with fewer such contacts is a rattler, left out (default 1: none at all).
    {near}

    Returns
    -------
    xarray.Dataset
        ``z`` (dimensionless) and ``n_active`` (N', the number of non-rattler particles) over
        ``time``; lazy on dask input.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``min_contacts`` is not an integer >= 1.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A, Fig. 6a; docs/conventions.md §7.
    """
    _check_min(min_contacts)
    z, kept = apply(_conn.coordination, contact_numbers(ds, walls=walls, near=near), kwargs={"min_contacts": min_contacts},
                    output_dtypes=[float, np.int64])
    return xr.Dataset({
        "z": with_attrs(z, "z", "1", "coordination number z (rattlers excluded)"),
        "n_active": with_attrs(kept, "n_active", "1", "number of non-rattler particles"),
    })


@fill_doc
def connectivity_pdf(ds: xr.Dataset, max_c: int = 10, walls: bool = False, min_contacts: int = 1,
                     near=None) -> xr.DataArray:
    """P(c) (time, c): fraction of non-rattler particles with exactly c contacts (Fig. 7).

        P(c) = N(c) / N'

    N(c) the number of particles with exactly c force-bearing contacts (a double contact once),
    N' the number of non-rattler particles (c >= ``min_contacts``).

    Parameters
    ----------
    {ds}
    max_c : int, default 10
        The largest c of the result (c = 0 .. max_c).
    {walls}
    min_contacts : int, default 1
        A particle with fewer such contacts is a rattler, left out (default 1: none at all).
    {near}

    Returns
    -------
    xarray.DataArray
        ``P_c`` (time, c), dimensionless, with the coordinate ``c``; lazy on dask input.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``min_contacts`` is not an integer >= 1.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV.A, Fig. 7; docs/conventions.md §7.
    """
    _check_min(min_contacts)
    da = apply(_conn.connectivity_pdf, contact_numbers(ds, walls=walls, near=near), output_sizes={"c": max_c + 1},
               kwargs={"max_c": max_c, "min_contacts": min_contacts})
    da = da.assign_coords(c=np.arange(max_c + 1))
    return with_attrs(da, "P_c", "1", "fraction of particles with exactly c contacts P(c)")


@fill_doc
def joint_connectivity_pdf(ds: xr.Dataset, max_m: int = 8, walls: bool = False, min_contacts: int = 1,
                           near=None) -> xr.DataArray:
    """P(m_s, m_d): fraction of non-rattler particles with m_s simple and m_d double contacts.

    (time, m_s, m_d), paper Fig. 21:

        P(m_s, m_d) = N(m_s, m_d) / N'

    N(m_s, m_d) the number of particles with exactly m_s simple and m_d double force-bearing
    contacts, N' the number of non-rattler particles (c >= ``min_contacts``,
    counting both kinds).

    Parameters
    ----------
    {ds}
    max_m : int, default 8
        The largest m_s and m_d of the result (0 .. max_m each).
    {walls}
    min_contacts : int, default 1
        A particle with fewer such contacts is a rattler, left out (default 1: none at all).
    {near}

    Returns
    -------
    xarray.DataArray
        ``P_ms_md`` (time, m_s, m_d), dimensionless, with the coordinates ``m_s`` and ``m_d``;
        lazy on dask input.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``min_contacts`` is not an integer >= 1.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. VI, Fig. 21; docs/conventions.md §7.
    """
    _check_min(min_contacts)
    da = apply(_conn.joint_connectivity_pdf, contact_numbers(ds, "simple", walls, near),
               contact_numbers(ds, "double", walls, near), output_sizes={"m_s": max_m + 1, "m_d": max_m + 1},
               kwargs={"max_m": max_m, "min_contacts": min_contacts})
    da = da.assign_coords(m_s=np.arange(max_m + 1), m_d=np.arange(max_m + 1))
    return with_attrs(da, "P_ms_md", "1", "fraction of particles with m_s simple and m_d double contacts")
