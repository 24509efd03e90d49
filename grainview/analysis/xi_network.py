"""The xi-network: stress and fabric carried by the contacts with f_n < xi <f_n> (paper
Sec. V.C, Figs. 15 and 16; docs/conventions.md §5).

Sweeping xi from 0 to the largest force shows how the shear stress and the fabric anisotropy
are shared between weak and strong contacts: the paper finds q(xi)/p ~ 0 for xi < 1 (the weak
network carries no deviator) and a'(xi) < 0 for small xi (weak contacts orthogonal to the
major principal stress direction).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import apply, with_attrs
from .arrays import xi_network as _xi
from .contacts import selection
from ..contract.errors import ParameterError
from .sample import volume
from .snapshots import select_snapshots
from .stress import stress_invariants
from ._docs import fill_doc

__all__ = ["xi_network", "xi_profile"]

DEFAULT_XI = np.linspace(0.0, 5.0, 101)


def _check_xi(xi):
    try:
        values = np.asarray(xi, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(f"xi={xi!r}: expected a 1-D sequence of numbers >= 0") from None
    if values.ndim == 0:
        values = values[None]
    if values.ndim != 1 or values.size == 0:
        raise ParameterError(f"xi: expected a non-empty 1-D sequence of cutoffs, got shape {values.shape}")
    if not np.all(np.isfinite(values)) or np.any(values < 0):
        raise ParameterError("xi: expected finite cutoffs >= 0 (multiples of the mean normal force <f_n>)")
    return values


@fill_doc
def xi_network(ds: xr.Dataset, xi=DEFAULT_XI, walls: bool = False, near=None) -> xr.Dataset:
    """q(xi)/p, a'(xi) and the contact fraction of the xi-networks (time, xi) (docs/conventions.md §5).

    The xi-network of a snapshot is the set of selected contacts (particle–particle by
    default) with f_n < xi <f_n> (strict), <f_n> their mean normal force.

    * ``q_over_p``: deviator q(xi) = (s1 - s2)/2 of the stress sigma(xi) = (1/V) sum f (x) l
      over the subset alone, divided by the mean stress p of the WHOLE sample, wall contacts
      included (:func:`grainview.analysis.stress.stress_invariants` with its default ``walls=True``),
      paper Fig. 15;
    * ``a_prime``: signed fabric anisotropy of the subset, a'(xi) = 2 (F_1 - F_2)
      cos 2(theta_F - theta_sigma), with F(xi) = (1/N(xi)) sum n (x) n normalised by the
      subset's own count and theta_sigma the whole sample's major principal stress direction,
      paper Fig. 16 (NaN while the subset is empty);
    * ``contact_fraction``: N(xi)/N_c; ``count``: N(xi).

    One sort per snapshot serves every xi (see :mod:`grainview.analysis.arrays.xi_network`).

    Parameters
    ----------
    {ds}
    xi : array_like of float, default 0, 0.05, ..., 5
        Any 1-D sequence of cutoffs >= 0, multiples of <f_n> (dimensionless).
    {walls}
    near : float, optional
        Which pairs are contacts (:func:`grainview.analysis.contacts.in_network`): None (default) the
        force-bearing ones, f_n > 0; a gap threshold in m adds the pairs with gap <= ``near``
        (they carry f_n = 0); ``np.inf`` every pair the file holds.
        Near pairs carry f_n = 0 and so belong to every xi-network with xi > 0.

    Returns
    -------
    xarray.Dataset
        ``q_over_p``, ``a_prime``, ``contact_fraction`` (dimensionless) and ``count`` over
        (time, xi), with the cutoffs as the coordinate ``xi``; lazy on dask input.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``xi`` is not a non-empty 1-D sequence of finite numbers >= 0.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V.C, Figs. 15 and 16; docs/conventions.md §5.
    """
    xi = _check_xi(xi)
    whole = stress_invariants(ds)
    outputs = apply(_xi.xi_network, ds["fn"], ds["ft"], ds["normal"], ds["branch"], selection(ds, walls=walls, near=near),
                    volume(ds), whole["p"], whole["theta_sigma"],
                    output_sizes={"xi": xi.size}, kwargs={"xi": xi},
                    output_dtypes=[float, float, float, np.int64])
    q_over_p, a_prime, fraction, count = outputs
    out = xr.Dataset({
        "q_over_p": with_attrs(q_over_p, "q_over_p", "1",
                               "deviator of the xi-network's stress over the whole sample's p, q(xi)/p"),
        "a_prime": with_attrs(a_prime, "a_prime", "1", "signed fabric anisotropy of the xi-network a'(xi)"),
        "contact_fraction": with_attrs(fraction, "contact_fraction", "1",
                                       "fraction of the selected contacts in the xi-network N(xi)/N_c"),
        "count": with_attrs(count, "count", "1", "number of contacts in the xi-network N(xi)"),
    })
    out = out.assign_coords(xi=("xi", xi, {"units": "1", "long_name": "force cutoff xi (f_n < xi <f_n>)"}))
    out.attrs["walls"] = int(walls)
    return out


@fill_doc
def xi_profile(ds: xr.Dataset, xi=None, time="residual", near=None) -> xr.Dataset:
    """q(xi)/p, a'(xi) and the contact fraction of the xi-network, averaged over the snapshots ``time``.

    The xi-network holds the contacts with f_n < xi <f_n> (docs/conventions.md §5;
    :func:`xi_network`, whose cutoffs are the default); each snapshot's values are averaged
    over the snapshots ``time``.

    Parameters
    ----------
    {ds_short}
    xi : array_like of float, optional
        The cutoffs xi >= 0, multiples of <f_n>.
    {time_averaged}
    near : float, optional
        None: the force-bearing contacts (f_n > 0); a gap in m: also the pairs within it,
        which carry no force and so belong to every xi-network (the file must hold them;
        :func:`grainview.analysis.contacts.in_network`).

    Returns
    -------
    xarray.Dataset
        ``q_over_p``, ``a_prime``, ``contact_fraction`` (dimensionless) and ``count`` over
        ``xi``; lazy on dask input (``time="residual"`` reads the boxes to find the window).

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V.C, Figs. 15 and 16; docs/conventions.md §5.
    """
    cutoffs = {} if xi is None else {"xi": np.asarray(xi, float)}
    return xi_network(select_snapshots(ds, time), near=near, **cutoffs).mean("time", keep_attrs=True)

