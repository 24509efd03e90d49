"""Which snapshots a distribution is averaged over: the residual state, an index, a slice.

The figures and the report average a distribution (a pdf, an angular profile, the
xi-network's q(xi)/p) over a set of snapshots chosen by one argument ``time``
(:func:`select_snapshots`): by default the residual state, eps_q >= 0.3
(:func:`grainview.analysis.strain.residual_window`), or for a run that stops short of it the
last 30% of its shear strain. An export or a movie takes every n-th snapshot and the last
(:func:`snapshot_indices`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from ..contract.errors import ParameterError
from .strain import RESIDUAL_STRAIN, residual_window, strains
from ._docs import fill_doc


@dataclass(frozen=True)
class Residual:
    """A ``time`` selector: the residual state from eps_q >= ``start`` on
    (``time="residual"`` is ``Residual(RESIDUAL_STRAIN)``)."""

    start: float = RESIDUAL_STRAIN


SHORT_RUN_FRACTION = 0.3
"""A run short of the residual window averages the last 30% of its shear strain instead."""


@fill_doc
def select_snapshots(ds: xr.Dataset, time="residual", residual_strain: float = RESIDUAL_STRAIN) -> xr.Dataset:
    """The snapshots a distribution is averaged over.

    ``time``: an integer snapshot index (``-1`` the last); ``"residual"`` (or
    :class:`Residual`, to choose where it starts) the residual state,
    the snapshots with eps_q >= ``residual_strain`` (:func:`grainview.analysis.strain.residual_window`)
    or, for a run that stops short of it, those with eps_q >= 0.7 max eps_q; the window used
    is described in the result's attribute ``window``; ``"all"`` or None every snapshot; a
    slice or a sequence of indices.

    Parameters
    ----------
    {ds_short}
    time : str, int, slice, sequence of int or Residual, default "residual"
        The snapshots, as above.
    residual_strain : float, default 0.3
        Start (eps_q, dimensionless) of the residual state for ``time="residual"``.

    Returns
    -------
    xarray.Dataset
        ``ds`` along the chosen snapshots (lazy as ``ds``; ``"residual"`` reads the boxes to
        find the window).

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``time`` is none of these, or an index lies outside the run.
    """
    n = ds.sizes["time"]
    if time is None or (isinstance(time, str) and time == "all"):
        return ds
    if isinstance(time, str) and time == "residual":
        return residual_snapshots(ds, residual_strain)
    if isinstance(time, Residual):
        return residual_snapshots(ds, time.start)
    if isinstance(time, (int, np.integer)) and not isinstance(time, bool):
        if not -n <= time < n:
            raise ParameterError(f"time={time}: expected a snapshot index in [{-n}, {n})")
        return ds.isel(time=[int(time)])
    if isinstance(time, slice):
        return ds.isel(time=time)
    try:
        idx = np.asarray(time, dtype=int)
    except (TypeError, ValueError):
        idx = None
    if idx is None or idx.ndim != 1 or idx.size == 0 or (idx < -n).any() or (idx >= n).any():
        raise ParameterError(f"time={time!r}: expected 'residual', 'all', a snapshot index, a slice "
                             f"or a sequence of indices in [{-n}, {n})")
    return ds.isel(time=idx)


def residual_snapshots(ds: xr.Dataset, residual_strain: float = RESIDUAL_STRAIN) -> xr.Dataset:
    """The residual snapshots of ``ds`` (see :func:`select_snapshots`), with ``attrs["window"]``
    saying which window was used and whether the residual state was reached."""
    window = residual_window(ds, residual_strain)
    eps_q = strains(ds)["eps_q"].compute()
    if bool(window.any()):
        note = f"residual: eps_q >= {residual_strain:g} ({int(window.sum())} snapshots)"
    else:
        top = float(eps_q.max())
        window = eps_q >= (1 - SHORT_RUN_FRACTION) * top
        note = (f"residual eps_q >= {residual_strain:g} NOT reached: last {SHORT_RUN_FRACTION:.0%} of the run, "
                f"eps_q {(1 - SHORT_RUN_FRACTION) * top:.3f}-{top:.3f} ({int(window.sum())} snapshots)")
    out = ds.isel(time=np.flatnonzero(window.values))
    out.attrs = {**ds.attrs, "window": note}
    return out


def time_mean(da):
    """Average over the snapshots, NaN-aware, attributes kept; lazy as ``da`` (a result without
    ``time`` comes back unchanged)."""
    return da.mean("time", skipna=True, keep_attrs=True) if "time" in da.dims else da


def snapshot_indices(ds: xr.Dataset, every: int = 1) -> np.ndarray:
    """Indices 0, every, 2 every, ... of the snapshots an export writes or a movie draws (and
    always the last).

    Parameters
    ----------
    ds : xarray.Dataset
        A grainview dataset.
    every : int, default 1
        The step between the snapshots taken (>= 1).

    Returns
    -------
    numpy.ndarray
        Increasing snapshot indices, the last snapshot included (empty for no snapshot).

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``every`` is not an integer >= 1.
    """
    if isinstance(every, bool) or not isinstance(every, (int, np.integer)) or every < 1:
        raise ParameterError(f"every={every!r}: expected an integer >= 1")
    n = ds.sizes["time"]
    return np.unique(np.append(np.arange(0, n, every), n - 1)) if n else np.arange(0)
