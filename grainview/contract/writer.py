"""Writing a netCDF file of the data contract snapshot by snapshot, safe against a killed run.

:class:`SnapshotWriter` is what the solver writes through (:mod:`solver.output`); it needs
netCDF4 and numpy only. The contract it writes is :mod:`grainview.contract.schema`. Any other
file (an export, a movie) is written under a temporary name and moved into place by
:func:`write_atomically`.
"""

from __future__ import annotations

import os

import numpy as np

from .cell import CELL_POSITIONS, CELL_VECTORS, cell_problems
from .errors import FileFormatError, GrainviewError, OutputError, ParameterError
from .locks import WriterLock, process_alive
from .schema import (CONTACT_VARIABLES, DEFAULT_WALL_NAMES, OPTIONAL_CONTACT_VARIABLES, REQUIRED, TIME_ATTRS,
                     VARIABLES, complete_snapshots, contact_slots, empty_slots, global_attrs, variable_attrs)
from .shapes import has_irregular_polygons, shape_problems

__all__ = ["SnapshotWriter", "compress_file", "decompress_file", "is_compressed", "check_complevel",
           "netcdf3_data_bytes", "lock_file", "remove_strays", "last_complete_value", "APPEND_FORMAT",
           "COMPRESSED_FORMAT", "DEFAULT_COMPLEVEL", "CHECKSUMS", "chunk_rows", "chunk_shape", "copy_blocks", "sample_blocks", "deflate_saving", "without_fill"]

APPEND_FORMAT = "NETCDF3_64BIT_OFFSET"
"""The format a run is written in while it goes on: its records are appended in place, so a
killed writer leaves every completed snapshot readable."""
COMPRESSED_FORMAT = "NETCDF4_CLASSIC"
"""The format a finished run is kept in: HDF5 storage with zlib, and the classic data model
(strings as character arrays, as in netCDF-3). Not variable-length strings: with them, this
project's netCDF4 1.7 / HDF5 2.2 can crash the interpreter when a file read before in the
same process is opened again (docs/schema.md)."""
DEFAULT_COMPLEVEL = 1
"""zlib level (1-9) of :func:`compress_file`: level 1 makes files within 2% of level 4's size and
inflates faster (benchmarks/results/compression.md)."""
CHECKSUMS = True
"""Whether a finished file's bytes are guarded: :func:`compress_file` (and
:func:`grainview.contract.dataset.netcdf_encoding` with ``zlib``) give every variable but the
scalars HDF5's Fletcher-32 filter, a checksum stored with each chunk that the library verifies
whenever it reads the chunk, so a changed byte is a read error rather than another number
(docs/schema.md, "Checksums"). netCDF-3 files (a run while it goes on) have none."""
COPY_BLOCK_BYTES = 8 * 2**20
"""At most this many bytes of one variable (whole chunks, at least one) are held in memory while
a file is converted."""
CHUNK_BYTES = 64 * 2**10
"""Target size of a compressed file's chunk along ``time``: a chunk holds one snapshot, or as many
as fit in this many bytes when one snapshot of the variable is smaller (see :func:`chunk_rows`)."""
MIN_SAVING = 0.4
"""A per-snapshot variable is deflated only when zlib saves at least this fraction of its bytes
(see :func:`deflate_saving`); data that compress less are stored as they are, since inflating
them costs the analyses more than the bytes saved (benchmarks/results/compression.md)."""


TEMPORARY_SUFFIXES = (".part", ".convert")
"""The hidden files ``.<name>.<pid><suffix>`` a file is written under before it is renamed
into place (:meth:`SnapshotWriter.create`, :func:`compress_file`, :func:`decompress_file`)."""

PID_DIGITS = 7
"""The most digits a process id has (Linux's pid_max is at most 2^22)."""

TEMPORARY_NAME_EXTRA = len("..") + PID_DIGITS + max(len(suffix) for suffix in TEMPORARY_SUFFIXES)
"""Bytes the temporary names add to a file's name: ``.<name>.<pid><suffix>`` (the lock's
``.<name>.writer``, grainview.contract.locks, adds fewer)."""


def _fsync(path: str) -> None:
    """Flush ``path`` (a file or a folder) to disk; a file system that cannot sync a folder is
    let be."""
    folder = os.path.isdir(path)
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        if folder:  # a system that cannot open a folder (Windows)
            return
        raise
    try:
        os.fsync(fd)
    except OSError:
        if not folder:
            raise
    finally:
        os.close(fd)


def _abandon(nc) -> None:
    """After a failed write or close (a full disk, a file-size limit), netCDF-C's close fails
    as well and leaves the handle half freed; netCDF4-python keeps it marked open and closes it
    again when the Dataset is finalised, which crashes the interpreter. One close that ignores
    the error (what the finaliser itself does) marks it closed."""
    closer = getattr(nc, "_close", None)
    if closer is not None and nc.isopen():
        try:
            closer(False)
        except (RuntimeError, OSError):
            pass


def _why(exc) -> str:
    """``exc``'s message, with the file-size limit (``ulimit -f``) when one is set: HDF5 reports
    a write beyond it only as "HDF error"."""
    try:
        import resource

        limit = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
    except (ImportError, OSError, ValueError):
        return str(exc)
    return str(exc) if limit == resource.RLIM_INFINITY else f"{exc}; the file-size limit, ulimit -f, is {limit} bytes"


def remove_strays(path) -> list[str]:
    """Remove the temporary files that killed processes left beside ``path`` (a creation or a
    conversion stopped by SIGKILL: ``.<name>.<pid>.part`` or ``.convert``). Only for a caller
    holding ``path``'s writer lock, and only files whose process is gone. Returns their names."""
    directory, base = os.path.split(os.path.abspath(os.fspath(path)))
    removed = []
    try:
        names = os.listdir(directory)
    except OSError:
        return removed
    for name in names:
        if not (name.startswith(f".{base}.") and name.endswith(TEMPORARY_SUFFIXES)):
            continue
        pid = name[len(base) + 2:].rsplit(".", 1)[0]
        if not pid.isdigit() or int(pid) == os.getpid() or process_alive(int(pid)):
            continue
        try:
            os.remove(os.path.join(directory, name))
            removed.append(name)
        except OSError:
            pass
    return removed


def lock_file(path) -> WriterLock:
    """Take the writer's lock of ``path`` (:class:`grainview.contract.locks.WriterLock`) and remove the
    temporary files killed writers left beside it (:func:`remove_strays`)."""
    lock = WriterLock(path)
    if lock.held:  # without locks (no fcntl) another process may be writing them
        remove_strays(path)
    return lock


def last_complete_value(path, name):
    """The value of variable ``name`` at the last complete snapshot of the file ``path`` (either
    format), or None when it has no complete snapshot or no such variable."""
    import netCDF4

    with netCDF4.Dataset(os.fspath(path)) as nc:
        nc.set_auto_mask(False)
        if name not in nc.variables:
            return None
        complete = np.flatnonzero(complete_snapshots(nc.variables))
        return nc.variables[name][complete[-1]].item() if complete.size else None


def _move_into_place(temporary: str, path: str, overwrite: bool) -> None:
    """Rename ``temporary`` to ``path`` atomically, the file synced to disk before and the
    folder after; without ``overwrite`` an existing ``path`` (even one created meanwhile by
    another process) is kept and FileExistsError raised."""
    _fsync(temporary)
    folder = os.path.dirname(os.path.abspath(path))
    if overwrite:
        os.replace(temporary, path)
        _fsync(folder)
        return
    try:
        os.link(temporary, path)  # fails if path exists: no check-then-rename race
    except FileExistsError:
        raise FileExistsError(f"{path} exists; pass overwrite=True to replace it") from None
    except OSError:  # file systems without hard links
        if os.path.exists(path):
            raise FileExistsError(f"{path} exists; pass overwrite=True to replace it") from None
        os.replace(temporary, path)
        _fsync(folder)
        return
    os.remove(temporary)
    _fsync(folder)


def netcdf3_data_bytes(fixed, record_slices) -> tuple[int, int]:
    """Bytes of a netCDF-3 file's data, the header aside: ``(fixed part, one record)``.

    ``fixed``: the size in bytes of each fixed-size variable; ``record_slices``: of each record
    variable's slice (one record's worth). The classic format pads every variable to 4 bytes,
    except the record slice of a file with a single record variable. A file holds at least
    header + fixed part + records x record bytes: the check that a netCDF-3 file is whole."""
    fixed_bytes = sum((int(n) + 3) // 4 * 4 for n in fixed)
    slices = [int(n) for n in record_slices]
    record_bytes = sum(slices) if len(slices) == 1 else sum((n + 3) // 4 * 4 for n in slices)
    return fixed_bytes, record_bytes


def is_compressed(path) -> bool:
    """True when ``path`` is an HDF5-based netCDF-4 file (what :func:`compress_file` writes),
    False for netCDF-3, which the solver appends to."""
    with open(path, "rb") as fh:
        return fh.read(8) == b"\x89HDF\r\n\x1a\n"


def _convert(path, fmt, complevel=None, lock=None, target=None, snapshots=None) -> None:
    """Rewrite ``path`` in format ``fmt`` (deflated at ``complevel`` when given), holding the
    writer's lock (``lock``, or one taken here): written under a temporary name, synced, and
    renamed over ``path`` (or onto ``target``) once complete, the folder synced after, so a
    failure or a kill at any moment leaves the original file as it was (a kill leaves the
    temporary file, which the next process that takes the lock removes). Variables, dimensions
    (the unlimited ``time`` too), values, fill values and attributes are copied as they are, in
    the file's order; no value passes through a float conversion. ``snapshots``: the indices
    along ``time`` kept (default all). An I/O failure (a full disk, a file-size limit) raises
    :class:`OutputError` in one line."""
    import netCDF4

    path = os.fspath(path)
    destination = path if target is None else os.fspath(target)
    directory, base = os.path.split(os.path.abspath(destination))
    temporary = os.path.join(directory, f".{base}.{os.getpid()}.convert")
    own = lock is None
    if own:
        lock = lock_file(path)
    src = dst = None
    try:
        src = netCDF4.Dataset(path)
        dst = netCDF4.Dataset(temporary, "w", format=fmt)
        src.set_auto_maskandscale(False)
        dst.set_auto_maskandscale(False)
        for name, dim in src.dimensions.items():
            dst.createDimension(name, None if dim.isunlimited() else len(dim))
        for name, var in src.variables.items():
            attrs = {k: var.getncattr(k) for k in var.ncattrs()}
            fill = attrs.pop("_FillValue", None)
            var.set_auto_chartostring(False)  # character arrays copied as characters
            row_bytes = max(1, var.dtype.itemsize * int(np.prod(var.shape[1:], dtype=np.int64)))
            per_snapshot = var.ndim > 0 and var.dimensions[0] == "time"
            options, rows_per_chunk, columns = {}, 1, None
            if complevel is not None and var.ndim > 0 and CHECKSUMS:
                options["fletcher32"] = True  # every chunk verified as it is read
            if complevel is not None and var.dtype.kind != "S" and var.ndim > 0:
                if per_snapshot:
                    chunks = chunk_shape(var.shape, var.dtype.itemsize, fill is not None)
                    rows_per_chunk = chunks[0]
                    options["chunksizes"] = chunks
                    if var.ndim > 1 and chunks[1] < var.shape[1]:
                        columns = chunks[1]  # chunks of empty slots are left unwritten
                    stored = fill if columns is not None else None  # the empty slots not stored, or stored
                    sample = [without_fill(var[b], stored) for b in sample_blocks(var.shape[0], rows_per_chunk)]
                    if deflate_saving(sample, complevel) >= MIN_SAVING:
                        options.update(zlib=True, complevel=complevel, shuffle=True)
                else:
                    options.update(zlib=True, complevel=complevel, shuffle=True)
            out = dst.createVariable(name, var.dtype, var.dimensions, fill_value=fill, **options)
            out.setncatts(attrs)
            out.set_auto_chartostring(False)
            if var.ndim == 0:
                out.assignValue(var.getValue())
                continue
            # Whole chunks written at once and no chunk cache on either side: the library holds
            # no variable's chunks while the next is copied, so memory stays at one block.
            for side in (var, out):
                if side.chunking() not in (None, "contiguous"):
                    side.set_var_chunk_cache(size=0)
            if per_snapshot and snapshots is not None:  # a few snapshots: one block
                if columns is None:
                    out[: len(snapshots)] = var[snapshots]
                else:
                    _write_occupied(out, 0, var[snapshots], columns, fill)
                continue
            source_rows = var.chunking()[0] if var.chunking() not in (None, "contiguous") else 1
            for block in copy_blocks(var.shape[0], row_bytes, max(rows_per_chunk, source_rows)):
                if columns is None:
                    out[block] = var[block]
                else:
                    _write_occupied(out, block.start, var[block], columns, fill)
        dst.setncatts({k: src.getncattr(k) for k in src.ncattrs()})
        dst.close()
        src.close()
        _move_into_place(temporary, destination, overwrite=True)
    except BaseException as exc:
        for nc in (dst, src):
            if nc is not None:
                _abandon(nc)
        if os.path.exists(temporary):
            os.remove(temporary)
        if isinstance(exc, (RuntimeError, OSError)) and not isinstance(exc, GrainviewError):
            what = "compressed" if complevel is not None else f"uncompressed ({fmt})"
            error = OutputError(f"{path}: could not be rewritten {what} ({_why(exc)}); the file is unchanged")
            error.reason = _why(exc)  # for a caller that words the message its own way
            raise error from exc
        raise
    finally:
        if own:
            lock.release()


def chunk_rows(row_bytes: int, n_rows: int) -> int:
    """Snapshots per chunk of a compressed file's per-snapshot variable.

    One snapshot, since the analyses read whole snapshots in dask chunks of any length
    (:func:`grainview.contract.io.time_chunks`) and a chunk is inflated whole whichever part of it
    is read; as many snapshots as fill :data:`CHUNK_BYTES` when one snapshot is smaller (a
    chunk's bookkeeping is then no longer small beside its data), and never more than the file
    has: ``max(1, min(n_rows, CHUNK_BYTES // row_bytes))``.

    Parameters
    ----------
    row_bytes : int
        Bytes of one snapshot of the variable.
    n_rows : int
        Snapshots in the file.

    Returns
    -------
    int
        Snapshots per chunk, >= 1.
    """
    return max(1, min(int(n_rows), CHUNK_BYTES // max(1, int(row_bytes))))


def chunk_shape(shape, itemsize: int, fill: bool = False) -> tuple:
    """The chunk of a compressed file's per-snapshot variable of ``shape`` (``time`` first).

    :func:`chunk_rows` snapshots, whole along the other dimensions; for a variable with a fill
    value (its empty slots) of one snapshot per chunk, the second dimension (``contact``,
    ``particle``) is cut into pieces of about :data:`CHUNK_BYTES`, so that the pieces that hold
    only empty slots need not be written at all: HDF5 gives the fill value for a chunk never
    written, without storing or inflating anything.

    Parameters
    ----------
    shape : tuple of int
        The variable's shape, ``time`` first.
    itemsize : int
        Bytes of one value.
    fill : bool, default False
        The variable has a fill value.

    Returns
    -------
    tuple of int
    """
    shape = tuple(int(n) for n in shape)
    rows = chunk_rows(itemsize * int(np.prod(shape[1:], dtype=np.int64)), shape[0])
    chunks = [rows, *shape[1:]]
    if fill and len(shape) > 1 and rows == 1:
        inner = itemsize * int(np.prod(shape[2:], dtype=np.int64))
        chunks[1] = max(1, min(shape[1], CHUNK_BYTES // inner))
    return tuple(chunks)


def _fill_mask(array, fill):
    """Where ``array`` (snapshots first, slots second) holds ``fill`` bit for bit, per slot:
    True for a slot whose every value (both components of a vector) is the fill value."""
    unsigned = f"u{array.dtype.itemsize}"
    same = np.ascontiguousarray(array).view(unsigned) == np.asarray(fill, array.dtype).view(unsigned)
    return same.reshape(*array.shape[:2], -1).all(axis=-1) if array.ndim > 1 else same


def without_fill(array, fill):
    """The values of ``array`` outside its empty slots (those holding ``fill`` bit for bit), as
    one flat array: what a compressed file stores of it. ``array`` itself when ``fill`` is None."""
    if fill is None or array.ndim < 2:
        return array
    return np.ascontiguousarray(array)[~_fill_mask(array, fill)]


def _write_occupied(out, start, data, columns, fill) -> None:
    """Write rows ``start ...`` of ``out`` from ``data`` one chunk (``columns`` slots of a row)
    at a time, skipping the chunks that hold only ``fill``: they stay unwritten and read as it."""
    empty = _fill_mask(data, fill)
    for row in range(data.shape[0]):
        for first in range(0, data.shape[1], columns):
            if not empty[row, first:first + columns].all():
                out[start + row, first:first + columns] = data[row, first:first + columns]


def copy_blocks(n_rows: int, row_bytes: int, rows_per_chunk: int = 1, budget: int | None = None) -> list[slice]:
    """The blocks of rows (snapshots) in which a variable is copied: whole chunks, as many as fit
    in ``budget`` bytes (at least one), in order, covering rows ``0 .. n_rows - 1`` once.

    The largest block holds ``max(rows_per_chunk, (budget // (row_bytes * rows_per_chunk)) *
    rows_per_chunk)`` rows, whatever ``n_rows`` is: copying a file of any number of snapshots
    holds at most that much of it in memory.

    Parameters
    ----------
    n_rows : int
        Rows along the first dimension.
    row_bytes : int
        Bytes of one row.
    rows_per_chunk : int, default 1
        Rows per chunk of the file written (or read); blocks start on chunk boundaries.
    budget : int, optional
        Bytes a block may hold (default: :data:`COPY_BLOCK_BYTES`).

    Returns
    -------
    list of slice
    """
    budget = COPY_BLOCK_BYTES if budget is None else budget
    rows_per_chunk = max(1, int(rows_per_chunk))
    step = max(1, int(budget) // max(1, int(row_bytes) * rows_per_chunk)) * rows_per_chunk
    return [slice(start, min(int(n_rows), start + step)) for start in range(0, int(n_rows), step)]


def sample_blocks(n_rows: int, rows_per_chunk: int, count: int = 3) -> list[slice]:
    """Up to ``count`` chunks spread over the rows (first, middle, last), to measure how well a
    variable compresses."""
    chunks = -(-int(n_rows) // rows_per_chunk)
    picks = sorted({int(k) for k in np.linspace(0, chunks - 1, min(count, chunks))}) if chunks else []
    return [slice(k * rows_per_chunk, min(int(n_rows), (k + 1) * rows_per_chunk)) for k in picks]


def deflate_saving(arrays, complevel: int = DEFAULT_COMPLEVEL) -> float:
    """Fraction of its bytes that byte shuffling and zlib at ``complevel`` save on ``arrays``
    (samples of one variable), as the netCDF library's filters would: ``1 - compressed / raw``.
    0 for no data."""
    import zlib

    raw = packed = 0
    for array in arrays:
        array = np.ascontiguousarray(array)
        shuffled = array.view(np.uint8).reshape(-1, array.dtype.itemsize).T.tobytes()
        raw += len(shuffled)
        packed += len(zlib.compress(shuffled, complevel))
    return 1.0 - packed / raw if raw else 0.0


def check_complevel(complevel) -> int:
    """``complevel`` as an int, or :class:`ParameterError` unless it is a zlib level 1-9."""
    if isinstance(complevel, bool) or not (isinstance(complevel, (int, np.integer)) and 1 <= complevel <= 9):
        raise ParameterError(f"complevel={complevel!r}: expected an integer from 1 to 9")
    return int(complevel)


def compress_file(path, complevel: int = DEFAULT_COMPLEVEL, lock=None) -> None:
    """Rewrite the finished file ``path`` compressed (:data:`COMPRESSED_FORMAT`, zlib at
    ``complevel`` with byte shuffling), in place and atomically; :func:`grainview.open_dataset`
    reads it unchanged. A file already compressed is left alone, so a compression stopped
    midway (the file still netCDF-3) is simply done again.

    Per-snapshot variables are chunked one snapshot per chunk (:func:`chunk_shape`), the chunks
    that hold only empty slots are not written (they read as the fill value), and a variable
    is deflated only when that saves at least :data:`MIN_SAVING` of the bytes of its slots in
    use (:func:`deflate_saving`, on three chunks); the others are stored as they are. Every
    variable but the scalars carries a Fletcher-32 checksum per chunk (:data:`CHECKSUMS`), which
    the netCDF library verifies whenever it reads the chunk. The copy goes block by block
    (:func:`copy_blocks`) without the library's chunk caches, in memory independent of the
    number of snapshots.

    Parameters
    ----------
    path : str or path-like
        A netCDF file of the contract that no other process is writing.
    complevel : int
        zlib level, 1 (fastest) to 9 (smallest).
    lock : grainview.contract.locks.WriterLock, optional
        ``path``'s writer lock, already held by the caller (default: taken here).

    Raises
    ------
    grainview.contract.locks.FileLockedError
        Another process is writing ``path``.
    OutputError
        The rewrite failed (a full disk, a file-size limit); ``path`` is unchanged.
    """
    complevel = check_complevel(complevel)
    own = lock is None
    if own:
        lock = lock_file(path)  # the format is read under the lock: no conversion meanwhile
    try:
        if not is_compressed(path):
            _convert(path, COMPRESSED_FORMAT, complevel, lock=lock)
    finally:
        if own:
            lock.release()


def copy_snapshots(path, target, snapshots, complevel: int = DEFAULT_COMPLEVEL) -> int:
    """Write to ``target`` a compressed copy of the contract file ``path`` that holds only the
    complete snapshots ``snapshots`` (indices among them, negative from the end; e.g. ``[0, -1]``,
    what a run needs to go on from its last snapshot, :mod:`solver.restart`), every value as it
    is; ``path`` is only read. Layout and compression as :func:`compress_file`; ``target`` is
    replaced atomically when it exists. Returns the number of snapshots copied.

    Raises
    ------
    grainview.contract.errors.ParameterError
        An index outside the file's complete snapshots, or ``target`` naming ``path``.
    grainview.contract.locks.FileLockedError
        Another process is writing ``path`` (stop the run first).
    OutputError
        The copy failed; ``target`` is as it was.
    """
    import netCDF4

    complevel = check_complevel(complevel)
    if os.path.abspath(os.fspath(path)) == os.path.abspath(os.fspath(target)):
        raise ParameterError(f"{target}: the copy would replace its source; give another target")
    lock = lock_file(path)
    try:
        with netCDF4.Dataset(os.fspath(path)) as nc:
            nc.set_auto_mask(False)
            complete = np.flatnonzero(complete_snapshots(nc.variables))
        chosen = []
        for index in snapshots:
            if not -complete.size <= int(index) < complete.size:
                raise ParameterError(f"{path}: snapshot {index} does not exist (the file holds "
                                     f"{complete.size} complete snapshots)")
            chosen.append(int(complete[int(index)]))
        chosen = sorted(set(chosen))
        _convert(path, COMPRESSED_FORMAT, complevel, lock=lock, target=target, snapshots=chosen)
        return len(chosen)
    finally:
        lock.release()


def decompress_file(path, lock=None) -> None:
    """Rewrite ``path`` uncompressed in :data:`APPEND_FORMAT`, in place and atomically, so that
    a run can append snapshots to it again (:mod:`solver.restart`). A netCDF-3 file is left
    alone. ``lock`` and the errors: as for :func:`compress_file`."""
    own = lock is None
    if own:
        lock = lock_file(path)
    try:
        if is_compressed(path):
            _convert(path, APPEND_FORMAT, lock=lock)
    finally:
        if own:
            lock.release()


class SnapshotWriter:
    """Create a netCDF file of the contract and append snapshots while a run goes on.

    The file is synced to disk after every snapshot; ``time`` and then the flag ``complete``
    are written last (``complete`` is the last variable of each netCDF-3 record, so a record
    cut short reads 0 there), so a reader (:func:`grainview.open_dataset`) sees every
    completed snapshot and drops a trailing incomplete one. The format is netCDF-3 (64-bit
    offset) by default: its fixed layout survives a killed writer better than HDF5's.

    Use as a context manager::

        with SnapshotWriter.create(path, radius=r, n_vertices=nv, mass=m, inertia=I,
                                   n_walls=4, attrs=params) as w:
            w.append(time=t, position=x, angle=a, contacts=c, box_min=lo, box_max=hi)
    """

    def __init__(self, nc, path, lock=None, owns_lock=True):
        self._nc = nc
        self.path = path
        self._lock = lock
        self._owns_lock = owns_lock  # released by close(); a lock the caller gave is the caller's
        self.advice = "free space or raise the file-size limit (ulimit -f)"
        """What a failed :meth:`append` tells the user to do (the solver adds how to resume)."""
        self._failed = False  # a write failed (a full disk): closed without flushing again
        self.n_particles = nc.dimensions["particle"].size
        self.n_slots = nc.dimensions["contact"].size
        self.n_walls = nc.dimensions["wall"].size if "wall" in nc.dimensions else 0

    @classmethod
    def create(cls, path, *, radius, n_vertices, mass, inertia, n_walls=0, wall_names=None,
               wall_normal=None, optional=(),
               attrs=None, n_contact_slots=None, overwrite=False, format=APPEND_FORMAT, lock=None, vertices=None,
               periodic=None):
        """Create ``path`` with the static particle data, ready for :meth:`append`.

        Parameters
        ----------
        path : str or path-like
            The file to create (its folder must exist).
        radius, mass, inertia : array_like, (N,)
            Circumscribed radii (m), masses (kg) and moments of inertia (kg m2).
        n_vertices : array_like, (N,)
            0 for a disk, n >= 3 for a polygon.
        vertices : array_like, (N, V, 2), optional
            The polygons' vertices in their own frames, m (centroid at the origin,
            counter-clockwise, NaN beyond each one's ``n_vertices`` and for disks:
            :mod:`grainview.contract.shapes`), written as ``vertices``; without it the polygons
            are regular.
        n_walls : int, default 0
            Number of walls (bodies N, N+1, ...).
        wall_names : sequence of str, optional
            One name per wall (default: bottom, right, top, left).
        wall_normal : array_like, (n_walls, 2), optional
            The walls' inward unit normals, written as ``wall_normal``.
        periodic : array_like of bool, (2,), optional
            A periodic sample: whether it repeats along the cell vectors a and b, written as
            ``periodic``; every snapshot then gives its ``cell`` (2, 2) (lattice vectors, m,
            :mod:`grainview.contract.cell`), and ``attrs`` may say ``cell_positions``
            (``wrapped``, the default, or ``unwrapped``).
        optional : sequence of str
            The optional per-snapshot variables this file will hold (e.g.
            ``("velocity", *DIAGNOSTICS)``); the others are not written at all.
        attrs : dict, optional
            Global attributes added to the contract's.
        n_contact_slots : int, optional
            Size of the ``contact`` dimension (default: :func:`grainview.contract.schema.contact_slots`).
        overwrite : bool, default False
            Replace an existing ``path`` (refused while another process writes it).
        format : str, default :data:`APPEND_FORMAT`
            The netCDF format (netCDF-3, appended in place).
        lock : grainview.contract.locks.WriterLock, optional
            ``path``'s writer lock, already held by the caller, who releases it (default: taken
            here before anything is written, released by :meth:`close`).

        Returns
        -------
        SnapshotWriter
            Holding the file open and its writer's lock (:mod:`grainview.contract.locks`).

        Raises
        ------
        FileExistsError
            ``path`` exists and ``overwrite`` is False.
        FileNotFoundError
            The folder does not exist.
        grainview.contract.locks.FileLockedError
            Another process is writing ``path``.
        OutputError
            The file could not be written (a full disk, a file-size limit): nothing is left at
            ``path``, nor a temporary file.
        ParameterError
            An unknown optional variable.
        """
        path = os.fspath(path)
        if os.path.exists(path) and not overwrite:
            raise FileExistsError(f"{path} exists; pass overwrite=True to replace it")
        folder = os.path.dirname(os.path.abspath(path))
        if not os.path.isdir(folder):  # named here, not by the hidden temporary file's name
            raise FileNotFoundError(f"cannot write {path}: the folder {folder} does not exist")
        own = lock is None
        if own:
            lock = lock_file(path)  # never replace a file another run is still writing
        try:
            nc = cls._create(path, radius, n_vertices, mass, inertia, n_walls, wall_names, wall_normal, optional,
                             attrs, n_contact_slots, overwrite, format, vertices, periodic)
        except BaseException:
            if own:
                lock.release()
            raise
        return cls(nc, path, lock, own)

    @staticmethod
    def _create(path, radius, n_vertices, mass, inertia, n_walls, wall_names, wall_normal, optional, attrs,
                n_contact_slots, overwrite, format, vertices=None, periodic=None):
        """:meth:`create`'s file, under the lock: written, moved into place and opened to append."""
        import netCDF4

        radius = np.asarray(radius, "f8")
        n = radius.shape[0]
        slots = n_contact_slots or contact_slots(n, n_walls)
        unknown = [o for o in optional if o not in VARIABLES or VARIABLES[o].required]
        if unknown:
            raise ParameterError(f"unknown optional variables {unknown}")
        if not n_walls:
            optional = [o for o in optional if "wall" not in VARIABLES[o].dims]
        optional = [o for o in optional if o not in ("cell", "periodic")]
        if periodic is None and "cell_velocity" in optional:
            raise ParameterError("cell_velocity needs a periodic cell: give periodic=(.., ..)")
        if periodic is not None:
            periodic = np.asarray(periodic)
            problems = cell_problems(np.zeros((0, 2, 2)), np.zeros((0, 2)), np.ones((0, 2)), periodic)
            if problems:
                raise ParameterError("; ".join(problems))
            optional.append("cell")
            attrs = {"cell_positions": "wrapped", **(attrs or {})}
            if attrs["cell_positions"] not in CELL_POSITIONS:
                raise ParameterError(f"cell_positions={attrs['cell_positions']!r}: expected one of {CELL_POSITIONS}")
        if vertices is not None:
            vertices = np.asarray(vertices, "f8")
            problems = shape_problems(radius, n_vertices, vertices) if vertices.ndim == 3 and \
                vertices.shape[::2] == (n, 2) else [f"vertices: expected shape (N, V, 2) with N = {n}, got {vertices.shape}"]
            if problems:
                raise ParameterError("; ".join(problems))
            if vertices.shape[1] == 0:  # disks only: nothing to store (a vertex dimension of size 0 is unlimited)
                vertices = None
        # The header and the static data are written under a temporary name and the file is
        # moved into place once they are on disk: a run killed while the file is being created
        # leaves either no file or a valid empty one, never a partial header.
        directory, base = os.path.split(os.path.abspath(path))
        temporary = os.path.join(directory, f".{base}.{os.getpid()}.part")
        nc = None
        try:
            nc = netCDF4.Dataset(temporary, "w", format=format)
            nc.set_auto_mask(False)
            nc.createDimension("time", None)
            nc.createDimension("particle", n)
            nc.createDimension("contact", slots)
            if any("contact_point" in VARIABLES[o].dims for o in optional):
                nc.createDimension("contact_point", 2)  # the two points of a double contact
            nc.createDimension("xy", 2)
            if vertices is not None:
                nc.createDimension("vertex", vertices.shape[1])
            nc.createDimension("xy_strlen", 1)
            xy = nc.createVariable("xy", "S1", ("xy", "xy_strlen"))
            xy[:] = np.array([[b"x"], [b"y"]])
            xy.long_name = "Cartesian component"
            xy._Encoding = "utf-8"
            tvar = nc.createVariable("time", "f8", ("time",), fill_value=np.nan)
            tvar.setncatts(TIME_ATTRS)
            if n_walls:
                names = tuple(wall_names) if wall_names is not None else DEFAULT_WALL_NAMES[:n_walls]
                width = max(len(s) for s in names)
                nc.createDimension("wall", n_walls)
                nc.createDimension("wall_strlen", width)
                wv = nc.createVariable("wall", "S1", ("wall", "wall_strlen"))
                wv[:] = netCDF4.stringtochar(np.array(names, dtype=f"S{width}"))
                wv.long_name = "wall name"
                wv._Encoding = "utf-8"
            if periodic is not None:
                nc.createDimension("cell_vector", 2)
                nc.createDimension("cell_vector_strlen", 1)
                cv = nc.createVariable("cell_vector", "S1", ("cell_vector", "cell_vector_strlen"))
                cv[:] = np.array([[name.encode()] for name in CELL_VECTORS])
                cv.long_name = "lattice vector of the cell"
                cv._Encoding = "utf-8"
            names = [*REQUIRED, *optional]
            if periodic is not None:
                names.append("periodic")
            if n_walls and wall_normal is not None:
                names.append("wall_normal")
            if vertices is not None:
                names.append("vertices")
            names.append("complete")  # defined last: the last bytes of each record
            for name in dict.fromkeys(names):
                var = VARIABLES[name]
                fill = None if var.is_integer else np.nan
                v = nc.createVariable(name, var.dtype, var.dims, fill_value=fill)
                v.setncatts(variable_attrs(name))
            static = {"radius": radius, "n_vertices": n_vertices, "mass": mass, "inertia": inertia}
            if "wall_normal" in nc.variables:
                static["wall_normal"] = wall_normal
            if vertices is not None:
                static["vertices"] = vertices
            if periodic is not None:
                static["periodic"] = periodic
            for name, value in static.items():
                nc.variables[name][:] = np.broadcast_to(np.asarray(value, VARIABLES[name].dtype),
                                                        nc.variables[name].shape)
            nc.setncatts(global_attrs(n, n_walls, attrs, has_irregular_polygons(radius, n_vertices, vertices),
                                      periodic is not None))
            nc.close()
            _move_into_place(temporary, path, overwrite)
        except BaseException as exc:
            if nc is not None:
                _abandon(nc)
            if os.path.exists(temporary):
                os.remove(temporary)
            if isinstance(exc, (RuntimeError, OSError)) and not isinstance(exc, (GrainviewError, FileExistsError)):
                raise OutputError(f"{path}: could not be created ({_why(exc)}); nothing was written") from exc
            raise
        nc = netCDF4.Dataset(path, "a")
        nc.set_auto_mask(False)
        return nc

    @classmethod
    def open_append(cls, path, lock=None):
        """Open an existing file of the contract to append further snapshots (refused with
        :class:`grainview.contract.locks.FileLockedError` while another process writes it). A compressed
        file is first rewritten uncompressed (:func:`decompress_file`). ``lock``: as for
        :meth:`create` (whoever reads the file's last snapshot to go on from it takes the lock
        first and passes it here, so that no other process appends in between)."""
        import netCDF4

        path = os.fspath(path)
        if not os.path.exists(path):
            raise FileFormatError(f"cannot open {path} for appending: no such file")
        own = lock is None
        if own:
            lock = lock_file(path)
        try:
            decompress_file(path, lock=lock)  # a finished, compressed run: netCDF-3 again, to append in place
            try:
                nc = netCDF4.Dataset(path, "a")
            except OSError as exc:
                raise FileFormatError(f"cannot open {path} for appending: {exc}") from exc
        except BaseException:
            if own:
                lock.release()
            raise
        nc.set_auto_mask(False)
        return cls(nc, path, lock, own)

    def take_lock(self):
        """Hand the writer's lock over to the caller, who releases it: :meth:`close` keeps it
        (to compress the closed file before another process may take it)."""
        self._owns_lock = False
        return self._lock

    def attribute(self, name, default=None):
        """The file's global attribute ``name`` (``default`` when it has none)."""
        return self._nc.getncattr(name) if name in self._nc.ncattrs() else default

    @property
    def n_snapshots(self) -> int:
        """Number of complete snapshots (trailing ones with no time are not counted)."""
        complete = np.flatnonzero(complete_snapshots(self._nc.variables))
        return int(complete[-1] + 1) if complete.size else 0

    def append(self, **snapshot):
        """Write one snapshot and sync it to disk, ``complete`` last.

        Parameters
        ----------
        time : float
            Simulated time, s.
        position : array_like, (N, 2)
            Particle centres, m.
        angle : array_like, (N,)
            Particle angles, rad.
        contacts : dict
            The contact variables (``i, j, kind, normal, fn, ft, point, branch`` and optionally
            ``gap``), one entry per contact, at most the file's number of slots.
        box_min, box_max : array_like, (2,)
            Corners of the sample box, m.
        **optional
            Values of the optional variables the file holds (``velocity``, ``wall_force``...).

        Raises
        ------
        OutputError
            An I/O failure (a full disk), in one line; the snapshot is not marked complete,
            so the file keeps the snapshots before it, readable and resumable.
        ParameterError
            More contacts than slots, or an unknown variable.
        """
        k = self.n_snapshots
        try:
            self._append(**snapshot)
        except (RuntimeError, OSError) as exc:
            self._failed = True
            raise OutputError(f"{self.path}: could not write snapshot {k} ({_why(exc)}); the file keeps its {k} "
                              f"complete snapshots: {self.advice}") from exc

    def _append(self, *, time, position, angle, contacts, box_min, box_max, **optional):
        """Write one snapshot; ``contacts`` is a dict of the contact variables with one
        entry per contact (any length up to the number of slots)."""
        nc = self._nc
        k = self.n_snapshots
        m = len(contacts["i"])
        if m > self.n_slots:
            raise ParameterError(f"{m} contacts exceed the file's {self.n_slots} contact slots")
        nc.variables["position"][k] = position
        nc.variables["angle"][k] = angle
        nc.variables["box_min"][k] = box_min
        nc.variables["box_max"][k] = box_max
        for name in CONTACT_VARIABLES + tuple(v for v in OPTIONAL_CONTACT_VARIABLES
                                              if v in contacts and v in nc.variables):
            var = VARIABLES[name]
            shape = (self.n_slots, 2) if var.dims[-1] == "xy" else (self.n_slots,)
            buf = empty_slots(shape, name)
            buf[:m] = np.asarray(contacts[name], var.dtype).reshape((m,) + shape[1:])
            nc.variables[name][k] = buf
        nc.variables["contact_count"][k] = m
        for name, value in optional.items():
            if name in nc.variables:
                nc.variables[name][k] = value
            elif name not in VARIABLES:
                raise ParameterError(f"unknown variable {name!r}")
        nc.variables["time"][k] = time
        nc.variables["complete"][k] = 1  # last: marks the snapshot complete
        nc.sync()

    def close(self):
        """Close the file and release its writer lock. A close that fails (a full disk) raises
        :class:`OutputError` in one line; the complete snapshots were synced before."""
        nc = self._nc
        try:
            if not nc.isopen():
                return
            if not self._failed:
                try:  # everything to disk first: a failure here leaves the handle whole
                    nc.sync()
                except (RuntimeError, OSError):
                    self._failed = True
            if not self._failed:
                try:
                    nc.close()
                    return
                except (RuntimeError, OSError) as exc:
                    self._abandon(nc)
                    raise OutputError(f"{self.path}: could not close the file ({exc}); its complete snapshots "
                                      "were written before") from exc
            self._abandon(nc)
        finally:
            if self._lock is not None and self._owns_lock:
                self._lock.release()
            self._lock = None

    _abandon = staticmethod(_abandon)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def write_atomically(path, overwrite, write):
    """Write ``path`` through ``write(temporary path)`` and move it into place.

    An interrupted write never leaves a half-written file under the final name; an existing
    ``path`` is refused unless ``overwrite``.

    Parameters
    ----------
    path : str
        The final file name.
    overwrite : bool
        Replace an existing ``path``.
    write : callable
        Called with the temporary path (``<root>.part<ext>`` beside ``path``); writes the file.

    Returns
    -------
    None

    Raises
    ------
    grainview.contract.errors.ParameterError
        When ``path`` exists and ``overwrite`` is False.
    """
    if os.path.exists(path) and not overwrite:
        raise ParameterError(f"{path} exists; pass overwrite=True to replace it")
    root, ext = os.path.splitext(path)
    temporary = f"{root}.part{ext}"
    write(temporary)
    os.replace(temporary, path)
