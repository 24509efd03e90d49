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

from .errors import FileFormatError, ParameterError, SchemaError
from .file_checks import damaged_snapshots, hidden_records
from .locks import being_written
from .schema import SCHEMA_VERSION, complete_snapshots
from .writer import netcdf3_data_bytes


def _header_reader():
    """scipy's netCDF-3 reader made to parse the header and the fixed-size variables only: the
    header's record count is kept as ``header_records`` and no record is mapped, so that a file
    whose last record is still being written (its count already raised, its bytes not all
    there) parses as well as a whole one. ``begins`` maps each variable to the offset of its
    data (of its first record, for a record variable)."""
    from scipy.io import netcdf_file

    class HeaderOnly(netcdf_file):
        def _read_numrecs(self):
            super()._read_numrecs()
            self.__dict__["header_records"] = self._recs
            self.__dict__["_recs"] = 0

        def _read_var(self):
            var = super()._read_var()
            self.__dict__.setdefault("begins", {})[var[0]] = var[7]  # the variable's first byte
            return var

    return HeaderOnly


def _check_netcdf3_length(path: str) -> None:
    """Raise FileFormatError when a netCDF-3 file is shorter than its header says.

    netCDF-3 readers return zeros for the missing bytes of a truncated file instead of
    failing, so the length is checked: header + fixed-size variables + records. While a
    writer holds the file (:func:`grainview.locks.being_written`) its last record may be
    short: it is being written (the writer raises the record count before all of the record's
    bytes reach the file); it reads with ``complete`` = 0 there, and :func:`open_dataset` drops
    it. The file is opened once, so that a file replaced meanwhile (a finished run being
    compressed) is checked whole.
    """
    with open(path, "rb") as fh:
        magic = fh.read(4)
        if magic[:3] != b"CDF" or magic[3:] not in (b"\x01", b"\x02"):
            return
        fh.seek(0)
        size = os.fstat(fh.fileno()).st_size
        try:
            nc = _header_reader()(fh, "r", mmap=False)
        except (ValueError, TypeError, OSError, IndexError) as exc:  # the header points beyond the end
            raise FileFormatError(f"{path}: truncated or damaged netCDF-3 file ({size} bytes): "
                                  f"its header describes data beyond its end ({exc})") from exc
        header = fh.tell()
        records = [v for v in nc.variables.values() if v.isrec]
        fixed, record_size = netcdf3_data_bytes(
            [v.data.nbytes for v in nc.variables.values() if not v.isrec],
            [v.itemsize() * int(np.prod(v.shape[1:], dtype=np.int64)) for v in records])
        n_records = nc.header_records if records else 0
        flags = None
        complete = nc.variables.get("complete")
        if complete is not None and complete.isrec and record_size:
            # the flag of every whole record the file's size holds beyond the counted ones
            beyond = max(0, (size - header - fixed - n_records * record_size) // record_size)
            flags = []
            for k in range(n_records, n_records + beyond):
                fh.seek(nc.begins["complete"] + k * record_size)
                flags.append(fh.read(1))
    needed = header + fixed + n_records * record_size
    if size < needed and n_records and being_written(path):
        needed -= record_size  # every record but the one being written
    if size < needed:
        raise FileFormatError(f"{path}: truncated file ({size} bytes, its header needs at least {needed})")
    hidden_records(path, size, header, fixed, record_size, n_records,  # nor longer by records it does not count
                   None if flags is None else [flag == b"\x01" for flag in flags])


REOPEN_ATTEMPTS = 3
"""How many times :func:`open_dataset` opens a file that is replaced while it is opened."""


def _open(source):
    """The dataset of ``source`` (not chunked) and its snapshots' ``complete`` mask (None
    without ``time``). netCDF-C reads a file's format and then opens it again by its name: a
    finished run compressed in between (renamed over the name) fails as "Unknown file format".
    A failure on a file whose name now points to another file is therefore tried again."""
    for attempt in range(REOPEN_ATTEMPTS):
        before = os.stat(source)
        try:
            _check_netcdf3_length(source)
            ds = xr.open_dataset(source, engine="netcdf4", chunks=None, cache=False,
                                 decode_times=False, mask_and_scale=True)
            complete = complete_snapshots(ds.variables) if "time" in ds.variables and "time" in ds.dims else None
            return ds, complete
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


def open_dataset(path, chunks: int | dict | None = "auto", validate: bool = False, format: str = "grainview",
                 **reader_options) -> xr.Dataset:
    """Open a grainview netCDF file, lazily; or another code's output, with ``format``.

    The file is opened read-only and never modified; netCDF-3 (a run still going on or
    stopped) and compressed files (a finished run, docs/schema.md "Compression") read the
    same. Trailing snapshots whose ``time`` is missing or whose ``complete`` flag is not set
    (a writer killed mid-snapshot) are dropped.

    Parameters
    ----------
    path : str or path-like
        A netCDF file of the data contract (docs/schema.md).
    chunks : int, "auto", dict or None, default "auto"
        Snapshots per dask chunk, ``"auto"`` (see :func:`time_chunks`), ``{"time": k}``, or
        ``None`` for eager numpy arrays. Only ``time`` is ever chunked: ``particle`` and
        ``contact`` stay whole in each chunk, as the analysis kernels need.
    validate : bool, default False
        Run :func:`grainview.validation.validate` (every value) before returning.
    format : str, default "grainview"
        ``"grainview"``: a netCDF file of the contract. Another code's output
        (:data:`grainview.formats.READERS`, docs/formats.md), read into memory and chunked as
        asked: ``"lammps"``, with ``path`` the particles' dump and ``contacts=``, ``walls=``,
        ``log=``, ``time_step=``... in ``reader_options``
        (:func:`grainview.formats.lammps.open_lammps`).
    **reader_options
        Passed on to the reader of ``format``.

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
    if format == "grainview" and reader_options:
        raise ParameterError(f"{', '.join(sorted(reader_options))}: options of another code's reader; give its "
                             "format (format='lammps', ...) or leave them out for a grainview file")
    if format != "grainview":
        from .formats import open_format

        ds = open_format(format, path, **reader_options)
        if chunks is not None:
            ds = ds.chunk(time_chunks(ds, chunks))
        if validate:
            from .validation import validate as check

            check(ds, source=os.fspath(path))
        return ds
    source = os.fspath(path)
    if not os.path.exists(source):
        raise FileFormatError(f"{source}: no such file")
    ds, complete = _open(source)
    _check_version(ds, source)
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
    if validate:
        from .validation import validate as _validate
        _validate(ds, source=source)
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
