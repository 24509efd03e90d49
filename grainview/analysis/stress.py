"""Stress of the packing: the tensor, p, q, q/p, principal direction, and the partial
stresses of simple and double contacts (paper Eqs. M and sigmasd; docs/conventions.md §1).

By default the stress includes the particle–wall contacts: with them the sum over contacts
equals the sum of the particles' tensorial moments exactly (see
:func:`grainview.analysis.arrays.stress.stress_tensor`), i.e. the stress the walls apply.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from . import sample
from ._lift import apply, ratio, with_attrs
from .arrays import stress as _stress
from .arrays.tensors import principal
from .contacts import kind_code, selection
from ._docs import fill_doc

__all__ = ["stress_tensor", "stress_invariants", "stress_direction"]


@fill_doc
def stress_tensor(ds: xr.Dataset, kind="all", walls: bool = True) -> xr.DataArray:
    """Stress tensor sigma of every snapshot, in Pa.

        sigma = (1/V) sum_c f^c (x) l^c

    with f^c = f_n n + f_t t the force of contact c (N), l^c its branch vector (m) and V the
    volume of the sample box (:func:`grainview.analysis.sample.volume`, m3); compression positive
    (paper Eq. M, docs/conventions.md §1).

    ``kind="simple"`` or ``"double"`` restricts the sum to one contact kind, so that
    ``stress_tensor(ds, "simple") + stress_tensor(ds, "double") == stress_tensor(ds)``
    (paper Eq. sigmasd). ``walls=False`` leaves out the particle–wall contacts; with them the
    sum equals the sum of the particles' tensorial moments, i.e. the stress the walls apply.
    Every pair the file holds is summed (a pair without force adds nothing).

    Parameters
    ----------
    {ds}
    {kind}
    walls : bool, default True
        Include the particle–wall contacts; ``False`` leaves them out.

    Returns
    -------
    xarray.DataArray
        ``stress`` (time, xy_a, xy_b) in Pa; lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. M (Sec. III) and, for the partial stresses, Eq. sigmasd;
    docs/conventions.md §1.
    """
    mask = selection(ds, walls=walls, kind=kind, near=np.inf)
    label = {None: "", 1: " of simple contacts", 2: " of double contacts"}[kind_code(kind)]
    return apply(_stress.stress_tensor, ds["fn"], ds["ft"], ds["normal"], ds["branch"], mask,
                 sample.volume(ds),
                 names=["stress"],
                 attrs={"units": "Pa", "long_name": f"stress tensor{label}",
                        "comment": "sigma = (1/V) sum_c f (x) l, compression positive"})


def _principal_parts(sigma: xr.DataArray):
    return apply(principal, sigma)


@fill_doc
def stress_invariants(ds: xr.Dataset, kind="all", walls: bool = True,
                      sigma: xr.DataArray | None = None) -> xr.Dataset:
    """p, q, q/p and theta_sigma of the stress tensor (paper Sec. III).

        p = (s1 + s2)/2,    q = (s1 - s2)/2

    with ``s1 >= s2`` the principal values of the symmetric part of sigma (Pa); ``theta_sigma``
    the major principal direction in [0, pi) (rad). For a partial stress (``kind`` simple or
    double), ``q_over_p`` divides its deviator by the p of the whole sample, as the paper's
    Fig. 18 does.

    Parameters
    ----------
    {ds}
    {kind}
    walls : bool, default True
        Include the particle–wall contacts; ``False`` leaves them out.
    sigma : xarray.DataArray, optional
        A stress tensor (time, xy_a, xy_b) in Pa to use instead of
        ``stress_tensor(ds, kind, walls)``; ``kind`` still decides which p divides q in
        ``q_over_p``.

    Returns
    -------
    xarray.Dataset
        Over ``time``: ``p``, ``q``, ``sigma_1``, ``sigma_2`` (the principal values s1, s2) in
        Pa, ``q_over_p`` (dimensionless) and ``theta_sigma`` (rad); lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III (p, q, q/p) and Fig. 18 (partial stresses); docs/conventions.md §1.
    """
    sigma = stress_tensor(ds, kind, walls) if sigma is None else sigma
    s1, s2, theta = _principal_parts(sigma)
    p = (s1 + s2) / 2
    q = (s1 - s2) / 2
    if kind_code(kind) is None:
        p_ref = p
    else:
        t1, t2, _ = _principal_parts(stress_tensor(ds, "all", walls))
        p_ref = (t1 + t2) / 2
    return xr.Dataset({
        "p": with_attrs(p, "p", "Pa", "mean stress p = (s1 + s2)/2"),
        "q": with_attrs(q, "q", "Pa", "stress deviator q = (s1 - s2)/2"),
        "q_over_p": with_attrs(ratio(q, p_ref), "q_over_p", "1", "normalised shear stress q/p"),
        "theta_sigma": with_attrs(theta, "theta_sigma", "rad", "major principal stress direction"),
        "sigma_1": with_attrs(s1, "sigma_1", "Pa", "major principal stress"),
        "sigma_2": with_attrs(s2, "sigma_2", "Pa", "minor principal stress"),
    })


@fill_doc
def stress_direction(ds: xr.Dataset, walls: bool = True) -> xr.DataArray:
    """Major principal stress direction theta_sigma (time,), rad.

    The reference direction of the signed anisotropies a', a_n, a_t (docs/conventions.md §3,
    "Signs"): :func:`stress_invariants`'s ``theta_sigma`` of the whole sample.

    Parameters
    ----------
    {ds}
    walls : bool, default True
        Include the particle–wall contacts; ``False`` leaves them out.

    Returns
    -------
    xarray.DataArray
        ``theta_sigma`` (time,) in rad, in [0, pi).

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III and Eq. a' (the reference direction theta'); docs/conventions.md §1 and §3.
    """
    return stress_invariants(ds, walls=walls)["theta_sigma"]
