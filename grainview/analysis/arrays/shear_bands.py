"""Shear bands on a coarse-grained map's arrays: each node's distance along the normal of
lines at an angle, the map averaged over the lines (a profile), the half-maximum crossings of a
profile and the strip of lines carrying the largest excess share of the map
(:mod:`grainview.analysis.shear_bands` lifts them to DataArrays; the definitions are there).
"""

from __future__ import annotations

import numpy as np

from .signature import core_dims

__all__ = ["normal_distance", "node_bins", "binned_mean", "half_maximum", "strongest_strip"]


def normal_distance(x, y, angle: float):
    """Signed distance s = -x sin(theta) + y cos(theta) (m) of the nodes (x, y) from the line
    through the origin at ``angle`` theta (degrees from the x axis).

    Parameters
    ----------
    x, y : array_like
        Coordinates, m (broadcast together).
    angle : float
        The lines' orientation theta, degrees counterclockwise from the x axis.

    Returns
    -------
    numpy.ndarray
        s, m.
    """
    t = np.radians(angle)
    return -np.asarray(x, float) * np.sin(t) + np.asarray(y, float) * np.cos(t)


def node_bins(x, y, angle, bin_width):
    """Each node's bin k = round(s / h) over (y, x) (int64, ``x`` (nx,) and ``y`` (ny,) the grid's
    coordinates, h = ``bin_width``), and the bins' range (k0, k1)."""
    s = normal_distance(x[None, :], y[:, None], angle)
    k = np.rint(s / bin_width).astype(np.int64)
    return k, int(k.min()), int(k.max())


@core_dims(("y", "x"), out=(("s",),))
def binned_mean(values, k, k0, n_bins):
    """Mean of ``values`` (..., y, x) over the nodes of each bin (NaN skipped): (..., n_bins)."""
    flat = values.reshape((-1, k.size))
    ok = np.isfinite(flat)
    # one bincount over (row, bin) pairs: each bin's sum in node order, the same bits on every
    # processor (a product with a one-hot matrix would sum in the order of the BLAS kernel)
    where = (np.arange(flat.shape[0])[:, None] * n_bins + (k.ravel() - k0)[None, :]).ravel()
    size = flat.shape[0] * n_bins
    sums = np.bincount(where, np.where(ok, flat, 0.0).ravel(), minlength=size).reshape(flat.shape[0], n_bins)
    counts = np.bincount(where, ok.ravel().astype(float), minlength=size).reshape(flat.shape[0], n_bins)
    sums = sums.reshape(values.shape[:-2] + (n_bins,))
    counts = counts.reshape(values.shape[:-2] + (n_bins,))
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(counts > 0, sums / np.where(counts > 0, counts, 1.0), np.nan)


def half_maximum(s, p, peak):
    """Distances of the half-maximum crossings either side of bin ``peak`` of the profile p(s)
    (linear interpolation), half-way between the peak and the profile's median; NaN where the
    profile stays above it to its end."""
    level = 0.5 * (p[peak] + np.nanmedian(p))
    ends = []
    for step in (-1, 1):
        k, found = peak, np.nan
        while 0 <= k + step < p.size and np.isfinite(p[k + step]):
            if p[k + step] < level:
                u = (p[k] - level) / (p[k] - p[k + step])
                found = s[k] + u * (s[k + step] - s[k])
                break
            k += step
        ends.append(found)
    return ends[0], ends[1], level



def strongest_strip(g, x, y, angles, bin_width, strip_bins):
    """The strip of ``strip_bins`` consecutive bins, over every orientation of ``angles``, whose
    share of the summed ``g`` most exceeds its share of the nodes (X = S - a,
    :func:`grainview.analysis.shear_bands.find_shear_band`).

    Parameters
    ----------
    g : numpy.ndarray
        The map over (y, x), NaN where undefined or left out.
    x, y : numpy.ndarray
        The grid's coordinates, m.
    angles : numpy.ndarray
        The orientations tried, degrees from the x axis.
    bin_width : float
        h, m.
    strip_bins : int
        The strip's width m in bins.

    Returns
    -------
    tuple or None
        (excess X, angle, the strip's first bin from k0, k0, the strip's sum of g, its node
        count) of the best strip (the first of the largest excess), or None when no orientation
        has ``strip_bins`` bins.
    """
    ok = np.isfinite(g)
    total, n = g[ok].sum(), ok.sum()
    m = strip_bins
    best = None
    for angle in angles:
        k, k0, k1 = node_bins(x, y, angle, bin_width)
        sums = np.bincount(k[ok] - k0, g[ok], minlength=k1 - k0 + 1)
        counts = np.bincount(k[ok] - k0, minlength=k1 - k0 + 1).astype(float)
        if sums.size < m:
            continue
        window = np.ones(m)
        strip_sum, strip_n = np.convolve(sums, window, "valid"), np.convolve(counts, window, "valid")
        excess = strip_sum / total - strip_n / n
        j = int(np.argmax(excess))
        if best is None or excess[j] > best[0]:
            best = (float(excess[j]), float(angle), j, k0, float(strip_sum[j]), float(strip_n[j]))
    return best
