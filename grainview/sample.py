"""The sample box: width l, height h and volume V of each snapshot."""

from __future__ import annotations

import xarray as xr

from ._lift import with_attrs


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
    """Sample volume V = l h times the slab thickness (m3); the V of the stress (ERRATA 1)."""
    return with_attrs(width(ds) * height(ds) * thickness(ds), "volume", "m3", "sample volume V")


def area(ds: xr.Dataset) -> xr.DataArray:
    """Sample area l h (m2)."""
    return with_attrs(width(ds) * height(ds), "area", "m2", "sample area l h")
