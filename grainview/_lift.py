"""Lifting the pure array functions of :mod:`grainview.arrays` to labelled DataArrays.

One helper, :func:`apply`, wraps :func:`xarray.apply_ufunc` with ``dask="parallelized"`` so
that every topic module gets the same behaviour: the named core dimensions (``contact``,
``particle``, ``xy``...) are moved last and must be whole in each chunk, every other
dimension (``time``) is broadcast, and a dask-backed input gives a lazy result chunked like it.
"""

from __future__ import annotations

import xarray as xr

TENSOR_DIMS = ("xy_a", "xy_b")
"""Dimension names of a 2x2 tensor result; both have coordinates ("x", "y")."""


def apply(func, *args, core_dims, output_core_dims=((),), output_sizes=None,
          output_dtypes=None, kwargs=None, attrs=None, names=None):
    """``xr.apply_ufunc(func, *args)`` with core dims, lazily over dask chunks.

    ``core_dims`` lists the core dims of each argument; ``output_core_dims`` those of each
    output. Returns a DataArray, or a tuple of them when several outputs are declared;
    ``attrs`` and ``names`` (one per output) are set on the results.
    """
    n_out = len(output_core_dims)
    result = xr.apply_ufunc(
        func, *args,
        input_core_dims=[list(d) for d in core_dims],
        output_core_dims=[list(d) for d in output_core_dims],
        kwargs=kwargs or {},
        dask="parallelized",
        output_dtypes=output_dtypes or [float] * n_out,
        dask_gufunc_kwargs={"output_sizes": dict(output_sizes or {}), "allow_rechunk": False},
    )
    results = result if n_out > 1 else (result,)
    attrs = attrs if isinstance(attrs, (list, tuple)) else [attrs] * n_out
    names = names or [None] * n_out
    out = []
    for da, at, name in zip(results, attrs, names):
        if TENSOR_DIMS[0] in da.dims:
            da = da.assign_coords({d: list("xy") for d in TENSOR_DIMS})
        if at:
            da.attrs = dict(at)
        if name:
            da.name = name
        out.append(da)
    return tuple(out) if n_out > 1 else out[0]


def with_attrs(da: xr.DataArray, name: str, units: str, long_name: str, **extra) -> xr.DataArray:
    """Name ``da`` and give it exactly these attributes: units, long_name and ``extra`` (any
    attribute it carried over from its inputs is dropped: it described something else)."""
    da = da.rename(name)
    da.attrs = {"units": units, "long_name": long_name, **extra}
    return da


__all__ = ["apply", "with_attrs", "TENSOR_DIMS"]
