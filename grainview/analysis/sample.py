"""The sample: its box (width l, height h and volume V of each snapshot) and its particles'
shapes (which are regular polygons, one name for them all)."""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import with_attrs
from ..contract.shapes import particle_area_of, regular_polygons
from ._docs import fill_doc

__all__ = ["thickness", "width", "height", "volume", "solid_fraction", "area", "regular_of", "shape_name"]


@fill_doc
def thickness(ds: xr.Dataset) -> float:
    """Slab thickness of the 2D sample in m (global attribute ``thickness_m``, default 1).

    Parameters
    ----------
    {ds_short}

    Returns
    -------
    float
        The thickness t, m.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III and Eq. 3 (the 2D setting); docs/conventions.md §0.
    """
    return float(ds.attrs.get("thickness_m", 1.0))


@fill_doc
def width(ds: xr.Dataset) -> xr.DataArray:
    """Box width l = x_max - x_min (m).

    Parameters
    ----------
    {ds}

    Returns
    -------
    xarray.DataArray
        ``width`` (time,) in m.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III (the horizontal strain eps_2); docs/conventions.md §6.
    """
    l = ds["box_max"].sel(xy="x") - ds["box_min"].sel(xy="x")
    return with_attrs(l.drop_vars("xy"), "width", "m", "sample width l")


@fill_doc
def height(ds: xr.Dataset) -> xr.DataArray:
    """Box height h = y_max - y_min (m).

    Parameters
    ----------
    {ds}

    Returns
    -------
    xarray.DataArray
        ``height`` (time,) in m.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III (the vertical strain eps_1); docs/conventions.md §6.
    """
    h = ds["box_max"].sel(xy="y") - ds["box_min"].sel(xy="y")
    return with_attrs(h.drop_vars("xy"), "height", "m", "sample height h")


@fill_doc
def volume(ds: xr.Dataset) -> xr.DataArray:
    """Sample volume V = l h times the slab thickness (m3); the V of the stress (docs/conventions.md §1).

        V = l h t

    Parameters
    ----------
    {ds}

    Returns
    -------
    xarray.DataArray
        ``volume`` (time,) in m3.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. M (Sec. III); docs/conventions.md §1.
    """
    return with_attrs(width(ds) * height(ds) * thickness(ds), "volume", "m3", "sample volume V")


@fill_doc
def solid_fraction(ds: xr.Dataset) -> xr.DataArray:
    """Solid fraction (time,): total particle area / box area l h.

        solid fraction = sum_i A_i / (l h)

    A_i the area of particle i, m2: pi R^2 for a disk, the shoelace area of a polygon's
    vertices (:func:`grainview.contract.shapes.particle_area`; the regular n-gon's
    (n/2) R^2 sin(2 pi/n) in a file without ``vertices``). The paper reports 0.80 for the
    pentagons S1 and 0.82 for the disks S2 (Sec. II.B). Particles outside the box are counted too.

    Parameters
    ----------
    {ds}

    Returns
    -------
    xarray.DataArray
        ``solid_fraction`` (time,), dimensionless.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. II.B.
    """
    solid = float(particle_area_of(ds).sum())
    return with_attrs(solid / area(ds), "solid_fraction", "1", "solid fraction")


@fill_doc
def area(ds: xr.Dataset) -> xr.DataArray:
    """Sample area l h (m2).

        A = l h

    Parameters
    ----------
    {ds}

    Returns
    -------
    xarray.DataArray
        ``area`` (time,) in m2.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. III (the V of the volumetric strain eps_p); docs/conventions.md §6.
    """
    return with_attrs(width(ds) * height(ds), "area", "m2", "sample area l h")


def regular_of(ds) -> np.ndarray:
    """(P,) bool: which particles of a dataset of the contract are regular polygons
    (:func:`grainview.contract.shapes.regular_polygons` of its ``vertices``, when it has them)."""
    n_vertices = np.asarray(ds["n_vertices"].values)
    if "vertices" not in ds.variables:  # the contract: without vertices, every polygon is regular
        return n_vertices >= 3
    return regular_polygons(ds["radius"].values, n_vertices, ds["vertices"].values)


def shape_name(ds) -> str:
    """One name for a sample's particles: "disk" (every particle a disk), "<n>-gon" (every one
    a regular n-gon), "irregular polygon" (every one a polygon, some irregular) or "mixed"
    (disks and polygons, or regular polygons of several vertex counts)."""
    n_vertices = np.asarray(ds["n_vertices"].values)
    if not n_vertices.any():
        return "disk"
    if not (n_vertices >= 3).all():
        return "mixed"
    regular = regular_of(ds)
    if not regular.all():
        return "irregular polygon"
    return f"{int(n_vertices[0])}-gon" if (n_vertices == n_vertices[0]).all() else "mixed"
