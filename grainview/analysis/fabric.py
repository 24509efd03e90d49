"""Fabric of the contact network (paper Sec. IV.B, Eqs. F and a'; docs/conventions.md §2).

Contacts default to particle–particle ones (``walls=False``): wall contacts have normals
fixed by the walls and would bias the orientation statistics.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import apply, with_attrs
from .arrays import fabric as _fabric
from .arrays.tensors import principal, signed_anisotropy
from .contacts import kind_code, selection
from ..contract.errors import ParameterError
from .stress import stress_direction
from ._docs import fill_doc

__all__ = ["fabric_tensor", "reference_direction", "fabric_anisotropy", "orientation_pdf",
           "theta_coord", "check_bins"]


@fill_doc
def fabric_tensor(ds: xr.Dataset, kind="all", walls: bool = False, near=None) -> xr.DataArray:
    """Fabric tensor F (time, xy_a, xy_b), dimensionless, tr F = 1 (paper Eq. F).

        F = (1/N_c) sum_c n^c (x) n^c

    over the N_c selected contacts, n^c the unit normal of contact c. With ``kind="simple"`` or
    ``"double"`` the sum runs over that kind while N_c stays the count of all contacts, so
    F = F_s + F_d exactly (paper Eq. fabricsd).

    Parameters
    ----------
    {ds}
    {kind}
    {walls}
    {near}

    Returns
    -------
    xarray.DataArray
        ``fabric`` (time, xy_a, xy_b), dimensionless; lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. F (Sec. IV.B) and Eq. fabricsd; docs/conventions.md §2.
    """
    mask_all = selection(ds, walls=walls, near=near)
    mask = selection(ds, walls=walls, kind=kind, near=near)
    label = {None: "", 1: " of simple contacts", 2: " of double contacts"}[kind_code(kind)]
    return apply(_fabric.fabric_tensor, ds["normal"], mask, mask_all, names=["fabric"], attrs={"units": "1", "long_name": f"fabric tensor{label}"})


@fill_doc
def reference_direction(ds, reference):
    """The reference direction theta' of a signed anisotropy (rad).

    ``"stress"``/None for the major principal stress direction of the whole sample, an angle, or
    a DataArray over time.

    Parameters
    ----------
    {ds}
    reference : "stress", None, float or xarray.DataArray
        ``"stress"`` or None: :func:`grainview.analysis.stress.stress_direction`; a number: a fixed angle
        in rad; a DataArray: the direction over time, rad.

    Returns
    -------
    xarray.DataArray or float
        theta', rad.

    Raises
    ------
    grainview.contract.errors.ParameterError
        For any other ``reference``.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. a' (theta'); docs/conventions.md §2 and §3, "Signs".
    """
    if reference is None or (isinstance(reference, str) and reference == "stress"):
        return stress_direction(ds)
    if isinstance(reference, (int, float, np.floating)):
        return float(reference)
    if isinstance(reference, xr.DataArray):
        return reference
    raise ParameterError(f"reference={reference!r}: expected 'stress', an angle in rad or a DataArray")


@fill_doc
def fabric_anisotropy(ds: xr.Dataset, kind="all", walls: bool = False, reference="stress", near=None) -> xr.Dataset:
    """Fabric anisotropy a = 2 (F_1 - F_2), theta_F and the signed a' (paper Eq. a').

        a = 2 (F_1 - F_2),    a' = a cos 2(theta_F - theta')

    F_1 >= F_2 the principal values of F (:func:`fabric_tensor`), theta_F its major direction
    and theta' the ``reference`` direction: ``"stress"`` (default, the major principal stress
    direction of the whole sample, docs/conventions.md §3, "Signs"), a fixed angle in rad, or a
    DataArray over time. For a partial tensor (kind simple/double) the anisotropies a_s, a'_s
    are those of F_s, whose trace is k_s (paper Fig. 22).

    Parameters
    ----------
    {ds}
    {kind}
    {walls}
    reference : "stress", float or xarray.DataArray, default "stress"
        The reference direction theta' (rad): ``"stress"`` (or None) the major principal stress
        direction of the whole sample (docs/conventions.md §3, "Signs"), a fixed angle in rad,
        or a DataArray over time.
    {near}

    Returns
    -------
    xarray.Dataset
        Over ``time``: ``a`` and ``a_prime`` (dimensionless) and ``theta_F`` (rad); lazy on
        dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eqs. F and a' (Sec. IV.B), Fig. 9 and, for the partial tensors, Fig. 22;
    docs/conventions.md §2.
    """
    f1, f2, theta = apply(principal, fabric_tensor(ds, kind, walls, near))
    ref = reference_direction(ds, reference)
    a_prime = signed_anisotropy(f1, f2, theta, ref, normalisation=1.0)
    return xr.Dataset({
        "a": with_attrs(2 * (f1 - f2), "a", "1", "fabric anisotropy a = 2 (F1 - F2)"),
        "a_prime": with_attrs(a_prime, "a_prime", "1", "signed fabric anisotropy a'"),
        "theta_F": with_attrs(theta, "theta_F", "rad", "major principal direction of the fabric"),
    })


@fill_doc
def orientation_pdf(ds: xr.Dataset, bins: int = 36, kind="all", walls: bool = False, near=None) -> xr.DataArray:
    """P(theta) (time, theta): density of contact-normal orientations on [0, pi), rad-1.

        P(theta_k) = N_c(theta_k) / (N_c dtheta),    dtheta = pi/bins

    N_c(theta_k) the number of selected contacts whose normal (folded into [0, pi)) falls in the
    sector centred on theta_k; normalised so that sum P dtheta = 1 (paper Fig. 8).

    Parameters
    ----------
    {ds}
    {bins}
    {kind}
    {walls}
    {near}

    Returns
    -------
    xarray.DataArray
        ``orientation_pdf`` (time, theta) in rad-1, with the sector centres as the coordinate
        ``theta`` (rad); lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. IV and Fig. 8; docs/conventions.md §0 and §2.
    """
    bins = check_bins(bins)
    mask = selection(ds, walls=walls, kind=kind, near=near)
    da = apply(_fabric.orientation_pdf, ds["normal"], mask, output_sizes={"theta": bins}, kwargs={"n_bins": bins},
               names=["orientation_pdf"],
               attrs={"units": "rad-1", "long_name": "probability density of contact orientations P(theta)"})
    return da.assign_coords(theta=theta_coord(bins))


def theta_coord(bins: int) -> xr.DataArray:
    """Centres theta_k = k pi/bins of the ``bins`` angular sectors, rad.

    Parameters
    ----------
    bins : int
        Number of sectors of [0, pi).

    Returns
    -------
    xarray.DataArray
        The centres along dimension ``theta``, in rad.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. fnft (Sec. V.A; the sectors S(theta) = [theta - dtheta/2, theta + dtheta/2]);
    docs/analysis.md, "Conventions worth knowing".
    """
    centres = np.arange(bins) * np.pi / bins
    return xr.DataArray(centres, dims="theta", attrs={"units": "rad", "long_name": "contact orientation theta"})


def check_bins(bins) -> int:
    """Validate a number of angular sectors (a positive integer).

    Parameters
    ----------
    bins : int
        Number of angular sectors.

    Returns
    -------
    int
        ``bins`` as a Python int.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``bins`` is not an integer >= 1.
    """
    if not isinstance(bins, (int, np.integer)) or bins < 1:
        raise ParameterError(f"bins={bins!r}: expected a positive integer number of angular sectors")
    return int(bins)
