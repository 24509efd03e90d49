"""The sample box: width l, height h and volume V of each snapshot."""

from __future__ import annotations

import xarray as xr

from ._lift import with_attrs
from .schema import particle_area


def thickness(ds: xr.Dataset) -> float:
    """Slab thickness of the 2D sample in m (global attribute ``thickness_m``, default 1)."""
    return float(ds.attrs.get("thickness_m", 1.0))


def width(ds: xr.Dataset) -> xr.DataArray:
    """Box width l = x_max - x_min (m)."""
    l = ds["box_max"].sel(xy="x") - ds["box_min"].sel(xy="x")
    return with_attrs(l.drop_vars("xy"), "width", "m", "sample width l")


def height(ds: xr.Dataset) -> xr.DataArray:
    """Box height h = y_max - y_min (m)."""
    h = ds["box_max"].sel(xy="y") - ds["box_min"].sel(xy="y")
    return with_attrs(h.drop_vars("xy"), "height", "m", "sample height h")


def volume(ds: xr.Dataset) -> xr.DataArray:
    """Sample volume V = l h times the slab thickness (m3); the V of the stress (docs/conventions.md §1)."""
    return with_attrs(width(ds) * height(ds) * thickness(ds), "volume", "m3", "sample volume V")


def solid_fraction(ds: xr.Dataset) -> xr.DataArray:
    """Solid fraction (time,): total particle area / box area l h (paper Sec. II.B: 0.80 for
    the pentagons S1, 0.82 for the disks S2). Particles outside the box are counted too."""
    solid = float(particle_area(ds["radius"].values, ds["n_vertices"].values).sum())
    return with_attrs(solid / area(ds), "solid_fraction", "1", "solid fraction")


def area(ds: xr.Dataset) -> xr.DataArray:
    """Sample area l h (m2)."""
    return with_attrs(width(ds) * height(ds), "area", "m2", "sample area l h")
