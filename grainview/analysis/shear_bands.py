"""Shear bands in a coarse-grained field: profiles along any direction (averages over parallel
lines of a given orientation, against the distance along their normal) and the band finder
(the strip of lines that carries the largest excess share of the shear rate, and the width at
half maximum of its profile); docs/analysis.md, "Coarse-grained fields".

Orientation: a line at angle theta (degrees, counterclockwise from the x axis, in [0, 180)) has
the unit normal n = (-sin theta, cos theta); a node r = (x, y) lies on the line at signed
distance s = r . n = -x sin theta + y cos theta (m) from the origin. theta = 0 gives the
profile across y (averages over x), theta = 90 the profile across x, reversed. The arithmetic
on the grid's arrays is :mod:`grainview.analysis.arrays.shear_bands`'.
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ..contract.errors import ParameterError
from .arrays.shear_bands import binned_mean, half_maximum, node_bins, normal_distance, strongest_strip

__all__ = ["profile_along", "find_shear_band", "normal_distance", "DEFAULT_ANGLES", "DEFAULT_CONTRAST",
           "DEFAULT_STRIP_CELLS"]

DEFAULT_ANGLES = np.arange(0.0, 180.0, 1.0)
"""The orientations :func:`find_shear_band` tries by default: every degree in [0, 180)."""

DEFAULT_CONTRAST = 2.0
"""A band is reported when its strip shears at least this many times faster than the rest."""

DEFAULT_STRIP_CELLS = 6
"""The default strip width, in grid spacings: three kernel widths at coarse_grained's default
spacing (half a width), the narrowest band a kernel of that width resolves with its flanks."""


def _number(value, name, expected, low=0.0, strict=True):
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not np.isfinite(value) or (value <= low if strict else value < low):
        raise ParameterError(f"{name}={value!r}: expected {expected}")
    return float(value)


def _grid_of(field: xr.DataArray):
    if "x" not in field.dims or "y" not in field.dims:
        raise ParameterError(f"field over {field.dims}: expected a field over the grid's (y, x), "
                             "e.g. scalar_field(coarse_grained(ds), 'shear_rate')")
    x, y = np.asarray(field["x"].values, float), np.asarray(field["y"].values, float)
    return x, y


def _spacing_of(x, y):
    steps = np.concatenate([np.diff(x), np.diff(y)])
    if steps.size == 0:
        raise ParameterError("the field has a single grid node: expected a grid of several nodes")
    return float(steps.max())


def profile_along(field: xr.DataArray, angle: float, inside=None, bin_width=None) -> xr.DataArray:
    """A field averaged over parallel lines at ``angle``: its profile along their normal.

        <g>_theta(s_k) = (1/n_k) sum_{nodes r: |r . n - s_k| <= h/2} g(r),   s_k = k h,
        n = (-sin theta, cos theta)

    over the grid nodes where ``g`` is defined (NaN skipped), optionally only those of
    ``inside``; h = ``bin_width``. A band of the field along the lines shows as a peak of the
    profile (a shear band, in the shear rate). theta = 0 averages over x (the profile across y);
    theta = 90 over y (across x, s = -x).

    Parameters
    ----------
    field : xarray.DataArray
        A field over (..., y, x) with coordinates ``x``, ``y`` in m, e.g.
        ``scalar_field(coarse_grained(ds), "shear_rate")``.
    angle : float
        The lines' orientation theta, degrees counterclockwise from the x axis.
    inside : xarray.DataArray of bool, optional
        The nodes averaged (broadcast against ``field``), e.g. ``interior(fields)``.
    bin_width : float, optional
        h, m; default the grid's largest spacing.

    Returns
    -------
    xarray.DataArray
        The profile over (..., s), ``s`` the distance along the normal in m (bins with no node
        are NaN), in the field's units; attribute ``angle_deg``. Lazy when ``field`` is.

    Raises
    ------
    grainview.contract.errors.ParameterError
        For a field without the grid's (y, x), an angle or bin width that is not a (positive)
        number.

    References
    ----------
    docs/analysis.md, "Coarse-grained fields".
    """
    x, y = _grid_of(field)
    angle = _number(angle, "angle", "an orientation in degrees", low=-np.inf)
    h = _spacing_of(x, y) if bin_width is None else _number(bin_width, "bin_width", "a bin width > 0 in m")
    k, k0, k1 = node_bins(x, y, angle, h)
    n_bins = k1 - k0 + 1
    values = field if inside is None else field.where(inside)
    out = xr.apply_ufunc(binned_mean, values.transpose(..., "y", "x"), input_core_dims=[["y", "x"]],
                         output_core_dims=[["s"]], kwargs={"k": k, "k0": k0, "n_bins": n_bins},
                         dask="parallelized", output_dtypes=[float],
                         dask_gufunc_kwargs={"output_sizes": {"s": n_bins}})
    out = out.assign_coords(s=("s", np.arange(k0, k1 + 1) * h,
                               {"units": "m", "long_name": f"distance along the normal of lines at {angle:g} deg"}))
    out.attrs = dict(field.attrs)
    out.attrs["angle_deg"] = angle
    if "long_name" in out.attrs:
        out.attrs["long_name"] = f"{out.attrs['long_name']}, averaged along lines at {angle:g} deg"
    return out.rename(field.name)


def find_shear_band(rate: xr.DataArray, inside=None, width=None, angles=None, contrast: float = DEFAULT_CONTRAST,
                    bin_width=None) -> xr.Dataset:
    """The shear band of a shear-rate map: the strip of lines that carries the largest excess
    share of the shear rate, and the width at half maximum of its profile.

    For each orientation theta of ``angles`` the nodes are binned by their distance
    s = -x sin theta + y cos theta along the normal (bins of h, as :func:`profile_along`); a
    strip is m = round(W / h) consecutive bins (W = ``width``). With the sums over the nodes of
    ``inside`` where the rate is defined,

        share S = sum_strip gamma_dot / sum gamma_dot,     area a = n_strip / n,
        excess  X = S - a

    (X = 0 for every strip of a uniform rate). The band is the strip of largest X over every
    orientation and offset; reported with

        contrast C = <gamma_dot>_strip / <gamma_dot>_rest = S (1 - a) / ((1 - S) a)

    and the full width at half maximum of its orientation's profile <gamma_dot>_theta(s): the
    distance between the two crossings, either side of the profile's highest bin within the
    strip, of the level half-way between that peak and the profile's median (linear
    interpolation between bins). A band is **found** when C >= ``contrast`` and the profile falls
    below the half level on both sides inside the sample; otherwise angle, offset and widths are
    still reported, ``found`` is False.

    Parameters
    ----------
    rate : xarray.DataArray
        A map over (y, x) (coordinates in m), e.g. the shear rate of the mean flow over a strain
        window, ``scalar_field(fields.mean("time"), "shear_rate")``; any non-negative field.
    inside : xarray.DataArray of bool, optional
        The nodes considered (over (y, x)), e.g. ``interior(fields).all("time")``.
    width : float, optional
        The strip width W, m; default :data:`DEFAULT_STRIP_CELLS` bins.
    angles : array_like, optional
        Orientations tried, degrees from the x axis; default every degree of [0, 180).
    contrast : float, default 2
        The contrast C a band must reach.
    bin_width : float, optional
        h, m; default the grid's largest spacing.

    Returns
    -------
    xarray.Dataset
        Scalars ``found`` (bool), ``angle`` (deg from the x axis, the lines' orientation),
        ``offset`` (m: the strip's centre line, s = offset), ``strip_width`` (m: m h),
        ``share`` S, ``area_fraction`` a, ``excess`` X, ``contrast`` C, ``inside_ratio`` and
        ``outside_ratio`` (the strip's and the rest's mean rate over the mean, 1), ``fwhm``
        (m; NaN when a side never falls to the half level), ``edges`` (edge: 2; m) the two
        crossings (the band lies between the lines s = edges), and ``profile`` over ``s`` (m): the
        profile at the band's orientation, in the rate's units.

    Raises
    ------
    grainview.contract.errors.ParameterError
        For a map over other dimensions than (y, x), a negative rate, no node with a value,
        or a width, contrast, angle or bin width that is not a positive number.

    References
    ----------
    docs/analysis.md, "Coarse-grained fields".
    """
    x, y = _grid_of(rate)
    if set(rate.dims) != {"y", "x"}:
        raise ParameterError(f"rate over {rate.dims}: expected one map over (y, x); average or select the "
                             "other dimensions first (e.g. the window's mean flow)")
    h = _spacing_of(x, y) if bin_width is None else _number(bin_width, "bin_width", "a bin width > 0 in m")
    m = DEFAULT_STRIP_CELLS if width is None else max(1, int(round(
        _number(width, "width", "a strip width > 0 in m") / h)))
    contrast = _number(contrast, "contrast", "a ratio > 0")
    angles = DEFAULT_ANGLES if angles is None else np.atleast_1d(np.asarray(angles, float))
    if angles.ndim != 1 or not angles.size or not np.all(np.isfinite(angles)):
        raise ParameterError(f"angles={angles!r}: expected finite orientations in degrees")
    values = rate if inside is None else rate.where(inside)
    g = np.asarray(values.transpose("y", "x").values, float)
    ok = np.isfinite(g)
    if not ok.any():
        raise ParameterError("rate: no node with a value (inside= leaves none?)")
    if np.any(g[ok] < 0):
        raise ParameterError("rate: negative values; expected a shear rate (>= 0)")
    total, n = g[ok].sum(), ok.sum()
    best = strongest_strip(g, x, y, angles, h, m)
    if best is None:
        raise ParameterError(f"width={width!r}: expected a strip narrower than the grid")
    excess, angle, j, k0, strip_sum, strip_n = best
    share, area = strip_sum / total, strip_n / n
    mean = total / n
    inside_ratio = strip_sum / strip_n / mean
    outside_ratio = (total - strip_sum) / (n - strip_n) / mean if n > strip_n else np.nan
    c = inside_ratio / outside_ratio if outside_ratio > 0 else np.inf
    offset = (k0 + j + (m - 1) / 2) * h
    prof = profile_along(rate, angle, inside=inside, bin_width=h)
    p, s = np.asarray(prof.values, float), np.asarray(prof["s"].values, float)
    first = int(np.argmin(np.abs(s - (k0 + j) * h)))
    strip = p[first:first + m]
    peak = first + int(np.nanargmax(strip)) if np.isfinite(strip).any() else first
    lo, hi, level = half_maximum(s, p, peak)
    fwhm = hi - lo
    found = bool(c >= contrast and np.isfinite(fwhm))
    scalar = lambda v, units, long_name: xr.DataArray(v, attrs={"units": units, "long_name": long_name})  # noqa: E731
    return xr.Dataset({
        "found": xr.DataArray(found, attrs={"long_name": f"contrast >= {contrast:g} and a half-maximum width"}),
        "angle": scalar(angle, "deg", "orientation of the band's lines, counterclockwise from the x axis"),
        "offset": scalar(offset, "m", "the strip's centre line: -x sin(angle) + y cos(angle) = offset"),
        "strip_width": scalar(m * h, "m", "width of the strip searched"),
        "share": scalar(share, "1", "the strip's share of the summed rate"),
        "area_fraction": scalar(area, "1", "the strip's share of the nodes"),
        "excess": scalar(excess, "1", "share - area_fraction"),
        "contrast": scalar(c, "1", "mean rate in the strip / mean rate outside it"),
        "inside_ratio": scalar(inside_ratio, "1", "mean rate in the strip / mean rate"),
        "outside_ratio": scalar(outside_ratio, "1", "mean rate outside the strip / mean rate"),
        "fwhm": scalar(fwhm, "m", "full width at half maximum of the profile at the band's angle"),
        "half_maximum": scalar(level, rate.attrs.get("units", ""), "the profile's half level"),
        "edges": xr.DataArray([lo, hi], dims="edge", attrs={
            "units": "m", "long_name": "the half-maximum crossings: the band between the lines s = edges"}),
        "profile": prof,
    }, attrs={"contrast_required": contrast, "bin_width_m": h})
