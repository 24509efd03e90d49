"""The byte layout of a netCDF-3 file, read without trusting its header.

netCDF-3 readers return zeros for the missing bytes of a truncated file instead of failing,
and never look past the record count of the header; :func:`check_netcdf3_length` measures a
file against its header so that a file cut short, or longer by records its header does not
count, is refused (:func:`grainview.contract.file_checks.hidden_records`).
"""

from __future__ import annotations

import os

import numpy as np

from .errors import FileFormatError
from .file_checks import hidden_records
from .locks import being_written
from .writer import netcdf3_data_bytes


def header_reader():
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


def check_netcdf3_length(path: str) -> None:
    """Raise FileFormatError when a netCDF-3 file is shorter than its header says.

    netCDF-3 readers return zeros for the missing bytes of a truncated file instead of
    failing, so the length is checked: header + fixed-size variables + records. While a
    writer holds the file (:func:`grainview.contract.locks.being_written`) its last record may be
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
            nc = header_reader()(fh, "r", mmap=False)
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
