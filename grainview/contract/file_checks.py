"""Checks of the contract on plain numpy arrays, shared by :func:`grainview.contract.validation.validate`
(xarray, lazily) and ``grainview info`` (netCDF4 alone), so that both say the same words.

Each function returns the problems it finds as lines (empty when there are none), or raises
:class:`~grainview.contract.errors.FileFormatError` for a damaged file. numpy only: ``grainview info``
imports this module without xarray.
"""

from __future__ import annotations

import numpy as np

from .errors import FileFormatError, SchemaError
from .schema import REQUIRED, SCHEMA_VERSION

NOT_A_GRAINVIEW_FILE = ("not a grainview file: none of the contract's particle or contact variables "
                        "(radius, position, i, j, fn...; docs/schema.md)")
"""The one problem reported for a file that holds none of the contract's required variables."""

NON_FINITE_FORCES = "{name}: {count} NaN or infinite force(s) in occupied slots"
"""Template of the problem of non-finite ``fn`` or ``ft`` in occupied slots."""

COUNT_OUT_OF_RANGE = "contact_count: {count} snapshot(s) with a count outside [0, {slots}]"
"""Template of the problem of ``contact_count`` values outside the contact slots."""

HIDDEN_RECORDS_TOLERATED = 1
"""Whole records beyond a netCDF-3 header's record count that a killed writer may leave (the
record it was writing, its bytes on disk before the header's count was raised); more are a
damaged header."""


def foreign_file_problems(names) -> list[str]:
    """``[NOT_A_GRAINVIEW_FILE]`` when none of the contract's required variables is among
    ``names`` (the file is of another kind: listing each missing variable would say nothing
    useful), else ``[]``."""
    return [] if any(name in names for name in REQUIRED) else [NOT_A_GRAINVIEW_FILE]


def damaged_snapshots(complete, source) -> int:
    """The number of leading complete snapshots of a file; raise :class:`FileFormatError` when
    an incomplete snapshot (``complete`` False: no time, or its flag unset) comes before a
    complete one. Only the last snapshot may be incomplete (a writer killed while writing
    it); one inside the file means the file is damaged.

    Parameters
    ----------
    complete : array_like of bool, (T,)
        :func:`grainview.contract.schema.complete_snapshots` of the file.
    source : str
        The file's name, for the message.
    """
    complete = np.asarray(complete, bool)
    leading = int(np.argmin(complete)) if not complete.all() else complete.size
    if complete[leading:].any():
        raise FileFormatError(f"{source}: snapshot {leading} is incomplete but later ones are complete; "
                              "the file is damaged")
    return leading


def order_problems(name, values, unit="") -> list[str]:
    """``time`` (or ``step``) must increase strictly from snapshot to snapshot: the snapshots
    that repeat the previous one's value (a snapshot written twice) and those below it.

    Parameters
    ----------
    name : str
        The variable's name, for the messages.
    values : array_like, (T,)
        Its value per snapshot (NaN entries are not compared).
    unit : str
        Its unit, for the messages (``" s"`` for time).

    Returns
    -------
    list of str
        At most two lines: repeated values, and values below the previous one, each with the
        first snapshot concerned.
    """
    values = np.asarray(values)
    if values.size < 2:
        return []
    step = np.diff(values)
    problems = []
    repeated = np.flatnonzero(step == 0) + 1
    if repeated.size:
        k = repeated[0]
        problems.append(f"{name}: {repeated.size} snapshot(s) repeating the previous snapshot's {name} (first: "
                        f"snapshot {k}, {name} = {values[k]:g}{unit}); expected {name} to increase strictly "
                        "(each snapshot written once)")
    earlier = np.flatnonzero(step < 0) + 1
    if earlier.size:
        k = earlier[0]
        problems.append(f"{name}: {earlier.size} snapshot(s) earlier than the previous snapshot (first: snapshot "
                        f"{k}, {name} = {values[k]:g}{unit} after {values[k - 1]:g}{unit}); expected {name} to "
                        "increase strictly")
    return problems


def negative_force_problem(count, snapshot, slot, i, j, fn) -> str:
    """The line naming ``count`` negative normal forces and the first of them: snapshot, slot,
    the two bodies and the force in N. Normal forces are compressive, ``fn >= 0`` (0: a pair
    in contact or near that carries no force)."""
    return (f"fn: {count} negative normal force(s) in occupied slots (first: snapshot {snapshot}, slot {slot}, "
            f"bodies {i} and {j}, fn = {fn:g} N); expected fn >= 0 (compression positive)")


def force_problems(fn, ft, i, j, occupied) -> list[str]:
    """Non-finite ``fn``/``ft`` and negative ``fn`` in the occupied slots of (T, C) arrays.

    Returns
    -------
    list of str
        The lines :func:`grainview.contract.validation.validate` gives for the same faults.
    """
    fn, ft, occupied = np.asarray(fn), np.asarray(ft), np.asarray(occupied, bool)
    problems = []
    for name, force in (("fn", fn), ("ft", ft)):
        count = int((occupied & ~np.isfinite(force)).sum())
        if count:
            problems.append(NON_FINITE_FORCES.format(name=name, count=count))
    with np.errstate(invalid="ignore"):
        negative = occupied & (fn < 0)
    if negative.any():
        k, slot = np.argwhere(negative)[0]
        problems.append(negative_force_problem(int(negative.sum()), k, slot, int(np.asarray(i)[k, slot]),
                                               int(np.asarray(j)[k, slot]), float(fn[k, slot])))
    return problems


def hidden_records(source, size, header, fixed, record, n_records, complete=None) -> None:
    """Raise :class:`FileFormatError` when a netCDF-3 file holds more complete records than
    its header counts, beyond the :data:`HIDDEN_RECORDS_TOLERATED` one that a killed writer
    may leave: a lowered record count hides snapshots from every reader.

    The netCDF library grows a file it writes by blocks, so a file being written (or whose
    writer was killed) is often longer than its counted records by several records' worth of
    bytes that hold no snapshot. When the ``complete`` flags of those would-be records are
    given, only the ones set count as hidden; without them (a file without the flag), every
    whole record the size holds does.

    Parameters
    ----------
    source : str
        The file's name, for the message.
    size : int
        The file's size in bytes.
    header, fixed, record : int
        Bytes of the header, of the fixed-size variables and of one record.
    n_records : int
        The record count in the header.
    complete : sequence of bool, optional
        Whether each whole record the size holds beyond the counted ones has its ``complete``
        flag set.
    """
    if record <= 0:
        return
    if complete is not None:
        held = n_records + int(sum(bool(flag) for flag in complete))
    else:
        held = n_records + max(0, (size - header - fixed - n_records * record) // record)
    if held - n_records > HIDDEN_RECORDS_TOLERATED:
        raise FileFormatError(f"{source}: its header counts {n_records} snapshots but its size holds {held}: the "
                              f"header's record count hides {held - n_records} snapshots (the file is damaged)")


DAMAGED_DATA = ("{source}: {name}{where}: its stored data cannot be read ({why}): the file is damaged (a chunk "
                "that fails its checksum or does not inflate)")
"""Template of the one-line error of a variable whose stored bytes the netCDF library refuses
(a finished file's chunk whose Fletcher-32 checksum does not match, or whose deflated bytes do
not inflate; docs/schema.md, "Checksums")."""

MISSING_SCHEMA_VERSION = ("global attribute grainview_schema_version is missing: which version of the contract the "
                          "file follows is unknown (every file grainview writes has it; docs/schema.md, "
                          "\"Global attributes\")")
"""The problem ``grainview info --check`` names for a file without ``grainview_schema_version``."""

CHECK_BLOCK_BYTES = 8 * 2**20
"""At most about this many bytes of one variable are read at once by :func:`damaged_chunks`."""


def damaged_data(source, name, exc, where="") -> FileFormatError:
    """The :class:`FileFormatError` of variable ``name`` of the file ``source`` whose stored
    data could not be read (``exc``, the netCDF library's error), in one line
    (:data:`DAMAGED_DATA`); ``where`` says which part (e.g. ``" at snapshot 3"``)."""
    why = " ".join(str(exc).split()) or type(exc).__name__
    return FileFormatError(DAMAGED_DATA.format(source=source, name=name, where=where, why=why))


class _CheckedVariable:
    """A netCDF4 variable whose reads raise :func:`damaged_data` instead of the library's bare
    ``RuntimeError`` (which names neither the file nor the variable); everything else is the
    variable's."""

    def __init__(self, var, name, source):
        self._var, self._name, self._source = var, name, source

    def __getitem__(self, key):
        try:
            return self._var[key]
        except RuntimeError as exc:
            raise damaged_data(self._source, self._name, exc) from exc

    def getValue(self):  # noqa: N802 (netCDF4's name)
        """A scalar variable's value."""
        try:
            return self._var.getValue()
        except RuntimeError as exc:
            raise damaged_data(self._source, self._name, exc) from exc

    def __getattr__(self, attr):
        return getattr(self._var, attr)

    def __len__(self):
        return len(self._var)


def checked_variables(variables, source) -> dict:
    """``variables`` (a netCDF4 Dataset's ``variables``) with each one's reads checked: a
    stored chunk the library refuses (a checksum that does not match, data that do not
    inflate) raises :class:`FileFormatError` naming ``source`` and the variable in one line
    (:func:`damaged_data`), not a bare ``RuntimeError``.

    Parameters
    ----------
    variables : mapping of str to netCDF4.Variable
        An open file's variables.
    source : str
        The file's name, for the messages.

    Returns
    -------
    dict
        Name -> a variable that reads as the original does.
    """
    return {name: _CheckedVariable(var, name, source) for name, var in variables.items()}


def _row_blocks(n_rows, row_bytes, rows_per_chunk):
    """Slices of whole chunks along the first dimension, about :data:`CHECK_BLOCK_BYTES` each."""
    step = max(1, CHECK_BLOCK_BYTES // max(1, row_bytes * rows_per_chunk)) * rows_per_chunk
    return [slice(start, min(n_rows, start + step)) for start in range(0, n_rows, step)]


def damaged_chunks(variables) -> list[str]:
    """Read every stored value of every variable, whole chunks at a time, and name those that
    the netCDF library refuses to read: in a finished (compressed) file, HDF5 verifies each
    chunk's Fletcher-32 checksum as it reads it, so a changed bit is found here rather than
    read as another number (docs/schema.md, "Checksums").

    Parameters
    ----------
    variables : mapping of str to netCDF4.Variable
        An open file's variables (a netCDF-3 file has no checksums: reading it finds only I/O
        errors).

    Returns
    -------
    list of str
        One line per damaged variable: how many of its snapshots (rows of chunks) cannot be
        read and the first of them, with the library's reason; empty when every chunk reads.
    """
    problems = []
    for name, var in variables.items():
        chunking = var.chunking() if hasattr(var, "chunking") else None
        if chunking not in (None, "contiguous"):
            var.set_var_chunk_cache(size=0)  # one block in memory at a time, whatever the file's length
        if var.ndim == 0:
            try:
                var.getValue()
            except RuntimeError as exc:
                problems.append(f"{name}: its stored value cannot be read ({' '.join(str(exc).split())})")
            continue
        rows_per_chunk = chunking[0] if chunking not in (None, "contiguous") else 1
        row_bytes = var.dtype.itemsize * int(np.prod(var.shape[1:], dtype=np.int64))
        bad, why = [], ""
        for block in _row_blocks(var.shape[0], row_bytes, rows_per_chunk):
            try:
                var[block]
                continue
            except RuntimeError as exc:
                why = " ".join(str(exc).split())
            for start in range(block.start, block.stop, rows_per_chunk):  # which chunks
                rows = slice(start, min(block.stop, start + rows_per_chunk))
                try:
                    var[rows]
                except RuntimeError:
                    bad.append(rows)
        if bad:
            what = "snapshot" if var.dimensions[:1] == ("time",) else f"{var.dimensions[0]} row"
            first = bad[0]
            at = f" {first.start}" if first.stop - first.start == 1 else f"s {first.start}-{first.stop - 1}"
            count = sum(rows.stop - rows.start for rows in bad)
            problems.append(f"{name}: {count} {what}(s) whose stored data cannot be read (first: {what}{at}; "
                            f"{why}): a chunk that fails its checksum or does not inflate")
    return problems


def check_version(version, source) -> None:
    """Refuse a schema version newer (by its major number) than this grainview's."""
    if version is None:
        return
    try:
        major = int(str(version).split(".")[0])
    except ValueError:
        raise SchemaError(f"global attribute grainview_schema_version={version!r} is not a version number", source)
    if major > int(SCHEMA_VERSION.split(".")[0]):
        raise SchemaError(f"file has schema version {version}, newer than this grainview understands "
                          f"({SCHEMA_VERSION}); upgrade grainview", source)
