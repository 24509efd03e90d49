"""Opening files of the data contract.

:func:`open_dataset` is the one way to read a grainview file: lazily (dask, chunked along
``time`` only), read-only, with trailing snapshots that a killed writer left incomplete
dropped, and with a clear :class:`~grainview.errors.FileFormatError` for anything that is not a
readable netCDF file.
"""

from __future__ import annotations

import os

import numpy as np
import xarray as xr

from .errors import FileFormatError, SchemaError
from .schema import SCHEMA_VERSION


def _check_version(ds, source):
    version = ds.attrs.get("grainview_schema_version")
    if version is None:
        return
    try:
        major = int(str(version).split(".")[0])
    except ValueError:
        raise SchemaError(f"global attribute grainview_schema_version={version!r} is not a version number", source)
    if major > int(SCHEMA_VERSION.split(".")[0]):
        raise SchemaError(
            f"file has schema version {version}, newer than this grainview understands "
            f"({SCHEMA_VERSION}); upgrade grainview", source)


def open_dataset(path, chunks: int | dict | None = "auto", validate: bool = False) -> xr.Dataset:
    """Open a grainview netCDF file.

    Parameters
    ----------
    path : str or path-like
    chunks : number of snapshots per dask chunk, ``"auto"`` (about 64 MiB per chunk of the
        largest variable), or ``None`` for eager numpy arrays. Only ``time`` is ever chunked:
        ``particle`` and ``contact`` stay whole in each chunk, as the analysis kernels need.
    validate : run :func:`grainview.validation.validate` before returning.

    The file is opened read-only and never modified. Trailing snapshots whose ``time`` is
    missing (a writer killed mid-snapshot) are dropped.
    """
    source = os.fspath(path)
    if not os.path.exists(source):
        raise FileFormatError(f"{source}: no such file")
    try:
        ds = xr.open_dataset(source, engine="netcdf4", chunks=None, cache=False,
                             decode_times=False, mask_and_scale=True)
    except (OSError, ValueError, RuntimeError, KeyError, TypeError) as exc:
        raise FileFormatError(f"{source}: not a readable netCDF file ({exc})") from exc
    _check_version(ds, source)
    if "time" in ds.dims and "time" in ds.variables:
        t = np.asarray(ds["time"].values)
        finite = np.flatnonzero(np.isfinite(t))
        n_complete = int(finite[-1] + 1) if finite.size else 0
        if n_complete < ds.sizes["time"]:
            ds = ds.isel(time=slice(0, n_complete))
    for name in ("xy", "wall"):
        if name in ds.coords and ds[name].dtype.kind in "SO":
            ds = ds.assign_coords({name: np.char.strip(ds[name].values.astype(str))})
    if chunks is not None and "time" in ds.dims:
        ds = ds.chunk(time_chunks(ds, chunks))
    ds.encoding["source"] = source
    if validate:
        from .validation import validate as _validate
        _validate(ds, source=source)
    return ds


def time_chunks(ds: xr.Dataset, chunks="auto") -> dict:
    """The chunking used by :func:`open_dataset`: ``time`` only, everything else whole."""
    if isinstance(chunks, dict):
        bad = [d for d in chunks if d != "time"]
        if bad:
            raise ValueError(f"only 'time' may be chunked, got chunks for {bad}")
        return {"time": chunks.get("time", -1)}
    if chunks == "auto":
        per_snapshot = max((v.dtype.itemsize * int(np.prod([ds.sizes[d] for d in v.dims if d != "time"] or [1]))
                            for v in ds.data_vars.values() if "time" in v.dims), default=1)
        return {"time": max(1, int(64 * 2**20 // per_snapshot))}
    return {"time": int(chunks)}
