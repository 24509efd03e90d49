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
from .errors import ParameterError
from .stress import stress_direction


def fabric_tensor(ds: xr.Dataset, kind="all", walls: bool = False, near=None) -> xr.DataArray:
    """F (time, xy_a, xy_b) = (1/N_c) sum_c n (x) n, dimensionless, tr F = 1 (paper Eq. F).

    With ``kind="simple"`` or ``"double"`` the sum runs over that kind while N_c stays the
    count of all contacts, so F = F_s + F_d exactly (paper Eq. fabricsd). ``near``: which
    pairs are contacts (:func:`grainview.contacts.in_network`; default force-bearing only).
    """
    mask_all = selection(ds, walls=walls, near=near)
    mask = selection(ds, walls=walls, kind=kind, near=near)
    label = {None: "", 1: " of simple contacts", 2: " of double contacts"}[kind_code(kind)]
    return apply(_fabric.fabric_tensor, ds["normal"], mask, mask_all, names=["fabric"], attrs={"units": "1", "long_name": f"fabric tensor{label}"})


def reference_direction(ds, reference):
    """The reference direction theta' of a signed anisotropy (rad): ``"stress"``/None for the
    major principal stress direction of the whole sample, an angle, or a DataArray over time."""
    if reference is None or (isinstance(reference, str) and reference == "stress"):
        return stress_direction(ds)
    if isinstance(reference, (int, float, np.floating)):
        return float(reference)
    if isinstance(reference, xr.DataArray):
        return reference
    raise ParameterError(f"reference={reference!r}: expected 'stress', an angle in rad or a DataArray")


def fabric_anisotropy(ds: xr.Dataset, kind="all", walls: bool = False, reference="stress", near=None) -> xr.Dataset:
    """a = 2 (F_1 - F_2), theta_F and the signed a' = a cos 2(theta_F - theta') (paper Eq. a').

    ``reference`` is theta': ``"stress"`` (default, the major principal stress direction of
    the whole sample, docs/conventions.md §3, "Signs"), a fixed angle in rad, or a DataArray over time. For a
    partial tensor (kind simple/double) the anisotropies a_s, a'_s are those of F_s, whose
    trace is k_s (paper Fig. 22).
    """
    f1, f2, theta = apply(principal, fabric_tensor(ds, kind, walls, near))
    ref = reference_direction(ds, reference)
    a_prime = signed_anisotropy(f1, f2, theta, ref, normalisation=1.0)
    return xr.Dataset({
        "a": with_attrs(2 * (f1 - f2), "a", "1", "fabric anisotropy a = 2 (F1 - F2)"),
        "a_prime": with_attrs(a_prime, "a_prime", "1", "signed fabric anisotropy a'"),
        "theta_F": with_attrs(theta, "theta_F", "rad", "major principal direction of the fabric"),
    })


def orientation_pdf(ds: xr.Dataset, bins: int = 36, kind="all", walls: bool = False, near=None) -> xr.DataArray:
    """P(theta) (time, theta): density of contact-normal orientations on [0, pi), rad-1,
    normalised so that sum P dtheta = 1 (paper Fig. 8)."""
    bins = check_bins(bins)
    mask = selection(ds, walls=walls, kind=kind, near=near)
    da = apply(_fabric.orientation_pdf, ds["normal"], mask, output_sizes={"theta": bins}, kwargs={"n_bins": bins},
               names=["orientation_pdf"],
               attrs={"units": "rad-1", "long_name": "probability density of contact orientations P(theta)"})
    return da.assign_coords(theta=theta_coord(bins))


def theta_coord(bins: int) -> xr.DataArray:
    """Centres theta_k = k pi/bins of the ``bins`` angular sectors, rad."""
    centres = np.arange(bins) * np.pi / bins
    return xr.DataArray(centres, dims="theta", attrs={"units": "rad", "long_name": "contact orientation theta"})


def check_bins(bins) -> int:
    """Validate a number of angular sectors (a positive integer)."""
    if not isinstance(bins, (int, np.integer)) or bins < 1:
        raise ParameterError(f"bins={bins!r}: expected a positive integer number of angular sectors")
    return int(bins)
