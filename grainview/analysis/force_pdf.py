"""Probability density of normal forces f_n/<f_n> and its exponential tail (paper Sec. V.B,
Eq. strong, Figs. 14 and 23).

The forces of each snapshot are normalised by that snapshot's mean normal force <f_n> over the
contacts chosen by ``walls`` (all kinds, so that the pdfs of simple and double contacts share
one abscissa, as in the paper's Fig. 23). Contacts default to particle–particle ones
(``walls=False``). The paper reports ``pdf ~ exp(-alpha f_n/<f_n>)`` above the mean with
alpha ~0.74 for pentagons and ~1.4 for disks (:func:`strong_force_exponent`).
"""

from __future__ import annotations

import numpy as np
import xarray as xr

from ._lift import apply, with_attrs
from .arrays import force_pdf as _pdf
from .contacts import kind_code, selection
from .snapshots import select_snapshots
from ..contract.errors import ParameterError
from ._docs import fill_doc

__all__ = ["force_pdf", "pooled_force_pdf", "pool_force_pdf", "strong_force_exponent", "strong_force_prefactor", "counting_error"]

SCALES = ("log", "linear")
DEFAULT_RANGE = {"linear": (0.0, 10.0), "log": (1e-4, 10.0)}
"""Default range of f_n/<f_n> per scale: an exponential tail exp(-alpha f/<f>) with
alpha = 0.74 leaves a fraction of about exp(-7.4), one contact in 1600, above 10."""


def _check(bins, scale, value_range):
    if isinstance(bins, bool) or not isinstance(bins, (int, np.integer)) or bins < 1:
        raise ParameterError(f"bins={bins!r}: expected a positive integer number of bins")
    if scale not in SCALES:
        raise ParameterError(f"scale={scale!r}: expected 'log' or 'linear'")
    value_range = DEFAULT_RANGE[scale] if value_range is None else value_range
    try:
        low, high = (float(v) for v in value_range)
    except (TypeError, ValueError):
        raise ParameterError(f"range={value_range!r}: expected a pair (low, high) of numbers") from None
    if not (np.isfinite(low) and np.isfinite(high) and low < high):
        raise ParameterError(f"range={value_range!r}: expected finite low < high")
    if scale == "log" and low <= 0:
        raise ParameterError(f"range={value_range!r}: log-spaced bins need low > 0")
    return int(bins), scale, (low, high)


def _histogram(ds, bins, scale, value_range, kind, walls, near=None):
    """Lazy per-snapshot counts, selected-contact counts and zero-force counts, and the edges."""
    bins, scale, value_range = _check(bins, scale, value_range)
    kind_code(kind)  # validates
    edges = _pdf.bin_edges(bins, scale, value_range)
    counts, n_selected, n_zero = apply(
        _pdf.force_histogram, ds["fn"], selection(ds, walls=walls, kind=kind, near=near), selection(ds, walls=walls, near=near),
        output_sizes={"bin": bins},
        kwargs={"edges": edges}, output_dtypes=[np.int64, np.int64, np.int64])
    return counts, n_selected, n_zero, edges, scale


def _pdf_dataset(counts, n_selected, n_zero, edges, scale, attrs):
    """The pdf and its bookkeeping from counts (lazy when the counts are)."""
    width = xr.DataArray(np.diff(edges), dims="bin")
    in_bins = counts.sum("bin")
    n_selected_or_nan = n_selected.where(n_selected > 0)  # 0/0 gives NaN without a warning
    pdf = counts / (in_bins * width).where(in_bins > 0)
    ds = xr.Dataset({
        "pdf": with_attrs(pdf, "pdf", "1", "probability density of f_n/<f_n>",
                          comment="count / (number of contacts in the bins * bin width): "
                                  "integrates to 1 over the bins"),
        "count": with_attrs(counts, "count", "1", "number of contacts per bin"),
        "n_contacts": with_attrs(n_selected, "n_contacts", "1", "number of selected contacts"),
        "zero_fraction": with_attrs(n_zero / n_selected_or_nan, "zero_fraction", "1",
                                    "fraction of the selected contacts with f_n <= 0 "
                                    "(never counted by log-spaced bins)"),
        "outside_fraction": with_attrs(1 - in_bins / n_selected_or_nan, "outside_fraction", "1",
                                       "fraction of the selected contacts in no bin "
                                       "(outside the range, or f_n <= 0 with log bins)"),
    })
    centres = _pdf.bin_centres(edges, scale)
    ds = ds.assign_coords(
        f_over_mean=("bin", centres, {"units": "1", "long_name": "normalised normal force f_n/<f_n>",
                                      "comment": "geometric bin centres" if scale == "log" else "bin centres"}),
        bin_edges=("edge", edges, {"units": "1", "long_name": "bin edges of f_n/<f_n>"}),
        bin_width=("bin", np.diff(edges), {"units": "1", "long_name": "bin width"}))
    ds.attrs.update(attrs, scale=scale)
    return ds


@fill_doc
def force_pdf(ds: xr.Dataset, bins: int = 50, scale: str = "log", range=None, kind="all",
              walls: bool = False, near=None) -> xr.Dataset:
    """P(f_n/<f_n>) per snapshot (time, bin), dimensionless (paper Fig. 14; Fig. 23 by kind).

        pdf = count / (N_in * width),    so that sum(pdf * bin_width) = 1

    Each snapshot's forces are divided by its mean normal force <f_n> over the contacts of
    ``walls`` (every kind); ``kind`` ("all", "simple", "double") chooses the contacts counted.
    The density follows ``np.histogram(density=True)``: N_in is the number of contacts that fall
    in a bin and ``width`` the bin width.

    Parameters
    ----------
    {ds}
    bins : int, default 50
        Number of bins (>= 1).
    scale : {"log", "linear"}, default "log"
        "log" (log-spaced bins, geometric centres; contacts with f_n <= 0 are skipped and
        reported by ``zero_fraction``) or "linear".
    range : (float, float), optional
        (low, high) of f_n/<f_n> (dimensionless); default (1e-4, 10) for log and (0, 10) for
        linear bins.
    kind : {"all", "simple", "double"}, default "all"
        The contacts counted (the mean <f_n> is always that of every kind).
    {walls}
    {near}

    Returns
    -------
    xarray.Dataset
        ``pdf`` and ``count`` (time, bin), ``n_contacts``, ``zero_fraction`` and
        ``outside_fraction`` (time), all dimensionless, and the coordinates ``f_over_mean`` (bin
        centres), ``bin_width`` and ``bin_edges`` (dim ``edge``); lazy on dask input.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V.B, Figs. 14 and 23.
    """
    counts, n_selected, n_zero, edges, scale = _histogram(ds, bins, scale, range, kind, walls, near)
    return _pdf_dataset(counts, n_selected, n_zero, edges, scale, {"kind": str(kind), "walls": int(walls)})


@fill_doc
def pooled_force_pdf(ds: xr.Dataset, bins: int = 50, scale: str = "log", range=None, kind="all",
                     walls: bool = False, near=None, time=None) -> xr.Dataset:
    """P(f_n/<f_n>) of the contacts of every snapshot of ``ds`` pooled (dims: bin).

    Each contact is normalised by the mean normal force of its own snapshot (as in
    :func:`force_pdf`); the counts of all snapshots are summed and the density taken from the
    sums. On dask input the result is lazy and computing it sums the counts one time-chunk at
    a time (a dask reduction), so the file is never loaded whole. ``time`` chooses the snapshots
    pooled, e.g. ``time="residual"`` for the residual state.

    Parameters
    ----------
    {ds}
    bins : int, default 50
        Number of bins (>= 1).
    scale : {"log", "linear"}, default "log"
        "log" (log-spaced bins, geometric centres; contacts with f_n <= 0 are skipped and
        reported by ``zero_fraction``) or "linear".
    range : (float, float), optional
        (low, high) of f_n/<f_n> (dimensionless); default (1e-4, 10) for log and (0, 10) for
        linear bins.
    kind : {"all", "simple", "double"}, default "all"
        The contacts counted (the mean <f_n> is always that of every kind).
    {walls}
    {near}
    time : str, int, slice or sequence of int, optional
        The snapshots pooled (:func:`grainview.analysis.snapshots.select_snapshots`): None or
        ``"all"`` (default) every snapshot, ``"residual"`` the residual state, eps_q >= 0.3 (for a
        run that stops short of it, the last part of the run; the boxes are read to find it), a
        snapshot index, a slice or a sequence of indices.

    Returns
    -------
    xarray.Dataset
        ``pdf`` and ``count`` (bin), ``n_contacts``, ``zero_fraction`` and
        ``outside_fraction`` (scalars), all dimensionless, and the coordinates ``f_over_mean`` (bin
        centres), ``bin_width`` and ``bin_edges`` (dim ``edge``); lazy on dask input.
        The attribute ``pooled_snapshots`` holds the number of snapshots pooled.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Sec. V.B, Figs. 14 and 23.
    """
    ds = select_snapshots(ds, time)
    counts, n_selected, n_zero, edges, scale = _histogram(ds, bins, scale, range, kind, walls, near)
    return _pdf_dataset(counts.sum("time"), n_selected.sum("time"), n_zero.sum("time"), edges, scale,
                        {"kind": str(kind), "walls": int(walls), "pooled_snapshots": int(ds.sizes["time"])})


def pool_force_pdf(pdf: xr.Dataset) -> xr.Dataset:
    """The pooled pdf of a per-snapshot :func:`force_pdf` result (dims time, bin): the counts
    of every snapshot summed and the density taken from the sums, as :func:`pooled_force_pdf`
    does from the contacts. It lets a pdf be pooled from per-snapshot counts kept on their own
    (a run's measures, one session at a time), without the contacts.

    Parameters
    ----------
    pdf : xarray.Dataset
        ``count`` (time, bin), ``n_contacts`` and ``zero_fraction`` (time), the coordinate
        ``bin_edges`` and the attribute ``scale`` of :func:`force_pdf`; other variables are
        ignored.

    Returns
    -------
    xarray.Dataset
        As :func:`pooled_force_pdf`.
    """
    missing = [name for name in ("count", "n_contacts", "zero_fraction", "bin_edges") if name not in pdf]
    if missing or "time" not in pdf["count"].dims or "scale" not in pdf.attrs:
        raise ParameterError(f"pdf lacks {missing or 'time or its scale'}: expected a per-snapshot result of force_pdf")
    n = pdf["n_contacts"]
    n_zero = (pdf["zero_fraction"].fillna(0.0) * n).round().astype(np.int64)
    attrs = {k: v for k, v in pdf.attrs.items() if k in ("kind", "walls")}
    return _pdf_dataset(pdf["count"].sum("time"), n.sum("time"), n_zero.sum("time"), pdf["bin_edges"].values,
                        pdf.attrs["scale"], {**attrs, "pooled_snapshots": int(pdf.sizes["time"])})


def strong_force_exponent(pdf: xr.Dataset, low: float = 1.0, high: float = np.inf) -> xr.DataArray:
    """alpha of the strong-force tail pdf ~ exp(-alpha f_n/<f_n>) (paper Eq. strong).

        ln pdf = c - alpha x,    x = f_n/<f_n>

    fitted on the bins of ``pdf`` (a result of :func:`force_pdf` or :func:`pooled_force_pdf`)
    whose centre x lies in (``low``, ``high``) (default: above the mean) and that hold at least
    one contact, by least squares weighted by the bin counts (the inverse variance of ln pdf).
    Use linear bins: with log bins the bin average of an exponential differs from its value at
    the geometric centre. The paper finds alpha ~0.74 (pentagons) and ~1.4 (disks).

    Parameters
    ----------
    pdf : xarray.Dataset
        The result of :func:`force_pdf` or :func:`pooled_force_pdf`.
    low, high : float, default 1.0 and inf
        The open interval of f_n/<f_n> (dimensionless) fitted; ``low < high``.

    Returns
    -------
    xarray.DataArray
        ``alpha``, dimensionless, over the remaining dims (time, or none for a pooled pdf); NaN
        with fewer than two usable bins.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``pdf`` is not such a Dataset, or ``low >= high``.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. strong (Sec. V.B), Figs. 14 and 23.
    """
    _check_pdf(pdf)
    if not low < high:
        raise ParameterError(f"low={low!r}, high={high!r}: expected low < high")
    counts = pdf["count"] if "count" in pdf else xr.ones_like(pdf["pdf"])
    alpha = xr.apply_ufunc(_pdf.exponential_fit, pdf["f_over_mean"], pdf["pdf"], counts,
                           input_core_dims=[["bin"]] * 3, kwargs={"low": low, "high": high},
                           dask="parallelized", output_dtypes=[float])
    return with_attrs(alpha, "alpha", "1", "exponent of the strong-force pdf ~ exp(-alpha f_n/<f_n>)")


def _check_pdf(pdf):
    if not isinstance(pdf, xr.Dataset) or "pdf" not in pdf or "f_over_mean" not in pdf.coords:
        raise ParameterError("pdf: expected the Dataset returned by force_pdf or pooled_force_pdf")


def strong_force_prefactor(pdf: xr.Dataset, alpha=None, low: float = 1.0, high: float = np.inf) -> xr.DataArray:
    """A of the strong-force tail pdf ~ A exp(-alpha f_n/<f_n>): the intercept of the fit of
    :func:`strong_force_exponent`.

        ln A = sum_k n_k (ln pdf_k + alpha x_k) / sum_k n_k,    x_k = f_n/<f_n> of bin k,

    over the bins with ``low < x_k < high`` that hold contacts, n_k their counts (weights 1
    when ``pdf`` has no ``count``): for the fitted alpha, the weighted least squares intercept.

    Parameters
    ----------
    pdf : xarray.Dataset
        The result of :func:`force_pdf` or :func:`pooled_force_pdf`.
    alpha : float or xarray.DataArray, optional
        The exponent, dimensionless (default: :func:`strong_force_exponent` of ``pdf`` over the
        same bins).
    low, high : float, default 1.0 and inf
        The open interval of f_n/<f_n> (dimensionless) used; ``low < high``.

    Returns
    -------
    xarray.DataArray
        ``prefactor`` A, in the units of the pdf (dimensionless), over the remaining dims; NaN
        without a usable bin or with a non-finite alpha.

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``pdf`` is not such a Dataset, or ``low >= high``.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Eq. strong (Sec. V.B) and Fig. 14.
    """
    _check_pdf(pdf)
    if not low < high:
        raise ParameterError(f"low={low!r}, high={high!r}: expected low < high")
    if alpha is None:
        alpha = strong_force_exponent(pdf, low, high)
    counts = pdf["count"] if "count" in pdf else xr.ones_like(pdf["pdf"])
    prefactor = xr.apply_ufunc(_pdf.exponential_prefactor, pdf["f_over_mean"], pdf["pdf"], counts, alpha,
                               input_core_dims=[["bin"]] * 3 + [[]], kwargs={"low": low, "high": high},
                               dask="parallelized", output_dtypes=[float])
    return with_attrs(prefactor, "prefactor", "1", "prefactor A of the strong-force pdf ~ A exp(-alpha f_n/<f_n>)")


def counting_error(pdf: xr.Dataset) -> xr.DataArray:
    """One standard deviation of each bin of a pdf from counting statistics (Poisson).

    A bin holding n contacts has P = n / (N width) and

        sigma_P = sqrt(n) / (N width) = P / sqrt(n).

    NaN where the bin is empty or the counts are not known. Contacts pooled over successive
    snapshots are counted as independent; a contact that lasts across snapshots is counted in
    each, so with closely spaced snapshots these errors are a lower bound.

    Parameters
    ----------
    pdf : xarray.Dataset
        The result of :func:`force_pdf` or :func:`pooled_force_pdf` (``pdf`` and ``count``).

    Returns
    -------
    xarray.DataArray
        ``pdf_error``, sigma_P per bin, in the units of the pdf (dimensionless).

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``pdf`` is not such a Dataset.

    References
    ----------
    Azéma, Radjai, Peyroux & Saussine, Phys. Rev. E 76, 011301 (2007),
    Fig. 14 (Sec. V.B).
    """
    _check_pdf(pdf)
    counts = pdf["count"] if "count" in pdf else xr.zeros_like(pdf["pdf"])
    error = xr.apply_ufunc(_pdf.counting_error, pdf["pdf"], counts, dask="parallelized", output_dtypes=[float])
    return with_attrs(error, "pdf_error", "1", "counting error of the pdf, P / sqrt(n)")

