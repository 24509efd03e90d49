"""Lifting the pure array functions of :mod:`grainview.analysis.arrays` to labelled DataArrays.

One helper, :func:`apply`, wraps :func:`xarray.apply_ufunc` with ``dask="parallelized"`` so
that every topic module gets the same behaviour: the named core dimensions (``contact``,
``particle``, ``xy``...) are moved last and must be whole in each chunk, every other
dimension (``time``) is broadcast, and a dask-backed input gives a lazy result chunked like it.
The core dimensions of each array function are declared beside it
(:mod:`grainview.analysis.arrays.signature`), so a topic module names only the sizes that depend on
its call (the number of angular bins...).
"""

from __future__ import annotations

import xarray as xr

from .arrays.signature import SIZES, TENSOR

TENSOR_DIMS = TENSOR
"""Dimension names of a 2x2 tensor result; both have coordinates ("x", "y")."""


def apply(func, *args, core_dims=None, output_core_dims=None, output_sizes=None,
          output_dtypes=None, kwargs=None, attrs=None, names=None):
    """``xr.apply_ufunc(func, *args)`` over the core dims ``func`` declares, lazily over dask
    chunks.

    ``core_dims`` (one tuple per argument) and ``output_core_dims`` (one per output) default to
    the function's declaration (:func:`grainview.analysis.arrays.signature.core_dims`). Returns a
    DataArray, or a tuple of them when several outputs are declared; ``attrs`` and ``names``
    (one per output) are set on the results.
    """
    core_dims = func.core_dims if core_dims is None else core_dims
    output_core_dims = getattr(func, "output_core_dims", ((),)) if output_core_dims is None else output_core_dims
    if len(core_dims) != len(args):
        raise TypeError(f"{getattr(func, '__name__', func)} declares {len(core_dims)} core-dim inputs, "
                        f"got {len(args)} arguments")
    sizes = {d: n for d, n in SIZES.items() if any(d in dims for dims in output_core_dims)}
    sizes.update(output_sizes or {})
    output_sizes = sizes
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


def ratio(num, den):
    """``num / den``, NaN where ``den`` is 0: a snapshot with no contacts (p = 0, a zero trace)
    gives NaN and no floating-point warning, also when dask computes it later, outside any
    ``np.errstate`` (xarray silences the warning only when it divides eagerly)."""
    return num / den.where(den != 0)


def with_attrs(da: xr.DataArray, name: str, units: str, long_name: str, **extra) -> xr.DataArray:
    """Name ``da`` and give it exactly these attributes: units, long_name and ``extra`` (any
    attribute it carried over from its inputs is dropped: it described something else)."""
    da = da.rename(name)
    da.attrs = {"units": units, "long_name": long_name, **extra}
    return da


__all__ = ["apply", "ratio", "with_attrs", "TENSOR_DIMS"]
