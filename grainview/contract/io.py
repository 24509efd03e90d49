"""Opening files of the data contract.

:func:`open_dataset` is the one way to read a grainview file: lazily (dask, chunked along
``time`` only), read-only, with trailing snapshots that a killed writer left incomplete
dropped, and with a clear :class:`~grainview.contract.errors.FileFormatError` for anything that is not a
readable netCDF file.
"""

from __future__ import annotations

import functools
import os

from typing import TYPE_CHECKING

import numpy as np

from .errors import FileFormatError
from .file_checks import check_version, damaged_data, damaged_snapshots
from .netcdf3 import check_netcdf3_length
from .schema import complete_snapshots

if TYPE_CHECKING:
    import xarray as xr


REOPEN_ATTEMPTS = 3
"""How many times :func:`open_dataset` opens a file that is replaced while it is opened."""


@functools.cache
def _checked_store():
    """xarray's netCDF4 store, its variables' reads checked: a stored chunk the netCDF library
    refuses (a Fletcher-32 checksum that does not match, data that do not inflate) raises
    :class:`FileFormatError` naming the file and the variable in one line
    (:func:`grainview.contract.file_checks.damaged_data`) wherever it is read, eagerly or in
    a dask task, instead of a bare ``RuntimeError: NetCDF: HDF error``. The classes are made
    here, when a file is first opened (they import xarray), and are this module's attributes
    ``CheckedStore`` and ``CheckedArray`` (:func:`__getattr__`), so that pickle finds them by
    name: a dataset opened lazily can be sent to another process."""
    import xarray as xr
    from xarray.backends.netCDF4_ import NetCDF4ArrayWrapper, NetCDF4DataStore
    from xarray.core import indexing

    class CheckedArray(NetCDF4ArrayWrapper):
        __slots__ = ()

        def _getitem(self, key):
            try:
                return super()._getitem(key)
            except RuntimeError as exc:
                raise damaged_data(self.datastore.source, self.variable_name, exc) from exc

    class CheckedStore(NetCDF4DataStore):
        source = None
        CheckedArray = None  # set below

        def open_store_variable(self, name, var):
            variable = super().open_store_variable(name, var)
            data = indexing.LazilyIndexedArray(CheckedArray(name, self))
            return xr.Variable(variable.dims, data, variable.attrs, variable.encoding)

    for cls in (CheckedArray, CheckedStore):
        cls.__module__, cls.__qualname__ = __name__, cls.__name__
    CheckedStore.CheckedArray = CheckedArray
    return CheckedStore


def __getattr__(name):
    """``CheckedStore`` and ``CheckedArray``, made on first use (:func:`_checked_store`)."""
    if name == "CheckedStore":
        return _checked_store()
    if name == "CheckedArray":
        return _checked_store().CheckedArray
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _open(source):
    """The dataset of ``source`` (not chunked), its snapshots' ``complete`` mask (None
    without ``time``) and the function that closes the file. netCDF-C reads a file's format
    and then opens it again by its name: a finished run compressed in between (renamed over
    the name) fails as "Unknown file format". A failure on a file whose name now points to
    another file is therefore tried again."""
    import xarray as xr

    for attempt in range(REOPEN_ATTEMPTS):
        before = os.stat(source)
        try:
            check_netcdf3_length(source)
            store = _checked_store().open(source, mode="r")
            store.source = source
            try:
                ds = xr.open_dataset(store, chunks=None, cache=False, decode_times=False, mask_and_scale=True)
                complete = complete_snapshots(ds.variables) if "time" in ds.variables and "time" in ds.dims else None
            except BaseException:
                store.close()
                raise
            return ds, complete, store.close
        except (OSError, ValueError, RuntimeError, KeyError, TypeError, IndexError) as exc:
            try:
                replaced = not os.path.samestat(before, os.stat(source))
            except OSError:
                replaced = False
            if replaced and attempt + 1 < REOPEN_ATTEMPTS:
                continue
            if isinstance(exc, FileFormatError):
                raise
            raise FileFormatError(f"{source}: not a readable netCDF file ({exc})") from exc


def open_dataset(path, chunks: int | dict | None = "auto", validate: bool = False) -> xr.Dataset:
    """Open a netCDF file of the data contract, lazily.

    The file is opened read-only and never modified; netCDF-3 (a run still going on or
    stopped) and compressed files (a finished run, docs/schema.md "Compression") read the
    same. Trailing snapshots whose ``time`` is missing or whose ``complete`` flag is not set
    (a writer killed mid-snapshot) are dropped. :func:`grainview.open_dataset` is this function
    for grainview files and also opens other codes' output (``format=``).

    Parameters
    ----------
    path : str or path-like
        A netCDF file of the data contract (docs/schema.md).
    chunks : int, "auto", dict or None, default "auto"
        Snapshots per dask chunk, ``"auto"`` (see :func:`time_chunks`), ``{"time": k}``, or
        ``None`` for eager numpy arrays. Only ``time`` is ever chunked: ``particle`` and
        ``contact`` stay whole in each chunk, as the analysis kernels need.
    validate : bool, default False
        Run :func:`grainview.contract.validation.validate` (every value) before returning.

    Returns
    -------
    xarray.Dataset
        The file's complete snapshots, with the ``ds.grain`` accessor.

    Raises
    ------
    FileFormatError
        No such file, not a readable netCDF file, a netCDF-3 file shorter than its header
        says, or an incomplete snapshot before complete ones (a damaged file).
    SchemaError
        A schema version newer than this grainview's, or (with ``validate``) any fault.
    """
    source = os.fspath(path)
    if not os.path.exists(source):
        raise FileFormatError(f"{source}: no such file")
    ds, complete, close = _open(source)  # close: the file's; a dataset made by assign_coords would not close it
    try:
        check_version(ds.attrs.get("grainview_schema_version"), source)
        if complete is not None:
            n_complete = damaged_snapshots(complete, source)
            if n_complete < ds.sizes["time"]:
                ds = ds.isel(time=slice(0, n_complete))
        for name in ("xy", "wall"):
            if name in ds.coords and ds[name].dtype.kind in "SO":
                ds = ds.assign_coords({name: np.char.strip(ds[name].values.astype(str))})
        if chunks is not None and "time" in ds.dims:
            ds = ds.chunk(time_chunks(ds, chunks))
        ds.encoding["source"] = source
        ds.set_close(close)
        if validate:
            from .validation import validate as _validate
            _validate(ds, source=source)
    except BaseException:
        close()
        raise
    return ds


MIN_CHUNK_SNAPSHOTS = 10
"""Smallest number of snapshots per chunk that ``chunks="auto"`` makes."""


def time_chunks(ds: xr.Dataset, chunks="auto") -> dict:
    """The chunking used by :func:`open_dataset`: ``time`` only, everything else whole.

    ``"auto"`` takes enough chunks to keep every core busy — about four per core, of at least
    :data:`MIN_CHUNK_SNAPSHOTS` snapshots (a chunk's overhead is a few ms) — and never more than
    64 MiB of the largest variable per chunk."""
    if isinstance(chunks, dict):
        bad = [d for d in chunks if d != "time"]
        if bad:
            raise ValueError(f"only 'time' may be chunked, got chunks for {bad}")
        return {"time": chunks.get("time", -1)}
    if chunks == "auto":
        per_snapshot = max((v.dtype.itemsize * int(np.prod([ds.sizes[d] for d in v.dims if d != "time"] or [1]))
                            for v in ds.data_vars.values() if "time" in v.dims), default=1)
        by_memory = max(1, int(64 * 2**20 // per_snapshot))
        by_cores = max(MIN_CHUNK_SNAPSHOTS, -(-ds.sizes["time"] // (4 * (os.cpu_count() or 1))))
        return {"time": min(by_memory, by_cores)}
    return {"time": int(chunks)}
