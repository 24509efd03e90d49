"""Distribution of normal forces normalised by their mean (paper Sec. V.B, Eq. strong, Fig. 14).

Histograms are taken per snapshot with one ``np.bincount`` for all snapshots at once
(:func:`grainview.analysis.arrays.binning.batched_bincount`), after locating every force in the bins
with ``np.searchsorted`` exactly as ``np.histogram`` does for explicit edges.
"""

from __future__ import annotations

import numpy as np

from ...contract import portable_math
from .binning import batched_bincount
from .signature import CONTACT, SCALAR, core_dims


def mean_normal_force(fn, mask):
    """<f_n> (...,) in N: the mean of ``fn`` over the contacts of ``mask`` (..., C); NaN where
    no contact is selected. Unselected slots may hold NaN."""
    mask = np.asarray(mask, bool)
    total = np.where(mask, fn, 0.0).sum(axis=-1)
    count = mask.sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return total / count


def bin_edges(n_bins, scale, value_range):
    """The ``n_bins + 1`` edges of the bins of f_n/<f_n>: evenly spaced (``scale="linear"``) or
    evenly spaced in log (``"log"``, needs ``0 < low``) over ``value_range = (low, high)``."""
    low, high = value_range
    if scale == "log":  # np.geomspace's edges, through the portable exp and log
        edges = portable_math.exp(np.linspace(portable_math.log(low), portable_math.log(high), n_bins + 1))
        edges[0], edges[-1] = low, high
        return edges
    return np.linspace(low, high, n_bins + 1)


def bin_centres(edges, scale):
    """Centres of the bins: arithmetic for linear bins, geometric sqrt(e_k e_k+1) for log bins."""
    edges = np.asarray(edges, float)
    if scale == "log":
        return np.sqrt(edges[:-1] * edges[1:])
    return 0.5 * (edges[:-1] + edges[1:])


def bin_index(values, edges):
    """Bin of each value by ``np.histogram``'s rule: bin k holds edges[k] <= x < edges[k+1], the
    last bin also holds x == edges[-1]. Values outside (or NaN) get -1 or ``len(edges) - 1``."""
    edges = np.asarray(edges, float)
    index = np.searchsorted(edges, values, side="right") - 1
    return np.where(values == edges[-1], edges.size - 2, index)


@core_dims(CONTACT, CONTACT, CONTACT, out=(("bin",), SCALAR, SCALAR))
def force_histogram(fn, mask, mean_mask, edges):
    """Counts of f_n/<f_n> per bin, per snapshot.

    ``fn`` (..., C) normal forces in N; ``mask`` (..., C) the contacts counted; ``mean_mask``
    (..., C) the contacts whose mean <f_n> normalises the forces (a superset of ``mask``, e.g.
    every kind when ``mask`` holds one kind). Returns ``(counts (..., n_bins), n_selected (...),
    n_zero (...))``: the histogram, the number of contacts of ``mask`` and how many of them
    carry f_n <= 0 (log bins cannot hold them).
    """
    mask = np.asarray(mask, bool)
    edges = np.asarray(edges, float)
    mean = mean_normal_force(fn, mean_mask)
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(mask, fn, np.nan) / mean[..., None]
    counts = batched_bincount(bin_index(ratio, edges), mask & np.isfinite(ratio), edges.size - 1)
    n_zero = (mask & ~(np.where(mask, fn, 1.0) > 0)).sum(axis=-1)
    return counts, mask.sum(axis=-1), n_zero


def density(counts, edges):
    """Probability density of each bin (..., n_bins): ``count / (total count * bin width)``, so
    that ``sum(pdf * width) = 1`` over the bins (``np.histogram(density=True)``); NaN when no
    contact falls in any bin."""
    counts = np.asarray(counts, float)
    width = np.diff(np.asarray(edges, float))
    with np.errstate(invalid="ignore", divide="ignore"):
        return counts / (counts.sum(axis=-1, keepdims=True) * width)


def exponential_fit(centres, pdf, counts, low=1.0, high=np.inf):
    """alpha of pdf ~ exp(-alpha x) fitted on the non-empty bins with ``low < x < high``.

    Weighted least squares of ``ln pdf = c - alpha x``, each bin weighted by its count (the
    inverse variance of ln pdf for Poisson counts). ``centres`` (n_bins,), ``pdf`` and
    ``counts`` (..., n_bins). Returns alpha (...); NaN with fewer than two usable bins.
    """
    x = np.asarray(centres, float)
    pdf = np.asarray(pdf, float)
    counts = np.asarray(counts, float)
    use = (x > low) & (x < high) & (counts > 0) & (pdf > 0) & np.isfinite(pdf)
    w = np.where(use, counts, 0.0)
    y = portable_math.log(np.where(use, pdf, 1.0))
    s, sx, sy = w.sum(-1), (w * x).sum(-1), (w * y).sum(-1)
    sxx, sxy = (w * x * x).sum(-1), (w * x * y).sum(-1)
    enough = use.sum(-1) >= 2
    with np.errstate(invalid="ignore", divide="ignore"):
        slope = (s * sxy - sx * sy) / (s * sxx - sx * sx)
    return np.where(enough, -slope, np.nan)


def exponential_prefactor(centres, pdf, counts, alpha, low=1.0, high=np.inf):
    """A of pdf ~ A exp(-alpha x) given alpha: the intercept of :func:`exponential_fit`'s line.

        ln A = sum_k n_k (ln pdf_k + alpha x_k) / sum_k n_k

    over the bins k with ``low < x_k < high`` that hold contacts (n_k > 0, pdf_k > 0): the
    count-weighted least squares intercept of ``ln pdf = ln A - alpha x`` for that slope.
    ``centres`` (n_bins,), ``pdf`` and ``counts`` (..., n_bins), ``alpha`` (...) or a number.
    Returns A (...), in the units of ``pdf``; NaN without a usable bin or with a non-finite alpha.
    """
    x = np.asarray(centres, float)
    pdf = np.asarray(pdf, float)
    counts = np.asarray(counts, float)
    alpha = np.asarray(alpha, float)
    use = (x > low) & (x < high) & (counts > 0) & (pdf > 0) & np.isfinite(pdf)
    w = np.where(use, counts, 0.0)
    y = portable_math.log(np.where(use, pdf, 1.0)) + alpha[..., None] * x
    total = w.sum(-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        log_a = (w * y).sum(-1) / total
    return np.where((total > 0) & np.isfinite(alpha), portable_math.exp(log_a), np.nan)


def counting_error(pdf, counts):
    """One standard deviation of each bin of a pdf from counting statistics (Poisson).

    A bin holding n contacts has P = n / (N width) and

        sigma_P = sqrt(n) / (N width) = P / sqrt(n);

    NaN where the bin is empty. ``pdf`` and ``counts`` (..., n_bins); returns sigma_P, in the
    units of ``pdf``.
    """
    pdf = np.asarray(pdf, float)
    counts = np.asarray(counts, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(counts > 0, pdf / np.sqrt(counts), np.nan)

